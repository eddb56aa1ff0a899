"""The verdict: missing, adequate or unexplained (module docstring of :mod:`parksteer.diagnose.select`, step 6)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..settings import DEFAULT_SETTINGS, DiagnosisSettings
from ..state import DiagnosisState
from ..engine import ReplayEngine
from .base import Stage


def trimmed_rms(weighted: np.ndarray, trim: float) -> float:
    """RMS of the weighted residuals without the largest fraction `trim` of them (in noise floors)."""
    magnitudes = np.sort(np.abs(np.asarray(weighted, dtype=float)))
    kept = magnitudes[: max(int(math.ceil((1.0 - trim) * len(magnitudes))), 1)]
    return float(np.sqrt(np.mean(kept**2)))


def choose_verdict(base_ratio: float, best_delta_bic: float | None, after_ratio: float | None,
                   explained: float | None, settings: DiagnosisSettings = DEFAULT_SETTINGS,
                   spread_ratio: float | None = None) -> str:
    """The verdict from the calibrated base model's weighted RMS over the floor, the best refit's BIC gain, its
    weighted RMS over the floor and the fraction of the excess it removes (module docstring, step 6).

    `spread_ratio` is the best refit's weighted RMS without its largest ``missing_ceiling_trim`` of residuals (by
    default `after_ratio`): the ceiling is checked on it, so that a misfit confined to a few instants does not
    block a name while one spread along the strokes does."""
    evidenced = best_delta_bic is not None and best_delta_bic > settings.bic_missing_threshold
    spread_ratio = after_ratio if spread_ratio is None else spread_ratio
    if (evidenced and spread_ratio <= settings.missing_rms_ceiling
            and (after_ratio <= settings.adequate_rms_factor
                 or (explained is not None and explained >= settings.explained_fraction_missing))):
        return "missing"
    if base_ratio <= settings.adequate_rms_factor and not evidenced:
        return "adequate"
    return "unexplained"


class Verdict(Stage):
    name = "verdict"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        settings, n, best = state.settings, state.problem.n, state.best_candidate
        base_rss = state.calibration.rss
        base_ratio = math.sqrt(base_rss / n)
        excess = base_rss - n
        explained = (base_rss - best.refit.rss) / excess if (best is not None and excess > 0) else None
        after_ratio = math.sqrt(best.refit.rss / n) if best is not None else None
        spread_ratio = trimmed_rms(best.refit.weighted, settings.missing_ceiling_trim) if best is not None else None
        verdict = choose_verdict(base_ratio, best.delta_bic if best is not None else None, after_ratio, explained,
                                 settings, spread_ratio)
        return replace(state, verdict=verdict, explained_fraction=explained)
