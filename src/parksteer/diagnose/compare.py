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

from dataclasses import dataclass, replace

import numpy as np

from ..measure.metrics import Comparison, compare
from ..model.symbolic.components import Effect, resolve_effects
from ..parameters import Parameters
from .problem import FileData, Problem, fit_statistics


@dataclass
class CompareResult:
    """Per-file comparisons and the pooled statistics of one model against the files."""

    effects: list[Effect]
    overrides: dict[str, float]
    files: list[FileData]
    predictions: list[np.ndarray]
    comparisons: list[Comparison]
    statistics: dict

    def as_dict(self) -> dict:
        files = []
        for f, c, m in zip(self.files, self.comparisons, self.predictions):
            summary = c.summary()
            delta = f.replay_uncertainty_Nm
            weighted = (f.torque_Nm - m) / f.sigma_Nm * f.noise.total_rms
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
        return {
            "effects": [e.name for e in self.effects],
            "overrides": dict(sorted(self.overrides.items())),
            "files": files,
            "overall": self.statistics,
        }


def compare_files(files: list[FileData], params: Parameters, effects=None,
                  overrides: dict[str, float] | None = None) -> CompareResult:
    """Replay every file through the model of `effects` (a spec or list) with `overrides`."""
    chosen = effects if isinstance(effects, list) and all(isinstance(e, Effect) for e in effects) \
        else resolve_effects(effects)
    overrides = dict(overrides or {})
    problem = Problem([replace(f, uses_angle=False) for f in files], params)  # a comparison is of the torque alone
    predictions = problem.predict(chosen, overrides)
    problem = problem.with_replay_uncertainty(chosen, overrides)
    files = list(problem.files)
    comparisons = [
        compare(f.time_s, f.torque_Nm, m, phases=f.phases,
                quantisation_step=f.measurement.quantisation_step("handwheel_torque_Nm"))
        for f, m in zip(files, predictions)
    ]
    return CompareResult(chosen, overrides, files, predictions, comparisons, fit_statistics(problem, predictions))
