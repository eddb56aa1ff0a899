"""Step 1 of ``parksteer assist identify`` (:mod:`.assist_identify`): the motor current's map of
the logged torsion-bar torque, fitted as a boost table (the law of
:func:`parksteer.model.symbolic.effects.assist_common.table_law`) by a bounded Levenberg-Marquardt on portable
arithmetic, with the intervals of a block sandwich and what a map cannot hold (scatter, hysteresis); and the
numbers it reports, each with its 95 % interval (:class:`Estimate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ... import portable as pm
from ...boost_table import entries
from ...model.numeric.boost_numeric import table_law_numeric, table_points_numeric
from ..fitting import Z95
from ..problem import FileData
from ...names import TORQUE

SPAN_POINTS = 7  # table points beyond the dead band (9 with the origin and the dead band; the law allows 10)
BLOCK_S = 1.0  # s: the blocks of the intervals' sandwich (residuals closer than this are taken as correlated)


@dataclass(frozen=True)
class Estimate:
    """One identified number: value, 95 % interval, unit."""

    value: float
    ci95: tuple[float, float]
    unit: str

    def as_dict(self) -> dict:
        return {"value": self.value, "ci95": list(self.ci95), "unit": self.unit}

    def text(self, digits: int = 4) -> str:
        unit = "" if self.unit == "1" else f" {self.unit}"
        return (f"{self.value:.{digits}g}{unit} (95 % {self.ci95[0]:.{digits}g} to "
                f"{self.ci95[1]:.{digits}g})")


def _estimate(value: float, se: float, unit: str, z: float = Z95) -> Estimate:
    return Estimate(float(value), (float(value - z * se), float(value + z * se)), unit)


def _t95(dof: int) -> float:
    """The two-sided 95 % quantile of Student's t: a sandwich over few blocks estimates its variance from few."""
    return pm.student_t_quantile(0.975, max(dof, 1))


def _map_law(torques: list[float], values: list[float]):
    """The boost table's law (:func:`parksteer.model.symbolic.effects.assist_common.table_law`) of one row, on
    numbers (:mod:`parksteer.model.numeric.boost_numeric`: the same operations, its points read once)."""
    scalars = entries([float(t) for t in torques], None, [[float(a) for a in values]])
    points = table_points_numeric(scalars.__getitem__, 0.0)

    def law(x):
        return table_law_numeric(np.asarray(x, dtype=float), points)

    return law


def _knots(dead_band: float, top: float, span: int = SPAN_POINTS) -> list[float]:
    return [0.0, dead_band] + [dead_band + (top - dead_band) * j / span for j in range(1, span + 1)]


def _blocks(time_s: np.ndarray, block_s: float) -> np.ndarray:
    return np.floor((time_s - time_s[0]) / block_s).astype(int)


