"""The base calibration ends at its optimum, and a candidate the data do not need is never the one named.

A candidate's refit starts from the calibrated base model; if the calibration stopped short, the refit walks on
and the fall of the sum of squares that the base parameters alone would give is counted as the candidate's BIC
gain (parksteer.diagnose.fitting.polish, parksteer.diagnose.stages.select.may_headline).
"""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import least_squares as scipy_least_squares
from scipy.optimize import lsq_linear

from parksteer.diagnose.calibrate import calibrate
from parksteer.diagnose.fitting import Fit, FitParameter, _predict, gauss_newton_step, polish
from parksteer.diagnose.engine import ReplayEngine
from parksteer.diagnose.problem import load_files
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.diagnose.stages import STAGES
from parksteer.diagnose.stages.select import compare_refits, may_headline
from parksteer.diagnose.stages.verdict import choose_verdict
from parksteer.diagnose.state import Candidate

# The car's parameters moved off the parameter file's, as a real car's are: the calibration has to find them.
MOVED = {"tyre.friction_coefficient": 0.70, "steering.rack_friction_force": 650.0,
         "tyre.carcass_torsional_stiffness": 800.0}
# A start far from them (in the fitted log-ratios: about 30 % off each way), for a calibration cut short.
FAR_START = {"tyre.friction_coefficient": 1.05, "steering.rack_friction_force": 430.0,
             "tyre.carcass_torsional_stiffness": 1100.0}


@pytest.fixture(scope="module")
def calibrated_problem(written, params):
    """A null record of the moved car, its replay uncertainty estimated (the diagnosis's first stage), and the
    base model's effects."""
    paths, _ = written("calibration_optimum", kind="null", base_overrides=MOVED)
    diagnosis = diagnose(load_files(paths, params), params, stages=STAGES[:2])
    return diagnosis.problem, list(diagnosis.calibration.effects)


def test_the_polished_calibration_is_the_optimum_another_fitter_finds_from_another_start(calibrated_problem):
    """A calibration cut short after one Levenberg-Marquardt step from a start 30 % off stops several standard
    errors from the optimum; polished, it is within half a standard error of the optimum scipy's trust-region
    least squares reaches from the parameter file's values with tolerances a thousand times tighter, and its weighted
    sum of squares is above that optimum's by less than 1. Both minimise the same weighted residual, so the
    optimum is one point, to the replay's own numerical noise."""
    problem, effects = calibrated_problem
    engine = ReplayEngine(1)
    short_settings = replace(DEFAULT_SETTINGS, calibration_max_iterations=1, calibration_polished=False)
    short = calibrate(engine, problem, effects, start=FAR_START, settings=short_settings)
    polished = polish(engine, problem, short, DEFAULT_SETTINGS)
    parameters, fixed = polished.parameters, polished.fixed
    lower = np.array([p.theta_bounds()[0] for p in parameters])
    upper = np.array([p.theta_bounds()[1] for p in parameters])

    def residual(values):  # scipy's variables are the parameters' values themselves, not the fit's log-ratios
        theta = np.array([p.theta(v) for p, v in zip(parameters, values)])
        return _predict(engine, problem, effects, parameters, theta, fixed)[1]

    # from the parameter file's values, with the diagnosis's finite-difference step (3 % of each value): smaller
    # ones see the integrator's noise
    independent = scipy_least_squares(residual, np.array([p.reference for p in parameters]),
                                      bounds=([p.lower for p in parameters], [p.upper for p in parameters]),
                                      diff_step=DEFAULT_SETTINGS.calibration_relative_step, x_scale="jac",
                                      xtol=1e-8, ftol=1e-10, gtol=1e-10)
    optimum = np.array([p.theta(v) for p, v in zip(parameters, independent.x)])
    _, se = gauss_newton_step(polished.jacobian, polished.weighted, polished.theta, lower, upper)
    short_off = np.abs(short.theta - optimum) / se
    polished_off = np.abs(polished.theta - optimum) / se
    assert short_off.max() > 3.0, short_off
    assert polished_off.max() < 0.5, polished_off
    # what a refit could still gain from the base parameters alone: under 1 in the weighted sum of squares, a BIC
    # gain under n_eff / RSS (about 1 here), a tenth of the threshold of a name
    assert polished.rss - float(independent.fun @ independent.fun) < 1.0


# --- the headline rule, on a linear least-squares problem whose truth is known ----------------------------------

