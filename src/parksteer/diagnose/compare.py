"""``parksteer compare``: the model against measurement files, by phase of the cycle, beside the noise floor.

The measured rack of each file is smoothed and replayed through the model
(:mod:`parksteer.diagnose.replay`); the residual (measured - model) is summarised overall
and in each phase of the cycle (initial rise, carcass wind-up, sliding plateau, reversal,
return; :mod:`parksteer.measure.phases`) by :func:`parksteer.measure.metrics.compare`, beside
the noise floor the data allow. Two numbers say how good the replay itself can be: the
replay uncertainty (the torque spread over racks the data allow equally well; largest at the
reversals) and the weighted RMS, which counts each sample by its attainable error and so
equals the noise floor for a perfect model.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import UsageError
from ..measure.metrics import Comparison, compare
from ..model.symbolic.components import Effect, power_assist_of, quantity_of, resolve_effects
from ..parameters import Parameters
from .calibrate import calibrate, free_strengths
from .engine import ReplayEngine
from .ensemble import with_replay_uncertainty
from .problem import FileData, Problem
from .statistics import fit_statistics
from ..names import TORQUE


@dataclass
class CompareResult:
    """Per-file comparisons and the pooled statistics of one model against the files."""

    effects: list[Effect]
    overrides: dict[str, float]
    files: list[FileData]
    predictions: list[np.ndarray]
    comparisons: list[Comparison]
    statistics: dict
    fitted: dict = field(default_factory=dict)  # with a user's free strengths: each fitted value and its interval

    def as_dict(self) -> dict:
        files = []
        for f, c, m in zip(self.files, self.comparisons, self.predictions):
            summary = c.summary()
            delta = f.replay_uncertainty_Nm
            weighted = (f.torque_Nm - f.torque_part(m)) / f.sigma_Nm * f.noise.total_rms
            files.append({
                "file": f.label,
                "case": f.case,
                "surface": f.surface,
                "samples": f.n,
                "rack_smoothing": f.rack.summary(),
                "overall": summary["overall"],
                "by_phase": summary["by_phase"],
                "noise_floor": summary["noise_floor"],
                "rms_over_noise_floor": summary["rms_over_noise_floor"],
                "replay_uncertainty_rms_Nm": float(np.sqrt(np.mean(delta**2))) if delta is not None else 0.0,
                "weighted_rms_Nm": float(np.sqrt(np.mean(weighted**2))),
                "over_floor": float(np.sqrt(np.mean(weighted**2)) / f.noise.total_rms),
            })
            if f.uses_motor:  # an assisted car's motor channel: its residual beside its own noise floor
                residual = f.motor - f.motor_part(m)
                weighted_motor = residual / f.sigma_motor * f.motor_noise.total_rms
                files[-1]["motor"] = {"column": f.motor_column, "rms": float(np.sqrt(np.mean(residual**2))),
                                      "peak": float(np.max(np.abs(residual))),
                                      "weighted_rms": float(np.sqrt(np.mean(weighted_motor**2))),
                                      "noise_floor": f.motor_noise.as_dict()}
        out = {
            "effects": [e.name for e in self.effects],
            "overrides": dict(sorted(self.overrides.items())),
            "files": files,
            "overall": self.statistics,
        }
        if self.fitted:
            out["fitted"] = self.fitted
        return out


def check_torque_sensors(files: list[FileData], assisted: bool) -> None:
    """A record of a torsion bar (an assisted car's) replayed without an assist, or a handwheel's with one, is
    refused in one line: the model would be judged on another torque than the one measured."""
    for f in files:
        sensor = f.measurement.torque_sensor
        if sensor == "torsion_bar" and not assisted:
            raise UsageError(f"{f.measurement.path or f.label}: its torque is an assisted car's torsion-bar torque; "
                             "replay it with the car's assist (--vehicle FILE --with-assist, or --effects "
                             "+electric_assist_column|_pinion|_rack|+hydraulic_assist)")


def compare_files(files: list[FileData], params: Parameters, effects=None,
                  overrides: dict[str, float] | None = None) -> CompareResult:
    """Replay every file through the model of `effects` (a spec or list) with `overrides`; with a user's effect that
    declares free strengths, those not in `overrides` fitted first with the calibrated parameters
    (:func:`parksteer.diagnose.calibrate.calibrate`), the files then compared with the fitted model."""
    chosen = effects if isinstance(effects, list) and all(isinstance(e, Effect) for e in effects) \
        else resolve_effects(effects)
    overrides = dict(overrides or {})
    # A comparison is of the torque, and of an assisted car's motor channel beside it (its own residual and floor).
    assisted = power_assist_of(chosen) is not None
    check_torque_sensors(files, assisted)
    problem = Problem([replace(f, uses_angle=False, uses_motor=assisted and f.motor is not None) for f in files],
                      params)
    engine = ReplayEngine()
    predictions = engine.predict(problem, chosen, overrides)
    problem = with_replay_uncertainty(engine, problem, chosen, overrides)
    fitted = {}
    if any(q.key not in overrides for q in free_strengths(chosen)):
        # a user's effect declares free strengths: fitted with the calibrated parameters (those not --set), from
        # their values, and the files compared with the fitted model
        fit = calibrate(engine, problem, chosen, fixed=overrides)
        predictions, overrides = fit.predictions, {**overrides, **fit.values}
        fitted = {key: {**entry, "unit": quantity_of(key, chosen).unit}
                  for key, entry in fit.intervals(problem).items()}
    files = list(problem.files)
    comparisons = [
        compare(f.time_s, f.torque_Nm, f.torque_part(m), phases=f.phases,
                quantisation_step=f.measurement.quantisation_step(TORQUE))
        for f, m in zip(files, predictions)
    ]
    return CompareResult(chosen, overrides, files, predictions, comparisons, fit_statistics(problem, predictions),
                         fitted)
