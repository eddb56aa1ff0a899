"""Every candidate outside the model: its signature at the calibrated model and its score test
(:mod:`parksteer.diagnose.candidates`)."""

from __future__ import annotations

from dataclasses import replace

from ..candidates import Signature, candidate_effects, probe_signature, score
from ..statistics import fit_statistics
from ..state import Candidate, DiagnosisState
from ..engine import ReplayEngine
from .base import Stage


class Score(Stage):
    name = "signatures_and_scores"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        problem, calibration, settings, base = state.problem, state.calibration, state.settings, list(state.base)
        testable, untestable = candidate_effects(base, dict(state.registry))
        floor = fit_statistics(problem, calibration.predictions)["noise_floor_Nm"]
        state.progress(f"ranking {len(testable)} candidates: " + ", ".join(e.name for e in testable))

        # Many candidates: one worker each (its model prepared once per file); each signature travels back
        # without its effects (a copy), which are put back here.
        def signature_of(effect) -> Signature:
            signature = probe_signature(engine, problem, base, effect, calibration.overrides,
                                        settings.probe_effect_noise_floors * floor, settings)
            return replace(signature, effect=None, model=None)

        candidates = []
        for effect, signature in zip(testable, engine.in_workers(problem, signature_of, testable, True)):
            signature = replace(signature, effect=effect, model=sorted([*base, effect], key=lambda e: e.name))
            candidates.append(Candidate(signature, score(signature, calibration)))
        return replace(state, candidates=tuple(candidates), untestable=tuple(untestable))
