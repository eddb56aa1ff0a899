"""A held form with no share in what the calibration carries (:func:`share_free_fit`, :func:`refit_in_basis`).

The signature's form (:func:`parksteer.diagnose.suggest.suggest`) is a sum of knot strengths; fitted together with
the car's calibrated values it can take over part of what one of them carries: knots of rack friction summing to a
uniform force are a Coulomb rack friction, and the healthy record fixes only their sum. The split is then the fit's
accident (on the baseline benchmark's Dahl-tyre car the calibrated rack friction came out well under the car's,
the knots carrying the rest), and a later record, judged with both held, meets a friction shaped by the knots where
the car has a uniform one. So the baseline fits the form's strengths only in the directions whose torque is
orthogonal, on the healthy records, to every calibrated value's sensitivity: ``C s = 0`` with ``C = J_c^T J_s``
(weighted sensitivities, taken at the calibration with the form absent). To first order the calibrated values are
then those the healthy records give without the form, and the form carries only what none of them can; for a
friction of knots, the uniform part (their mean) is the rack friction's.

The strengths are fitted in coordinates of that subspace, ``s = s_0 + F z`` (F a basis of the null space of C):
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
NULL_RCOND = 1e-9  # a null-space direction of C: its projector's pivot above this fraction of the largest


@dataclasses.dataclass(frozen=True)
class ShareFreeBasis:
    """Strengths `keys` confined to ``s = origin + basis @ z``: `basis` (K x m) spans the directions whose torque is
    orthogonal to each calibrated value's sensitivity; `calibrated` names those values."""

    keys: tuple[str, ...]
    basis: np.ndarray
    calibrated: tuple[str, ...]

    def strengths(self, origin: np.ndarray, z: np.ndarray) -> np.ndarray:
        return origin + pm.matmul(self.basis, z)


def null_basis(constraints: np.ndarray) -> np.ndarray:
    """A basis (K x m) of the vectors s with ``constraints @ s = 0`` (rows scaled to unit length first; a row of
    zeros constrains nothing): the factor of the projector ``I - C^T (C C^T)^- C``."""
    rows = np.asarray(constraints, dtype=float)
    k = rows.shape[1]
    lengths = pm.norm(rows, axis=1)
    rows = rows[lengths > 0.0] / lengths[lengths > 0.0][:, None]
    if rows.shape[0] == 0:
        return np.eye(k)
    projector = np.eye(k) - pm.matmul(rows.T, pm.matmul(pm.generalized_inverse(pm.matmul(rows, rows.T)), rows))
    return pm.psd_factor((projector + projector.T) / 2.0, NULL_RCOND)


def share_free_basis(jacobian: np.ndarray, calibrated: list[int], strengths: list[int], keys: list[str],
                     names: list[str]) -> ShareFreeBasis:
    """The basis of the strengths' share-free directions from a Jacobian (columns `calibrated` and `strengths`)."""
    constraints = pm.matmul(jacobian[:, calibrated].T, jacobian[:, strengths])
    return ShareFreeBasis(tuple(keys), null_basis(constraints), tuple(names))


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
    `calibration`, its strengths confined to the directions orthogonal to every calibrated value's sensitivity (the
    module docstring); from the calibration and zero strengths. Returns the fit, written in the strengths, and the
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
    """The strengths refitted on `problem` within the share-free directions from `origin` (the calibrated values
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
