"""The base model's uncertain parameters calibrated to all files (:mod:`parksteer.diagnose.calibrate`), with the
strengths a user's effect in the model declares free."""

from __future__ import annotations

from dataclasses import replace

from ..calibrate import calibrate, free_strengths
from ..fitting import Fit
from ..problem import Problem
from ..engine import ReplayEngine
from ..state import DiagnosisState
from .base import Stage


def calibrated(state: DiagnosisState, engine: ReplayEngine, problem: Problem, announce=None) -> Fit:
    """The base model calibrated on `problem` with the state's strengths, start values and settings (the strengths
    held at a baseline's values kept)."""
    return calibrate(engine, problem, list(state.base), fixed=None if state.held is None else dict(state.held),
                     strengths=None if state.strengths is None else dict(state.strengths),
                     start=None if state.start is None else dict(state.start), settings=state.settings,
                     announce=announce)


class Calibrate(Stage):
    name = "calibration"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        free = free_strengths(list(state.base))
        also = (f", with the {len(free)} free strength(s) of " + ", ".join(sorted({q.section for q in free}))
                if free else "")
        fit = calibrated(state, engine, state.problem,
                         announce=lambda keys: state.progress("calibrating " + ", ".join(keys) + also))
        return replace(state, calibration=fit)
