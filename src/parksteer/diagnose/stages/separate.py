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
    difference from the first there, in N m and in the file's noise floors. The replays are independent, spread
    over the engine's workers; runs of the same effect set share one prepared replay per condition in each
    process."""
    f = problem.files[0]
    conditions = conditions_not_covered(problem)
    replays: dict[tuple[int, int], Replay] = {}

    def torque(job: tuple[int, int]) -> np.ndarray:
        condition, run = job
        effects, overrides = runs[run]
        if (condition, id(effects)) not in replays:
            case, surface = conditions[condition]
            replays[condition, id(effects)] = engine.new_replay(effects, case, surface, problem.params, f.rack,
                                                                f.time_s)
        return replays[condition, id(effects)].torque(overrides)

    jobs = [(condition, run) for condition in range(len(conditions)) for run in range(len(runs))]
    predicted = engine.map(torque, jobs)
    rows: list[list[dict]] = [[] for _ in runs[1:]]
    for condition, (case, surface) in enumerate(conditions):
        first = predicted[condition * len(runs)]
        for out, other in zip(rows, predicted[condition * len(runs) + 1:(condition + 1) * len(runs)]):
            difference = float(np.sqrt(np.mean((first - other) ** 2)))
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
