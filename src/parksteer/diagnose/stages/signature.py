"""The residual's signature: what kind of effect the calibrated model lacks (:mod:`parksteer.diagnose.signature`),
read beside any verdict and kept as the state's output ``signature``."""

from __future__ import annotations

from ..signature import signature_of
from ..state import DiagnosisState
from ..engine import ReplayEngine
from .base import Stage


class ResidualSignature(Stage):
    name = "signature"

    def message(self, state: DiagnosisState) -> str | None:
        return "the residual's signature" if state.settings.residual_signature else None

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        if not state.settings.residual_signature:
            return state
        calibration = state.calibration
        signature = signature_of(state.problem.files, calibration.predictions, state.problem.params,
                                 calibration.overrides, calibration.jacobian, state.settings, engine.map)
        return state.with_output(self.name, signature)
