"""The best-scored few candidates refitted in the full nonlinear model, the calibrated parameters and the
candidate's strength together."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..fitting import Fit, FitParameter, least_squares
from ..candidates import Signature, strength_parameter
from ..problem import Problem
from ..settings import DEFAULT_SETTINGS, DiagnosisSettings
from ..state import DiagnosisState
from ..engine import ReplayEngine
from .base import Stage


def refit(engine: ReplayEngine, problem: Problem, calibration: Fit, signature: Signature, start_strength: float,
          settings: DiagnosisSettings = DEFAULT_SETTINGS) -> Fit:
    """The calibrated parameters and the candidate's strength fitted together in the full model."""
    spec = strength_parameter(signature.effect)
    strength = FitParameter(signature.key, "linear", 1.0, max(spec.lower, 0.0), spec.upper, signature.probe)
    parameters = [*calibration.parameters, strength]
    theta0 = np.concatenate([calibration.theta, [min(max(start_strength, strength.lower), strength.upper)]])
    seed = np.column_stack([calibration.jacobian, signature.weighted])
    fit = least_squares(engine, problem, signature.model, parameters, theta0, calibration.fixed, jacobian=seed,
                        max_iterations=settings.refit_max_iterations, settings=settings)
    angle_keys = set(settings.calibrated_with_angle) | {key for key, _, _ in settings.calibrated_with_angle_offsets}
    reset = [i for i, p in enumerate(calibration.parameters) if p.key in angle_keys]
    if problem.uses_angle and reset:
        # The calibrated base model's column may have absorbed the candidate (a soft column passes for a lash):
        # refit also from the parameter file's values of what only the angle calibrates, and keep the better fit.
        theta1 = theta0.copy()
        for i in reset:
            theta1[i] = calibration.parameters[i].theta(calibration.parameters[i].reference) \
                if calibration.parameters[i].transform == "offset" else 0.0
        other = least_squares(engine, problem, signature.model, parameters, theta1, calibration.fixed,
                              max_iterations=settings.refit_max_iterations, settings=settings)
        if other.rss < fit.rss:
            fit = replace(other, evaluations=other.evaluations + fit.evaluations)
    return fit


def chosen_for_refit(state: DiagnosisState) -> list:
    """The candidates a score test says remove some of the misfit, best first, at most settings.refit_count."""
    hopeful = sorted((c for c in state.candidates if c.score.removed_rss > 0.0), key=lambda c: -c.score.statistic)
    return hopeful[: state.settings.refit_count]


class Refit(Stage):
    name = "refits"

    def message(self, state: DiagnosisState) -> str | None:
        chosen = chosen_for_refit(state)
        return "refitting " + ", ".join(c.name for c in chosen) if chosen else None

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        problem, calibration, settings = state.problem, state.calibration, state.settings
        chosen = chosen_for_refit(state)

        # The few refits spread their files over the workers (or, with one file, one refit each); each fit travels
        # back without its effects (a copy), which are put back here.
        def refit_of(candidate) -> Fit:
            fit = refit(engine, problem, calibration, candidate.signature, candidate.score.linear_strength, settings)
            return replace(fit, effects=None)

        fits = {c.name: replace(fit, effects=c.signature.model)
                for c, fit in zip(chosen, engine.in_workers(problem, refit_of, chosen, False))}
        candidates = tuple(replace(c, refit=fits[c.name]) if c.name in fits else c for c in state.candidates)
        return replace(state, candidates=candidates)
