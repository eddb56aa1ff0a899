"""The base model replayed at its default parameters, and each sample's replay uncertainty: the spread of the
torque (and angle) replayed from the racks the data allow equally well (:mod:`parksteer.diagnose.problem`)."""

from __future__ import annotations

from dataclasses import replace

from ..engine import ReplayEngine
from ..ensemble import with_replay_uncertainty as ensemble_uncertainty
from ..state import DiagnosisState
from .base import Stage


def with_replay_uncertainty(state: DiagnosisState, engine: ReplayEngine, effects, overrides,
                            keep_larger: bool = False):
    """The state's problem on files with their replay uncertainty under `effects` with `overrides`."""
    settings = state.settings
    return ensemble_uncertainty(engine, state.problem, effects, overrides, settings.replay_ensemble_draws,
                                settings.replay_ensemble_seed, keep_larger=keep_larger)


class ReplayUncertainty(Stage):
    name = "nominal_and_replay_uncertainty"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        problem = state.problem
        state.progress(f"{len(problem.files)} file(s), {problem.n} samples, {engine.workers} worker(s): replaying "
                       f"the base model and its replay uncertainty ({state.settings.replay_ensemble_draws} racks "
                       "per file)")
        if state.problem.uses_angle:
            state.progress("handwheel angle fitted beside the torque in "
                           + ", ".join(f.label for f in state.files if f.uses_angle))
        base = list(state.base)
        nominal = tuple(engine.predict(state.problem, base, {}))
        return replace(state, nominal=nominal, problem=with_replay_uncertainty(state, engine, base, state.start_values))
