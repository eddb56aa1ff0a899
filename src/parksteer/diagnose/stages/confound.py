"""Where each candidate the calibrated parameters take up in these data would show (module docstring of
:mod:`parksteer.diagnose.select`, step 8)."""

from __future__ import annotations

from dataclasses import replace

from ..fitting import Fit
from ..problem import Problem
from ..state import Candidate, DiagnosisState, confounded_candidates, frozen_mapping
from ..engine import ReplayEngine
from .base import Stage
from .separate import conditions_not_covered, differences_by_condition


def confound_tests(engine: ReplayEngine, problem: Problem, calibration: Fit, candidates: list[Candidate]
                   ) -> dict[str, dict | None]:
    """Where each candidate that the calibrated parameters take up in these data would show, by name: None if
    the data cover every load case and surface.

    A candidate at its probe strength changes the replayed torque by a few noise floors; the calibrated
    parameters, moved by the least-squares change that best cancels that change here (to first order: the score
    test's projection, Score.calibrated_equivalent), take up all but the part the score test sees (its
    identifiable fraction). The
    compensated model and the calibrated base model, which the data cannot tell apart, are then replayed on the
    first file's rack under each condition the data do not cover (the base model once for all candidates), and
    the condition where they differ most (RMS, in noise floors) is the measurement that would tell the candidate
    from the parameter: a king-pin friction, whose moment grows with the wheel load, from a rack friction, which
    does not.
    """
    if not candidates or not conditions_not_covered(problem):
        return {c.name: None for c in candidates}
    runs, summaries = [(calibration.effects, calibration.overrides)], []
    for candidate in candidates:
        signature, score = candidate.signature, candidate.score
        theta = calibration.theta - signature.probe * score.calibrated_equivalent
        moved = {p.key: p.value(t) for p, t in zip(calibration.parameters, theta)}
        runs.append((signature.model, {**calibration.fixed, **moved, signature.key: signature.probe}))
        # what the moved parameters leave of the probe's plain RMS change here (in the weighted sense)
        left_Nm = signature.rms_change_Nm * score.identifiable_fraction
        summaries.append({"strength": signature.probe, "change_here_rms_Nm": signature.rms_change_Nm,
                          "left_here_rms_Nm": left_Nm,
                          "left_here_over_noise_floor": left_Nm / problem.files[0].noise.total_rms,
                          "compensated": moved})
    out = {}
    for candidate, rows, summary in zip(candidates, differences_by_condition(engine, problem, runs), summaries):
        top = max(rows, key=lambda r: r["over_noise_floor"])
        out[candidate.name] = {"case": top["case"], "surface": top["surface"],
                               "predicted_difference_rms_Nm": top["predicted_difference_rms_Nm"],
                               "over_noise_floor": top["over_noise_floor"], **summary}
    return out


def _confounded(state: DiagnosisState) -> tuple[Candidate, ...]:
    return confounded_candidates(state.candidates, state.settings) if state.settings.confound_tests else ()


class Confound(Stage):
    name = "confound_tests"

    def message(self, state: DiagnosisState) -> str | None:
        confounded = _confounded(state)
        return ("where the confounded candidates would show: " + ", ".join(c.name for c in confounded)
                if confounded else None)

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        tested = confound_tests(engine, state.problem, state.calibration, list(_confounded(state)))
        return replace(state, confound_tests=frozen_mapping(tested))
