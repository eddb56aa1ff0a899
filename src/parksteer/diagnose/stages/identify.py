"""What these data fix: each calibrated parameter fixed or not, and the test that would fix it."""

from __future__ import annotations

import math
from dataclasses import replace

from ...model.symbolic.components import power_assist_of
from ..calibrate import free_strengths
from ..fitting import Fit
from ..problem import Problem
from ..settings import DEFAULT_SETTINGS, DiagnosisSettings
from ..state import DiagnosisState
from ..engine import ReplayEngine
from .base import Stage
from .separate import differences_by_condition
from .user_effect import conditioned_on_strengths


def identification(engine: ReplayEngine, problem: Problem, calibration: Fit,
                   settings: DiagnosisSettings = DEFAULT_SETTINGS, assisted: bool = False) -> list[dict]:
    """What these data fix: every parameter the method calibrates (with the angle, also what only the angle
    shows), each with a status and, where it is not fixed, the test that would fix it.

    ``fixed``: calibrated, its 95 % interval within ``identified_relative_halfwidth`` of its value either side
    (a phase-like parameter: ``identified_phase_halfwidth_rad``); ``not fixed``: calibrated with a wider
    interval, replayed at both ends of it on the first file's rack under each load case and surface the data do
    not cover, the condition where the torque moves most (RMS, in noise floors) named as the test that fixes
    it; ``not calibrated``: a parameter only the handwheel angle shows, in a diagnosis without it (an `assisted`
    car's: no test, since the diagnosis refuses an assisted car's angle).
    """
    free = [q.key for q in free_strengths(calibration.effects)]
    # with a user's free strengths: the car's intervals with them held at their fit (stages/user_effect.py)
    intervals = (conditioned_on_strengths(calibration, problem, free, settings.interval_block_s) if free
                 else calibration.intervals(problem, settings.interval_block_s))
    offsets = {key for key, _, _ in settings.calibrated_with_angle_offsets}
    out = []
    for key in [*settings.calibrated_parameters, *settings.calibrated_with_angle, *sorted(offsets)]:
        if key not in intervals:
            if not problem.uses_angle and (key in settings.calibrated_with_angle or key in offsets):
                out.append({"parameter": key, "status": "not calibrated", "value": None, "ci95": None,
                            "fixed_by": None if assisted else "a handwheel angle channel, with the rack logged on "
                                                              "12 bits or finer (parksteer diagnose --angle)"})
            continue
        entry = intervals[key]
        value, ci = entry["value"], entry["ci95"]
        if ci is None or not all(math.isfinite(c) for c in ci):
            halfwidth = math.inf
        else:
            halfwidth = (ci[1] - ci[0]) / 2
        limit = settings.identified_phase_halfwidth_rad if key in offsets \
            else settings.identified_relative_halfwidth * abs(value)
        row = {"parameter": key, "status": "fixed" if halfwidth <= limit else "not fixed", "value": value,
               "ci95": ci, "fixed_by": None}
        if row["status"] == "not fixed" and math.isfinite(halfwidth):
            row["fixed_by"] = _fixing_test(engine, problem, calibration, key, ci[0], ci[1])
        out.append(row)
    return out


def _fixing_test(engine: ReplayEngine, problem: Problem, calibration: Fit, key: str, low: float, high: float
                 ) -> dict | None:
    """The uncovered condition where the parameter's two interval ends move the replayed torque most."""
    base = calibration.overrides
    rows = differences_by_condition(engine, problem, [(calibration.effects, {**base, key: v}) for v in (low, high)])[0]
    return max(rows, key=lambda r: r["over_noise_floor"]) if rows else None


class Identify(Stage):
    name = "identification"

    def message(self, state: DiagnosisState) -> str:
        return "what these data fix: the calibrated parameters' intervals"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        found = identification(engine, state.problem, state.calibration, state.settings,
                               assisted=power_assist_of(state.base) is not None)
        return replace(state, identification=tuple(found))
