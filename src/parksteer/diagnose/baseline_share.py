"""A held form with no share in what the calibration carries (:func:`share_free_fit`, :func:`refit_in_basis`).

The signature's form (:func:`parksteer.diagnose.suggest.suggest`) is a sum of knot strengths; fitted together with
the car's calibrated values it can take over part of what one of them carries: knots of rack friction summing to a
uniform force are a Coulomb rack friction, and the healthy record fixes only their sum. The split is then the fit's
accident, and a later record, judged with both held, meets a friction shaped by the knots where the car has a
uniform one. So the baseline ranks the form's strength directions by the share of their weighted torque, on the
healthy records, that the calibrated values' sensitivities reproduce (:func:`carried_shares`, at the calibration
with the form absent), and fits the strengths only in the directions of share at most one half: a direction the
calibration reproduces more of than it leaves is the calibration's. For knots against a Coulomb rack friction
alone, their mean has share 1 and the rest share 0. Confining every direction with any share (``C s = 0``,
``C = J_c^T J_s``) would leave a form of few knots hardly a direction: each knot's torque correlates a little with
some calibrated value's.

The strengths are fitted in coordinates of that subspace, ``s = s_0 + F z`` (F a basis of the free directions):
:class:`CoordinateEngine` turns the coordinates into strengths for the replay, so the fitter is the calibration's
own (:func:`parksteer.diagnose.fitting.least_squares`, :func:`~parksteer.diagnose.fitting.polish`)."""

from __future__ import annotations

import dataclasses

import numpy as np

from .. import portable as pm
from .calibrate import calibration_parameters
from .engine import ReplayEngine
from .fitting import Fit, FitParameter, finite_difference_jacobian, least_squares, polish
from .problem import Problem
from .settings import DiagnosisSettings

COORDINATE = "baseline_share.z"  # the coordinates' keys: COORDINATE + index; never a model quantity


@dataclasses.dataclass(frozen=True)
class ShareFreeBasis:
    """Strengths `keys` confined to ``s = origin + basis @ z``: `basis` (K x m) spans the directions whose torque the
    calibrated values reproduce for at most CARRIED_SHARE; `calibrated` names those values."""

    keys: tuple[str, ...]
    basis: np.ndarray
    calibrated: tuple[str, ...]

    def strengths(self, origin: np.ndarray, z: np.ndarray) -> np.ndarray:
        return origin + pm.matmul(self.basis, z)


CARRIED_SHARE = 0.5  # confine a direction whose torque the calibrated values reproduce more of than the form


def carried_shares(jacobian: np.ndarray, calibrated: list[int], strengths: list[int]) -> tuple[np.ndarray,
                                                                                                  np.ndarray]:
    """The form's strength directions ranked by the share of their weighted torque that the calibrated values'
    sensitivities reproduce: the generalized eigenproblem ``J_s^T P_c J_s v = share J_s^T J_s v`` (P_c the
    projector on the calibrated columns), solved as a symmetric one through the Cholesky factor of ``J_s^T J_s``
    (columns scaled to unit length first). Returns the shares (descending, each in [0, 1]) and the directions
    (columns, in the strengths' own units). A strength that moves no torque is left out (share 0, its own axis)."""
    strength_columns = np.asarray(jacobian, dtype=float)[:, strengths]
    calibrated_columns = np.asarray(jacobian, dtype=float)[:, calibrated]
    k = strength_columns.shape[1]
    lengths = pm.norm(strength_columns, axis=0)
    moving = np.flatnonzero(lengths > 0.0)
    unit = strength_columns[:, moving] / lengths[moving]
    shares, directions = np.zeros(k), np.zeros((k, k))
    still = np.setdiff1d(np.arange(k), moving)
    directions[still, len(moving) + np.arange(len(still))] = 1.0
    if len(moving) == 0:
        return shares, directions
    c_lengths = pm.norm(calibrated_columns, axis=0)
    c_unit = calibrated_columns[:, c_lengths > 0.0] / c_lengths[c_lengths > 0.0]
    cross = pm.matmul(c_unit.T, unit)  # C = J_c^T J_s
    carried = pm.matmul(cross.T, pm.matmul(pm.generalized_inverse(pm.matmul(c_unit.T, c_unit)), cross))
    low = pm.cholesky(pm.matmul(unit.T, unit))
    half = pm.solve(low, carried)  # L^-1 A
    reduced = pm.solve(low, half.T)  # L^-1 A L^-T
    values, vectors = pm.symmetric_eigen((reduced + reduced.T) / 2.0)
    shares[:len(moving)] = np.clip(values, 0.0, 1.0)
    directions[moving, :len(moving)] = pm.solve(low.T, vectors) / lengths[moving][:, None]
    return shares, directions


def share_free_basis(jacobian: np.ndarray, calibrated: list[int], strengths: list[int], keys: list[str],
                     names: list[str]) -> ShareFreeBasis:
    """The strengths' free directions from a Jacobian (columns `calibrated` and `strengths`): those of
    :func:`carried_shares` whose torque the calibrated values reproduce for at most CARRIED_SHARE, each scaled to
    unit length (their torques orthogonal to every confined direction's)."""
    shares, directions = carried_shares(jacobian, calibrated, strengths)
    free = directions[:, shares <= CARRIED_SHARE]
    lengths = pm.norm(free, axis=0)
    return ShareFreeBasis(tuple(keys), free / np.where(lengths > 0.0, lengths, 1.0), tuple(names))


