"""The calibration: which model parameters are fitted against measurement files, and how they start.

:func:`calibrate` fits the base model's uncertain parameters (the tyre friction coefficient, the rack friction force,
the carcass torsional stiffness) to all files at once, before any candidate is considered, so that a wrong value of
one is not taken for a missing effect; the same fitter refits a candidate's strength with them
(:mod:`parksteer.diagnose.select`). The fitter, the fitted model and its intervals are
:mod:`parksteer.diagnose.fitting`'s.
"""

from __future__ import annotations

import math

import numpy as np

from ..model.symbolic.components import Effect, quantity_of
from ..model.symbolic.system import CORE_PARAMETERS
from ..parameters import Quantity
from .settings import DEFAULT_SETTINGS, DiagnosisSettings
from .engine import ReplayEngine
from .fitting import Fit, FitParameter, least_squares, polish
from .problem import Problem

# A free strength's finite-difference step (free_parameter): of its declared range, or of its value when open.
FREE_STEP_OF_RANGE = 1e-3
FREE_STEP_OF_VALUE = 1e-2


def log_parameter(engine: ReplayEngine, problem: Problem, effects: list[Effect], key: str,
                  settings: DiagnosisSettings = DEFAULT_SETTINGS) -> FitParameter:
    """A positive parameter fitted as log(value / default), within calibration_range_factor of the default."""
    spec = quantity_of(key, effects)
    default = engine.replay(problem, effects, 0).value(key)
    factor = settings.calibration_range_factor
    return FitParameter(key, "log", default, max(spec.lower, default / factor), min(spec.upper, default * factor),
                        settings.calibration_relative_step)


def linear_parameter(effects: list[Effect], key: str, step: float) -> FitParameter:
    """A parameter fitted as it stands (a candidate's strength), within its bounds and never below zero."""
    spec = quantity_of(key, effects)
    return FitParameter(key, "linear", 1.0, max(spec.lower, 0.0), spec.upper, step)


def calibration_parameters(engine: ReplayEngine, problem: Problem, effects: list[Effect],
                           keys: tuple[str, ...] | None = None, strengths: dict[str, float] | None = None,
                           settings: DiagnosisSettings = DEFAULT_SETTINGS) -> list[FitParameter]:
    """The calibrated parameters the model has (an effect left out of the model leaves its keys out).

    Unless `keys` are given, with a fitted angle also what only the angle shows (the settings'
    ``calibrated_with_angle`` and ``calibrated_with_angle_offsets``: the column stiffness, the Hooke joint phase).
    `strengths` adds effects' strengths, fitted linearly, with their finite-difference steps.
    """
    if keys is None:
        logs, offsets = calibrated_keys(effects, problem.uses_angle, settings)
    else:
        used = _used_keys(effects)
        logs, offsets = [key for key in keys if key in used], []
    out = [log_parameter(engine, problem, effects, key, settings) for key in logs]
    out += [offset_parameter(engine, problem, effects, key, half_range, step) for key, half_range, step in offsets]
    out += [linear_parameter(effects, key, step) for key, step in (strengths or {}).items()]
    if keys is None:
        out += [free_parameter(engine, problem, effects, q) for q in free_strengths(effects)
                if q.key not in (strengths or {})]
    return out


def free_strengths(effects: list[Effect]) -> list[Quantity]:
    """The strengths the model's effects declare free (``Quantity.free``: a user's effect, fitted whenever it is in
    the model), in the order of the effects and of their quantities."""
    return [q for e in effects for q in e.quantities if q.free]


def free_parameter(engine: ReplayEngine, problem: Problem, effects: list[Effect], spec: Quantity) -> FitParameter:
    """A free strength fitted as it stands within its declared bounds, from the model's value (its default, or the
    value given); its finite-difference step a thousandth of its range (a strength of a linear law: any step
    within the range gives the same slope), or a hundredth of its value where the range is open."""
    value = engine.replay(problem, effects, 0).value(spec.key)
    span = spec.upper - spec.lower
    step = span * FREE_STEP_OF_RANGE if math.isfinite(span) else max(abs(value), 1.0) * FREE_STEP_OF_VALUE
    # an open bound is not a value the quantity may take: the fit stops just inside it
    lower = spec.lower if spec.lower_inclusive else math.nextafter(spec.lower, math.inf)
    upper = spec.upper if spec.upper_inclusive else math.nextafter(spec.upper, -math.inf)
    return FitParameter(spec.key, "offset", value, lower, upper, step)


