"""Candidates within ``bic_indistinguishable`` of the named one: where the two fitted models differ most,
among the conditions the data do not cover (module docstring of :mod:`parksteer.diagnose.select`, step 7)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...names import SURFACES
from ...model.symbolic.components import Effect
from ..engine import ReplayEngine
from ..problem import Problem
from ..replay import Replay
from ..state import Candidate, DiagnosisState, Separation
from .base import Stage
from .select import may_headline


def conditions_not_covered(problem: Problem) -> list[tuple[str, str]]:
    covered = {(f.case, f.surface) for f in problem.files}
    return [(c, s) for c in problem.params.case_names for s in SURFACES if (c, s) not in covered]


def differences_by_condition(engine: ReplayEngine, problem: Problem, runs: list[tuple[list[Effect], dict[str, float]]]
                             ) -> list[list[dict]]:
    """The first run and each other ((effects, overrides) each), replayed on the first file's rack under each
    load case and surface the data do not cover: for each other run, one row per condition with the RMS torque
    difference from the first there, in N m and in the file's noise floors. The conditions are independent, spread
    over the engine's workers, a condition's runs in one process, where runs of the same effect set share one
    prepared replay (each run is prepared once, not once a worker)."""
    f = problem.files[0]
    conditions = conditions_not_covered(problem)

    def replayed(condition: tuple[str, str]) -> list[np.ndarray]:
        case, surface = condition
        replays: dict[int, Replay] = {}
        predicted = []
        for effects, overrides in runs:
            if id(effects) not in replays:
                replays[id(effects)] = engine.new_replay(effects, case, surface, problem.params, f.rack, f.time_s)
            predicted.append(replays[id(effects)].torque(overrides))
        return predicted

    rows: list[list[dict]] = [[] for _ in runs[1:]]
    for (case, surface), predicted in zip(conditions, engine.map(replayed, conditions)):
        for out, other in zip(rows, predicted[1:]):
            difference = float(np.sqrt(np.mean((predicted[0] - other) ** 2)))
            out.append({"case": case, "surface": surface, "predicted_difference_rms_Nm": difference,
                        "over_noise_floor": difference / f.noise.total_rms})
    return rows


def separation(engine: ReplayEngine, problem: Problem, best: Candidate, other: Candidate) -> Separation:
    """Replay both fitted models on the first file's rack under each uncovered condition (module docstring)."""
    rows = differences_by_condition(engine, problem, [(c.signature.model, c.refit.overrides) for c in (best, other)])[0]
    top = max(rows, key=lambda r: r["over_noise_floor"])
    return Separation(other.name, float(other.delta_bic), top["case"], top["surface"],
                      top["predicted_difference_rms_Nm"], top["over_noise_floor"], tuple(rows))


class Separate(Stage):
    name = "separation"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        if state.verdict != "missing":
            return state
        best, threshold = state.best_candidate, state.settings.bic_indistinguishable
        separations = tuple(separation(engine, state.problem, best, c) for c in state.candidates
                            if c.refit is not None and c.name != best.name
                            and c.delta_bic >= best.delta_bic - threshold
                            and may_headline(state.problem, c, state.settings))
        return replace(state, indistinguishable=separations)