class CoordinateEngine:
    """A replay engine whose overrides may hold coordinates ``COORDINATE<i>``: they are turned into the strengths
    ``origin + basis @ z`` before the replay (everything else passes through to `engine`)."""

    def __init__(self, engine: ReplayEngine, share: ShareFreeBasis, origin: np.ndarray):
        self.engine, self.share, self.origin = engine, share, np.asarray(origin, dtype=float)

    @property
    def evaluations(self) -> int:
        return self.engine.evaluations

    def strength_values(self, overrides: dict[str, float]) -> dict[str, float]:
        z = np.array([overrides[coordinate_key(i)] for i in range(self.share.basis.shape[1])])
        return dict(zip(self.share.keys, (float(v) for v in self.share.strengths(self.origin, z))))

    def predict(self, problem: Problem, effects, overrides: dict[str, float] | None = None):
        overrides = dict(overrides or {})
        strengths = self.strength_values(overrides)
        plain = {k: v for k, v in overrides.items() if not k.startswith(COORDINATE)}
        return self.engine.predict(problem, effects, {**plain, **strengths})


def coordinate_key(i: int) -> str:
    return f"{COORDINATE}{i}"


def _coordinates(share: ShareFreeBasis, step: float) -> list[FitParameter]:
    """The coordinates as fitted parameters, as they stand (0 at the origin), each stepped by `step` (a strength
    moving the torque by about a noise floor); their bounds far outside any steering force."""
    from ..model.symbolic.shapes import FORCE_BOUND_N

    bound = FORCE_BOUND_N * max(len(share.keys), 1)
    return [FitParameter(coordinate_key(i), "offset", 0.0, -bound, bound, step)
            for i in range(share.basis.shape[1])]


def _in_strengths(engine: ReplayEngine, problem: Problem, fit: Fit, share: ShareFreeBasis, origin: np.ndarray,
                  plain: list[FitParameter], settings: DiagnosisSettings) -> Fit:
    """The fit in coordinates written as a fit of the strengths themselves (its Jacobian taken afresh there), so
    that its values and intervals are the strengths'."""
    proxy = CoordinateEngine(engine, share, origin)
    values = {**fit.fixed, **fit.values}
    values.update(proxy.strength_values(values))
    theta = np.array([p.theta(values[p.key]) for p in plain])
    fixed = {k: v for k, v in fit.fixed.items() if k not in share.keys}
    predictions = engine.predict(problem, fit.effects, {**fixed, **{p.key: values[p.key] for p in plain}})
    jacobian = finite_difference_jacobian(engine, problem, fit.effects, plain, theta, fixed, predictions)
    return Fit(fit.effects, plain, theta, fixed, predictions, problem.weighted(predictions), jacobian,
               fit.iterations, fit.evaluations, fit.history)


def share_free_fit(problem: Problem, calibration: Fit, shape, places: dict, keys: list[str],
                   settings: DiagnosisSettings) -> tuple[Fit, ShareFreeBasis]:
    """The form `shape` (its knots `places`, its strengths `keys`) fitted with the calibrated parameters of
    `calibration`, its strengths confined to the directions the calibration does not carry (the module docstring); from the calibration and zero strengths. Returns the fit, written in the strengths, and the
    basis."""
    from .statistics import fit_statistics

    model = sorted([*calibration.effects, shape], key=lambda e: e.name)
    engine = ReplayEngine()
    floor = fit_statistics(problem, calibration.predictions)["noise_floor_Nm"]
    ratio = problem.params.sections["steering"]["handwheel_to_rack_ratio"]
    step = floor * ratio if keys and shape.quantities[0].unit == "N" else floor
    plain = [dataclasses.replace(p, step=step) if p.key in keys else p
             for p in calibration_parameters(engine, problem, model, settings=settings)]
    start = {p.key: t for p, t in zip(calibration.parameters, calibration.theta)}
    theta0 = np.array([start.get(p.key, 0.0) for p in plain])
    fixed = {**calibration.fixed, **places}
    predictions = engine.predict(problem, model, {**fixed, **{p.key: p.value(t) for p, t in zip(plain, theta0)}})
    jacobian = finite_difference_jacobian(engine, problem, model, plain, theta0, fixed, predictions)
    strength_columns = [i for i, p in enumerate(plain) if p.key in keys]
    calibrated_columns = [i for i, p in enumerate(plain) if p.key not in keys]
    share = share_free_basis(jacobian, calibrated_columns, strength_columns, [plain[i].key for i in strength_columns],
                             [plain[i].key for i in calibrated_columns])
    origin = np.zeros(len(share.keys))
    proxy = CoordinateEngine(engine, share, origin)
    parameters = [plain[i] for i in calibrated_columns] + _coordinates(share, step)
    theta = np.concatenate([theta0[calibrated_columns], np.zeros(share.basis.shape[1])])
    fit = least_squares(proxy, problem, model, parameters, theta, fixed, settings=settings,
                        refresh_at_end=not settings.calibration_polished)
    if settings.calibration_polished:
        fit = polish(proxy, problem, fit, settings)
    return _in_strengths(engine, problem, fit, share, origin, plain, settings), share


def refit_in_basis(engine: ReplayEngine, problem: Problem, model, share: ShareFreeBasis, origin: dict[str, float],
                   fixed: dict[str, float], step: float, settings: DiagnosisSettings) -> dict[str, float]:
    """The strengths refitted on `problem` within the free directions from `origin` (the calibrated values
    and the form's places held in `fixed`): the fitted strengths."""
    start = np.array([origin[k] for k in share.keys])
    proxy = CoordinateEngine(engine, share, start)
    parameters = _coordinates(share, step)
    held = {k: v for k, v in fixed.items() if k not in share.keys}
    fit = least_squares(proxy, problem, model, parameters, np.zeros(len(parameters)), held, settings=settings,
                        refresh_at_end=not settings.calibration_polished)
    if settings.calibration_polished:
        fit = polish(proxy, problem, fit, settings)
    return proxy.strength_values(fit.values)