class _File:
    """One 18 s record at 50 Hz, a torque channel alone, no replay ensemble."""

    def __init__(self):
        self.time_s = np.arange(0.0, 18.0, 0.02)
        self.n = self.time_s.size
        self.signals = 1
        self.replay_draws = None


class _Problem:
    def __init__(self):
        self.files = [_File()]
        self.n = self.files[0].n


def _fit(design: np.ndarray, y: np.ndarray, theta: np.ndarray, names: list[str]) -> Fit:
    parameters = [FitParameter(name, "linear", 1.0, 0.0 if name.endswith("strength") else -np.inf, np.inf, 1e-3)
                  for name in names]
    return Fit(None, parameters, np.asarray(theta, dtype=float), {}, [design @ theta], y - design @ theta, design,
               0, 0)


def _case(candidate_size: float, seed: int = 3):
    """A base model of two columns (shaped like the cycle's slow signals), a candidate column, unit noise and the
    candidate hidden at `candidate_size`; the base fit stopped 5 standard errors short of its optimum, and the
    candidate's refit (strength at least 0) at the joint optimum."""
    rng = np.random.default_rng(seed)
    problem = _Problem()
    t = problem.files[0].time_s
    base = np.column_stack([np.sin(2 * np.pi * t / 18.0), np.tanh(5.0 * np.cos(2 * np.pi * t / 9.0))])
    candidate = np.sign(np.sin(2 * np.pi * t / 3.0)) * (np.abs(t - 9.0) < 6.0)
    y = base @ np.array([20.0, -5.0]) + candidate_size * candidate + rng.normal(size=t.size)
    optimum, *_ = np.linalg.lstsq(base, y, rcond=None)
    se = np.sqrt(np.diag(np.linalg.inv(base.T @ base)))
    calibration = _fit(base, y, optimum + 5.0 * se, ["base.a", "base.b"])
    full = np.column_stack([base, candidate])
    # bounded-variable least squares: a strength at its bound is exactly 0, as the diagnosis's fitter clips it
    joint = lsq_linear(full, y, bounds=([-np.inf, -np.inf, 0.0], [np.inf, np.inf, np.inf]), method="bvls").x
    refit = _fit(full, y, joint, ["base.a", "base.b", "candidate.strength"])
    signature = SimpleNamespace(effect=SimpleNamespace(name="candidate"), key="candidate.strength")
    return problem, calibration, Candidate(signature, None, refit)


@pytest.mark.parametrize("size, interval_rule, why", [
    (-0.3, False, "fitted at strength 0 (its bound)"),
    (0.02, True, "fitted above 0 with an interval that holds 0, with headline_interval_clear_of_zero")])
def test_a_candidate_the_data_do_not_need_is_never_named_whatever_its_bic_gain(size, interval_rule, why):
    """A base fit 5 standard errors short leaves a fall of the sum of squares that any refit starting there takes
    (about 25 in the weighted RSS per parameter): a candidate hidden at 0 (or below its bound) gains more than the
    BIC threshold from it, yet is not the best; with the interval rule on, neither is one far inside its noise
    (fitted above 0, its interval holding 0). The verdict on a base model at the floor is then adequate."""
    settings = replace(DEFAULT_SETTINGS, headline_interval_clear_of_zero=interval_rule)
    problem, calibration, candidate = _case(size)
    _, _, _, refitted = compare_refits(problem, calibration, [candidate], settings)
    assert refitted[0].delta_bic > DEFAULT_SETTINGS.bic_missing_threshold, why
    best, *_ = compare_refits(problem, calibration, [candidate], settings)
    assert best is None and not may_headline(problem, refitted[0], settings), why
    if interval_rule:  # without the clause, a strength above 0 may be named
        assert compare_refits(problem, calibration, [candidate])[0] is not None
    base_ratio = np.sqrt(calibration.rss / problem.n)
    assert choose_verdict(base_ratio, None, None, None) == "adequate"


def test_a_candidate_clear_of_zero_is_still_named():
    """The same problem with the candidate hidden at a quarter of the noise's RMS (its 95 % interval clear of 0):
    it is the best, and named."""
    problem, calibration, candidate = _case(0.25)
    best, n_eff, _, _ = compare_refits(problem, calibration, [candidate])
    assert best is not None and best.name == "candidate"
    low, _ = best.refit.intervals(problem)["candidate.strength"]["ci95"]
    assert 0.0 < low <= 0.25
    after = np.sqrt(best.refit.rss / problem.n)
    assert choose_verdict(np.sqrt(calibration.rss / problem.n), best.delta_bic, after, None) == "missing"
