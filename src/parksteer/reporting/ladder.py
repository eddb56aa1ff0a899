"""The error ladder: the error as the model grows one step at a time, down to the noise floor.

Rungs: the paper's model at its own parameter values; the same model with its uncertain
parameters calibrated to the files; then, while the diagnosis names a missing effect, the
model with that effect added (its strength fitted with the calibrated parameters). After
each addition the ladder stops if the weighted error has reached the floor (within
``ADEQUATE_RMS_FACTOR``; with a fitted handwheel angle, the weighted error of both signals); otherwise the grown model is diagnosed again (its added strengths
calibrated with the base parameters), up to ``LADDER_MAX_STEPS`` additions. A calibrated value named as changed
since a baseline (``changed:<key>``) is the ladder's last rung: it adds no effect whose strength a next diagnosis
could fit, and that diagnosis would not hold the baseline's values.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..model.symbolic.components import Effect, resolve_effects
from ..parameters import Parameters
from ..diagnose.baseline_changed import changed_key
from ..diagnose.settings import DEFAULT_SETTINGS, DiagnosisSettings
from ..diagnose.problem import FileData
from ..diagnose.select import Diagnosis, diagnose


@dataclass
class Ladder:
    rungs: list[dict]
    diagnoses: list[Diagnosis]
    noise_floor_Nm: float
    attainable_floor_Nm: float

    def as_dict(self) -> dict:
        return {"rungs": self.rungs, "noise_floor_Nm": self.noise_floor_Nm,
                "attainable_floor_Nm": self.attainable_floor_Nm}


def _rung(label: str, effects: list[Effect], statistics: dict, parameters: dict[str, float]) -> dict:
    return {
        "label": label,
        "effects": [e.name for e in effects],
        "rms_Nm": statistics["rms_Nm"],
        "weighted_rms_Nm": statistics["weighted_rms_Nm"],
        "peak_Nm": statistics["peak_Nm"],
        "over_floor": statistics["weighted_rms_Nm"] / statistics["noise_floor_Nm"],
        "parameters": dict(sorted(parameters.items())),
        # with a fitted angle: its residual, and the weighted error of both signals together over the floor
        **({"angle_rms_rad": statistics["angle"]["rms_rad"],
            "over_floor_both_signals": (statistics["weighted_rss"] / statistics["samples"]) ** 0.5}
           if "angle" in statistics else {}),
    }


def _at_floor(statistics: dict, settings: DiagnosisSettings) -> bool:
    """Whether the weighted error is within the adequate factor of the floor (with a fitted angle, of both signals)."""
    if "angle" in statistics:
        return (statistics["weighted_rss"] / statistics["samples"]) ** 0.5 <= settings.adequate_rms_factor
    return statistics["weighted_rms_Nm"] <= settings.adequate_rms_factor * statistics["noise_floor_Nm"]


def error_ladder(files: list[FileData], params: Parameters, effects=None, first: Diagnosis | None = None,
                 settings: DiagnosisSettings | None = None, workers: int = 1) -> Ladder:
    """Rungs from the paper's model to the model with every effect the diagnoses name (module docstring).

    `first` is a diagnosis of the same files and model already made (it is not repeated); the ladder uses its
    settings, else `settings` (by default the documented ones). `workers`: as for
    :func:`parksteer.diagnose.select.diagnose`.
    """
    settings = settings or (first.settings if first is not None else DEFAULT_SETTINGS)
    base = resolve_effects(effects) if not (isinstance(effects, list) and effects
                                             and isinstance(effects[0], Effect)) else effects
    diagnosis = first if first is not None else diagnose(files, params, base, settings=settings, workers=workers)
    nominal = diagnosis.statistics(diagnosis.nominal_predictions)
    calibrated = diagnosis.statistics(diagnosis.calibration.predictions)
    rungs = [
        _rung("paper's model", base, nominal, {}),
        _rung("calibrated", base, calibrated, diagnosis.calibration.values),
    ]
    diagnoses = [diagnosis]
    strengths: dict[str, float] = {}
    model = list(base)
    for _ in range(settings.ladder_max_steps):
        if diagnosis.verdict != "missing":
            break
        best = diagnosis.best
        fit = best.refit
        statistics = diagnosis.statistics(fit.predictions)
        model = list(best.signature.model)
        rungs.append(_rung(f"+ {best.name}", model, statistics, fit.values))
        if changed_key(best.name) is not None or _at_floor(statistics, settings):
            break
        strengths[best.signature.key] = best.signature.probe
        diagnosis = diagnose(files, params, model, strengths=dict(strengths), start=fit.values, settings=settings,
                             workers=workers)
        diagnoses.append(diagnosis)
    return Ladder(rungs, diagnoses, calibrated["noise_floor_Nm"], calibrated["attainable_floor_Nm"])