def _used_keys(effects: list[Effect]) -> set[str]:
    return {k for e in effects for k in e.uses} | set(CORE_PARAMETERS)


def calibrated_keys(effects: list[Effect], uses_angle: bool, settings: DiagnosisSettings = DEFAULT_SETTINGS
                    ) -> tuple[list[str], list[tuple[str, float, float]]]:
    """(log-fitted keys, [(offset-fitted key, half range, step)]) a diagnosis calibrates in a model of `effects`:
    the settings' calibrated parameters the model has, and with a fitted angle what only the angle shows (the
    column's stiffness, the Hooke joint's angle and phase)."""
    used = _used_keys(effects)
    logs = [key for key in settings.calibrated_parameters if key in used]
    offsets = []
    if uses_angle:
        logs += [key for key in settings.calibrated_with_angle if key in used]
        offsets = [entry for entry in settings.calibrated_with_angle_offsets if entry[0] in used]
    return logs, offsets


def offset_parameter(engine: ReplayEngine, problem: Problem, effects: list[Effect], key: str, half_range: float,
                     step: float) -> FitParameter:
    """A parameter fitted as it stands within `half_range` of the model's value (an angle such as a phase)."""
    spec = quantity_of(key, effects)
    default = engine.replay(problem, effects, 0).value(key)
    return FitParameter(key, "offset", default, max(spec.lower, default - half_range),
                        min(spec.upper, default + half_range), step)


def calibrate(engine: ReplayEngine, problem: Problem, effects: list[Effect], fixed: dict[str, float] | None = None,
              keys: tuple[str, ...] | None = None, strengths: dict[str, float] | None = None,
              start: dict[str, float] | None = None, settings: DiagnosisSettings = DEFAULT_SETTINGS,
              announce=None) -> Fit:
    """Fit the base model's uncertain parameters (and any `strengths`, and the strengths its effects declare free:
    :func:`free_strengths`) to all files.

    From the model's defaults, or from the values in `start` where it has them. `announce`, if given, is called
    with the keys of the calibrated parameters (the base model's, and with a fitted angle the column's).
    """
    free = {q.key for q in free_strengths(effects)}
    # a free strength given a value (`fixed`, e.g. compare's --set) keeps it
    parameters = [p for p in calibration_parameters(engine, problem, effects, keys, strengths, settings)
                  if not (p.key in free and p.key in (fixed or {}))]
    if announce is not None:
        announce([p.key for p in parameters if p.key not in (strengths or {}) and p.key not in free])
    start = start or {}
    theta0 = np.array([p.theta(start[p.key]) if p.key in start else
                       {"log": 0.0, "offset": p.reference}.get(p.transform, p.lower)
                       for p in parameters])
    moving = [i for i, p in enumerate(parameters) if p.key in free and p.key not in start]
    if moving and len(moving) < len(parameters):
        # A user's effect starts from its strengths' values (a suggested file's: its own fit): the car's parameters
        # are calibrated first with those held, then everything together from there. Fitted together from the
        # parameter file's values at once, a form that overlaps a calibrated parameter (knots of rack friction
        # summing to a uniform one) wanders along the valley where the two trade, to the same error but other values.
        rest = [i for i in range(len(parameters)) if i not in moving]
        held = {**(fixed or {}), **{parameters[i].key: parameters[i].value(theta0[i]) for i in moving}}
        first = least_squares(engine, problem, effects, [parameters[i] for i in rest], theta0[rest], held,
                              settings=settings)
        theta0 = theta0.copy()
        theta0[rest] = first.theta
    fit = least_squares(engine, problem, effects, parameters, theta0, fixed, settings=settings,
                        refresh_at_end=not settings.calibration_polished)
    return polish(engine, problem, fit, settings) if settings.calibration_polished else fit
