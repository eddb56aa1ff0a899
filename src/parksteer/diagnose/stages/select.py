"""The refits compared by an information criterion over the effective sample size (module docstring of
:mod:`parksteer.diagnose.select`, step 5), and compared again with the larger replay uncertainty where a
candidate is evidenced."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..fitting import Fit
from ..problem import Problem
from ..settings import DEFAULT_SETTINGS, DiagnosisSettings
from ..statistics import bic_gain, effective_samples, lag1_autocorrelation
from ..engine import ReplayEngine
from ..state import Candidate, DiagnosisState
from .base import Stage
from .replay_uncertainty import with_replay_uncertainty


def may_headline(problem: Problem, candidate: Candidate,
                 settings: DiagnosisSettings = DEFAULT_SETTINGS) -> bool:
    """Whether a refitted candidate may be the one a diagnosis names: its fitted strength above 0 and, with the
    setting ``headline_interval_clear_of_zero``, its 95 % interval (:meth:`parksteer.diagnose.fitting.Fit.
    intervals`) clear of 0. A candidate is absent at strength 0, so a refit that ends there says that the data do
    not need the candidate: whatever it gained in the BIC came from the calibrated parameters moving with it, not
    from the candidate."""
    key = candidate.signature.key
    strength = candidate.refit.values[key]
    if not settings.headline_interval_clear_of_zero:
        return bool(strength > 0.0)
    low = candidate.refit.intervals(problem, settings.interval_block_s)[key]["ci95"][0]
    return bool(strength > 0.0 and low > 0.0)


def compare_refits(problem: Problem, calibration: Fit, refitted: list[Candidate],
                   settings: DiagnosisSettings = DEFAULT_SETTINGS
                   ) -> tuple[Candidate | None, float, float, list[Candidate]]:
    """(best candidate, effective sample size, rho, the candidates with their BIC gain over the calibrated base
    model). The best is the largest gain among the candidates that may be named (:func:`may_headline`); None
    when no refitted candidate may be."""
    best_fit = min((c.refit for c in refitted), key=lambda f: f.rss, default=calibration)
    rho = lag1_autocorrelation(problem, best_fit.weighted)
    n_eff = effective_samples(problem.n, rho)
    refitted = [replace(c, delta_bic=bic_gain(calibration.rss, c.refit.rss, n_eff, 1))
                for c in refitted]
    named = [c for c in refitted if may_headline(problem, c, settings)]
    return max(named, key=lambda c: c.delta_bic, default=None), n_eff, rho, refitted


def reweigh(problem: Problem, fit: Fit, sigma_before: list[np.ndarray]) -> Fit:
    """A fit's copy with its weighted residuals and Jacobian recomputed for the files' new attainable errors."""
    ratio = np.concatenate([old / f.sigma for old, f in zip(sigma_before, problem.files)])
    return replace(fit, weighted=problem.weighted(fit.predictions), jacobian=fit.jacobian * ratio[:, None])


class Select(Stage):
    name = "selection"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        problem, calibration, settings = state.problem, state.calibration, state.settings
        refitted = [c for c in state.candidates if c.refit is not None]
        best, n_eff, rho, refitted = compare_refits(problem, calibration, refitted, settings)
        if best is not None and best.delta_bic > settings.bic_missing_threshold:
            # The replay's uncertainty was estimated with the base model; with the candidate, the torque may turn
            # more sharply where the rack data are least certain (a breakaway peak at each reversal). Weigh every
            # model by the larger of the two uncertainties and compare again.
            state.progress(f"{best.name} evidenced: replay uncertainty again with it")
            before = [f.sigma for f in problem.files]
            problem = with_replay_uncertainty(state, engine, best.signature.model, best.refit.overrides,
                                              keep_larger=True)
            calibration = reweigh(problem, calibration, before)
            refitted = [replace(c, refit=reweigh(problem, c.refit, before)) for c in refitted]
            best, n_eff, rho, refitted = compare_refits(problem, calibration, refitted, settings)
        by_name = {c.name: c for c in refitted}
        return replace(state, problem=problem, calibration=calibration,
                       candidates=tuple(by_name.get(c.name, c) for c in state.candidates),
                       best=best.name if best is not None else None, n_eff=n_eff, rho=rho)
