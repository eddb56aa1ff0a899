"""Fit statistics of a diagnosis: how far predictions are from the measured signals, the residuals' lag-1
autocorrelation, the effective sample size it implies, the information criterion's gain of a richer model, and the
covariances of fitted parameters (the block sandwich, the replay's own)."""

from __future__ import annotations

import math

import numpy as np

from .. import portable as pm
from .problem import Problem


def fit_statistics(problem: Problem, predictions: list[np.ndarray]) -> dict:
    """Plain and weighted RMS, the noise floor and the attainable floor over all files.

    ``weighted_rms_Nm`` is sqrt(mean(r_i^2 floor_f^2)) with r_i the weighted residual and
    floor_f the file's noise floor: it equals the noise floor for a perfect model, and
    sqrt(floor^2 + e^2) for a model off by e where the replay is certain.
    """
    files = problem.files
    residual = np.concatenate([f.torque_Nm - f.torque_part(m) for f, m in zip(files, predictions)])
    weighted = problem.weighted(predictions)
    is_torque = np.concatenate([np.arange(f.m) < f.n for f in files])
    floors = np.concatenate([np.full(f.n, f.noise.total_rms) for f in files])
    attainable = np.concatenate([f.sigma_Nm for f in files])
    floor = float(np.sqrt(np.mean(floors**2)))
    out = {
        "rms_Nm": float(np.sqrt(np.mean(residual**2))),
        "peak_Nm": float(np.max(np.abs(residual))),
        "weighted_rms_Nm": float(np.sqrt(np.mean((weighted[is_torque] * floors) ** 2))),
        "noise_floor_Nm": floor,
        "attainable_floor_Nm": float(np.sqrt(np.mean(attainable**2))),
        "weighted_rss": float(np.sum(weighted**2)),
        "samples": int(weighted.size),
    }
    with_angle = [(f, m) for f, m in zip(files, predictions) if f.uses_angle]
    if with_angle:  # the angle's residual beside the torque's (the same definitions, in rad and degrees)
        angle = np.concatenate([f.angle_rad - f.angle_part(m) for f, m in with_angle])
        angle_floors = np.concatenate([np.full(f.n, f.angle_noise.total_rms) for f, _ in with_angle])
        angle_weighted = np.concatenate([(f.angle_rad - f.angle_part(m)) / f.sigma_rad for f, m in with_angle])
        angle_attainable = np.concatenate([f.sigma_rad for f, _ in with_angle])
        rms = float(np.sqrt(np.mean(angle**2)))
        out["angle"] = {
            "rms_rad": rms,
            "rms_deg": math.degrees(rms),
            "peak_rad": float(np.max(np.abs(angle))),
            "weighted_rms_rad": float(np.sqrt(np.mean((angle_weighted * angle_floors) ** 2))),
            "noise_floor_rad": float(np.sqrt(np.mean(angle_floors**2))),
            "attainable_floor_rad": float(np.sqrt(np.mean(angle_attainable**2))),
            "weighted_rss": float(np.sum(angle_weighted**2)),
            "samples": int(angle.size),
        }
    with_motor = [(f, m) for f, m in zip(files, predictions) if f.uses_motor]
    if with_motor:  # an assisted car's motor channel beside the torque (in its own unit, A or N m)
        motor = np.concatenate([f.motor - f.motor_part(m) for f, m in with_motor])
        motor_floors = np.concatenate([np.full(f.n, f.motor_noise.total_rms) for f, _ in with_motor])
        motor_weighted = np.concatenate([(f.motor - f.motor_part(m)) / f.sigma_motor for f, m in with_motor])
        out["motor"] = {
            "column": with_motor[0][0].motor_column,
            "rms": float(np.sqrt(np.mean(motor**2))),
            "peak": float(np.max(np.abs(motor))),
            "weighted_rms": float(np.sqrt(np.mean((motor_weighted * motor_floors) ** 2))),
            "noise_floor": float(np.sqrt(np.mean(motor_floors**2))),
            "weighted_rss": float(np.sum(motor_weighted**2)),
            "samples": int(motor.size),
        }
    return out