def _sandwich(jacobian: np.ndarray, residual: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    """Covariance of a least-squares fit with residuals correlated within blocks (the cluster sandwich), scaled
    so that it is never smaller than the plain one of independent residuals."""
    n, k = jacobian.shape
    bread = pm.generalized_inverse(pm.matmul(jacobian.T, jacobian))
    meat = np.zeros((k, k))
    for b in np.unique(blocks):
        g = pm.matmul(jacobian[blocks == b].T, residual[blocks == b])
        meat += np.outer(g, g)
    count = len(np.unique(blocks))
    correction = count / max(count - k, 1)
    plain = bread * pm.dot(residual, residual) / max(n - k, 1)
    cluster = pm.matmul(pm.matmul(bread, meat), bread) * correction
    return np.where(np.diag(cluster)[:, None] * np.diag(cluster)[None, :] >=
                    np.diag(plain)[:, None] * np.diag(plain)[None, :], cluster, plain)


@dataclass
class _Map:
    torques: list[float]
    current: list[float]
    centre: float
    covariance: np.ndarray
    jacobian_values: np.ndarray  # d(current at the points) / d(parameters)
    representation: np.ndarray  # A: the table's own error at each point (a standard error)
    torque_step: float  # N m: the logged torque's rounding
    dead_band_representation: float  # N m: the table's own error of its dead band (the change from a coarser one)
    rms: float
    noise: float
    hysteresis: float
    hysteresis_se: float
    hysteresis_Nm: float

    def law(self):
        return _map_law(self.torques, self.current)


def _currents(x) -> list[float]:
    return [0.0, 0.0, *(float(c) for c in np.cumsum(pm.exp(np.asarray(x[2:], dtype=float))))]


def _fit_table(S: np.ndarray, i: np.ndarray, top: float, d0: float, span: int):
    """The least-squares table of `span` points beyond the dead band: parameters (D, c, log rises), residuals and
    their Jacobian."""
    magnitude = np.abs(S)
    active = magnitude > d0
    start = []
    previous = 0.0
    for k in _knots(d0, top, span)[2:]:
        near = active & (np.abs(magnitude - k) <= (top - d0) / span)
        level = float(np.median(np.abs(i[near]))) if near.any() else previous + 1.0
        start.append(float(pm.log(max(level - previous, 0.05))))  # the portable log, as _currents' exp
        previous = max(level, previous + 0.05)
    x0 = np.array([d0, 0.0, *start])

    def residual(x):
        return _map_law(_knots(x[0], top, span), _currents(x))(S - x[1]) - i

    lower = np.r_[0.01, -0.5, np.full(span, -12.0)]
    upper = np.r_[0.9 * top, 0.5, np.full(span, 8.0)]
    return bounded_least_squares(residual, np.clip(x0, lower + 1e-9, upper - 1e-9), lower, upper)


def bounded_least_squares(residual, x0: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                          max_iterations: int = 200, tolerance: float = 1e-12):
    """(x, residual(x), its Jacobian) minimising the sum of squares of `residual` within the box [lower, upper]:
    Levenberg-Marquardt with a forward-difference Jacobian, on the fixed-order arithmetic of parksteer.portable,
    so that the same records give the same table on any machine (a BLAS-backed solver rounds by its kernel)."""
    def jacobian(x, r):
        out = np.empty((r.size, x.size))
        for j in range(x.size):
            h = 1e-7 * max(1.0, abs(float(x[j])))
            moved = x.copy()
            moved[j] = x[j] + h if x[j] + h <= upper[j] else x[j] - h
            out[:, j] = (residual(moved) - r) / (moved[j] - x[j])
        return out

    x = np.clip(np.asarray(x0, dtype=float), lower, upper)
    r = residual(x)
    rss = pm.dot(r, r)
    J = jacobian(x, r)
    damping = 1e-3
    for _ in range(max_iterations):
        JTJ = pm.matmul(J.T, J)
        scale = np.diag(JTJ).copy()
        scale[scale <= 0] = 1.0
        try:
            step = -pm.solve(JTJ + damping * np.diag(scale), pm.matmul(J.T, r))
        except pm.LinAlgError:
            damping *= 4.0
            continue
        trial = np.clip(x + step, lower, upper)
        if not np.any(trial != x):
            break
        trial_r = residual(trial)
        trial_rss = pm.dot(trial_r, trial_r)
        if trial_rss < rss:
            done = rss - trial_rss <= tolerance * rss
            x, r, rss = trial, trial_r, trial_rss
            J = jacobian(x, r)
            damping = max(damping / 3.0, 1e-12)
            if done:
                break
        else:
            damping *= 4.0
            if damping > 1e12:
                break
    return x, r, J


def fit_map(files: list[FileData]) -> _Map:
    """Step 1 of the module docstring: the current's map of the logged torsion-bar torque."""
    from ...model.numeric.assisted import rack_speed_mps

    S = np.concatenate([f.torque_Nm for f in files])
    i = np.concatenate([f.motor for f in files])
    times = np.concatenate([f.time_s + 1e6 * k for k, f in enumerate(files)])
    magnitude = np.abs(S)
    top = float(np.max(magnitude))  # the last point at the largest torque: no sample on the straight continuation
    step_i = max(max(f.measurement.quantisation_step(f.motor_column) for f in files), 1e-6)
    quiet = magnitude[np.abs(i) <= 2.0 * step_i + 0.02 * np.max(np.abs(i))]
    d0 = float(np.clip(np.quantile(quiet, 0.9) if quiet.size else 0.1 * top, 0.02, 0.6 * top))
    x, r, jacobian = _fit_table(S, i, top, d0, SPAN_POINTS)
    covariance = _sandwich(jacobian, r, _blocks(times, BLOCK_S))
    # the points' currents against the parameters (exp of the rises, summed)
    rises = pm.exp(np.asarray(x[2:], dtype=float))
    jac_values = np.zeros((SPAN_POINTS + 2, len(x)))
    for k in range(2, SPAN_POINTS + 2):
        jac_values[k, 2:k + 1] = rises[: k - 1]
    # what a table of these points cannot follow: the change at the points from a table of two points fewer (the
    # cubic's error falls as the spacing's fourth power, so the finer table's is less than half of it), taken
    # as a standard error of its own beside the noise's
    coarse, _, _ = _fit_table(S, i, top, d0, SPAN_POINTS - 2)
    coarse_law = _map_law(_knots(coarse[0], top, SPAN_POINTS - 2), _currents(coarse))
    points = np.array(_knots(x[0], top))
    representation = np.abs(coarse_law(points) - np.array(_currents(x))) / 2.0
    # ... and the current's rounding: the control unit gives one current at one reading of the sensor, so repeated
    # samples at a torque level carry the same rounding error and do not average it away
    representation = pm.hypot(representation, np.full_like(representation, step_i / math.sqrt(12.0)))
    representation[:2] = 0.0
    dead_band_representation = abs(float(coarse[0] - x[0])) / 2.0
    torques, current = _knots(x[0], top), _currents(x)
    # what the two channels' rounding allows: the current's step, and the torque's through the map's slope (the
    # control unit reads the sensor the log reads, so the sensor's own noise moves both together and is no scatter)
    law = _map_law(torques, current)
    slope = (law(S - x[1] + 1e-4) - law(S - x[1] - 1e-4)) / 2e-4
    step_s = max(f.measurement.quantisation_step(TORQUE) for f in files)
    noise_i, noise_s = step_i / math.sqrt(12.0), step_s / math.sqrt(12.0)
    on = magnitude > x[0] + 0.05 * (top - x[0])
    expected = float(np.sqrt(noise_i ** 2 + np.mean((slope[on] * noise_s) ** 2))) if on.any() else float(noise_i)
    rms = float(np.sqrt(np.mean(r[on] ** 2))) if on.any() else float(np.sqrt(np.mean(r ** 2)))
    # hysteresis: the residual (signed with the torque) while the steering turns outward (the torque's way, the
    # motor driving) against while it comes back, at equal torque
    rate = np.concatenate([rack_speed_mps(f.rack, f.time_s) for f in files])
    loading = np.sign(S) * rate
    moving = np.abs(rate) > 0.1 * np.quantile(np.abs(rate), 0.9)
    signed = -np.sign(S) * r  # measured less the map, in the torque's direction
    use = on & moving
    up, down = use & (loading > 0), use & (loading < 0)
    if up.sum() > 10 and down.sum() > 10:
        design = np.column_stack([up[use].astype(float), down[use].astype(float)])
        coef = pm.lstsq(design, signed[use])
        resid = signed[use] - pm.matmul(design, coef)
        cov = _sandwich(design, resid, _blocks(times[use], BLOCK_S))
        contrast = np.array([1.0, -1.0])
        hysteresis, hysteresis_se = float(coef[0] - coef[1]), math.sqrt(pm.dot(contrast, pm.matmul(cov, contrast)))
        hysteresis_Nm = hysteresis / float(np.median(slope[use])) if np.median(slope[use]) > 0 else math.nan
    else:
        hysteresis, hysteresis_se, hysteresis_Nm = 0.0, math.inf, math.nan
    return _Map(torques, current, float(x[1]), covariance, jac_values, representation, step_s,
                dead_band_representation, rms, expected, hysteresis,
                hysteresis_se, hysteresis_Nm)