def pooled_lag1(segments) -> float:
    """Lag-1 autocorrelation pooled over `segments` (arrays; pairs within a segment, each about its own mean)."""
    num = den = 0.0
    for r in segments:
        r = r - r.mean()
        num += float(np.sum(r[1:] * r[:-1]))
        den += float(np.sum(r * r))
    return num / den if den > 0 else 0.0


def lag1_autocorrelation(problem: Problem, weighted: np.ndarray) -> float:
    """Lag-1 autocorrelation of the weighted residuals, pooled over files (pairs within a file and signal)."""
    bounds = np.cumsum([0] + [f.n for f in problem.files for _ in range(f.signals)])
    return pooled_lag1(weighted[a:b] for a, b in zip(bounds[:-1], bounds[1:]))


def effective_samples(n: int, rho: float) -> float:
    """n (1 - rho) / (1 + rho) for AR(1)-like residuals, rho clipped to [0, 0.95]."""
    rho = min(max(rho, 0.0), 0.95)
    return max(n * (1.0 - rho) / (1.0 + rho), 2.0)


def bic_gain(rss_without: float, rss_with: float, n_eff: float, parameters: int) -> float:
    """The fall of the BIC over the effective sample size, ``BIC = n_eff ln(RSS / n) + k ln(n_eff)``, when
    `parameters` more columns take the weighted residual sum of squares from `rss_without` to `rss_with`:
    ``n_eff ln(rss_without / rss_with) - k ln(n_eff)`` (positive: the richer model is the better)."""
    return n_eff * pm.log(rss_without / max(rss_with, 1e-300)) - parameters * pm.log(n_eff)


def block_sandwich(jacobian: np.ndarray, weighted: np.ndarray, problem: Problem, block_s: float
                   ) -> tuple[np.ndarray, int]:
    """(Block sandwich covariance of the fitted parameters, number of blocks B): residuals grouped in segments
    of `block_s` of each file (a last segment shorter than half a block joins the one before)."""
    ids, start, offset = [], 0, 0
    for f in problem.files:
        t = f.time_s - f.time_s[0]
        count = max(int(round(t[-1] / block_s)), 1)
        block = np.minimum((t / (t[-1] / count)).astype(int), count - 1) if t[-1] > 0 else np.zeros(f.n, dtype=int)
        ids.extend([block + offset] * f.signals)  # a file's signals at the same instants share their segment
        offset += count
        start += f.n
    ids = np.concatenate(ids)
    k = jacobian.shape[1]
    bread = pm.inv(pm.matmul(jacobian.T, jacobian))
    meat = np.zeros((k, k))
    for b in range(offset):
        rows = ids == b
        score = pm.matmul(jacobian[rows].T, weighted[rows])
        meat += np.outer(score, score)
    scale = offset / max(offset - k, 1)
    return pm.matmul(pm.matmul(scale * bread, meat), bread), offset


def replay_covariance(jacobian: np.ndarray, problem: Problem) -> np.ndarray:
    """Covariance of the fitted parameters from the replay's own uncertainty: each rack of the replay ensemble
    (:func:`parksteer.diagnose.ensemble.with_replay_uncertainty`) changes the replayed torque by its
    deviation d from the ensemble mean, which a fit absorbs as the parameter shift (J^T J)^-1 J^T (d / sigma);
    the covariance of these shifts over the draws. Zero when the ensemble was not run."""
    k = jacobian.shape[1]
    draws = [f.replay_draws for f in problem.files]
    if any(d is None for d in draws) or len({d.shape[0] for d in draws}) != 1 or draws[0].shape[0] < 2:
        return np.zeros((k, k))
    deviations = np.concatenate([d / f.sigma for d, f in zip(draws, problem.files)], axis=1)
    shifts = pm.solve(pm.matmul(jacobian.T, jacobian), pm.matmul(jacobian.T, deviations.T))  # k x draws
    return pm.matmul(shifts, shifts.T) / (shifts.shape[1] - 1)
