"""The score test that ranks candidate effects, on linear problems whose answer is known."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.diagnose.fitting import Fit, FitParameter
from parksteer.diagnose.candidates import Signature, score, strength_parameter
from parksteer.model.symbolic.components import Effect
from parksteer.parameters import Quantity


def _declared(effect: str, name: str, unit: str, lower: float, upper: float, default: float) -> Quantity:
    return Quantity(f"{effect}.{name}", unit, lower, upper, lower_inclusive=True, default=default, source="test")


class _Candidate(Effect):
    name = "toy_candidate"
    in_default_set = False
    quantities = (_declared("toy_candidate", "strength", "N", 0.0, 1e3, 0.0),)
    uses = tuple(q.key for q in quantities)


class _TwoZeroDefaults(Effect):
    name = "toy_ambiguous"
    quantities = (_declared("toy_ambiguous", "a", "N", 0.0, 1.0, 0.0),
                  _declared("toy_ambiguous", "b", "N", 0.0, 1.0, 0.0))
    uses = tuple(q.key for q in quantities)


class _OneZeroDefault(Effect):
    name = "toy_single"
    quantities = (_declared("toy_single", "speed", "m/s", 1e-4, 1.0, 1e-3),
                  _declared("toy_single", "force", "N", 0.0, 1.0, 0.0))
    uses = tuple(q.key for q in quantities)


def _fit(J: np.ndarray, r: np.ndarray) -> Fit:
    parameters = [FitParameter(f"base.p{i}", "log", 1.0, 0.1, 10.0, 0.01) for i in range(J.shape[1])]
    return Fit([], parameters, np.zeros(J.shape[1]), {}, [], r, J, 0, 0)


def _signature(w: np.ndarray) -> Signature:
    return Signature(_Candidate(), "toy_candidate.strength", 1.0, [], [], w, 0.0, [])


def _calibrated_residual(J, data):
    """Residual of the base parameters' least-squares fit: the part of the data they cannot make."""
    return data - J @ np.linalg.lstsq(J, data, rcond=None)[0]


def test_a_signature_the_calibrated_parameters_also_make_is_confounded():
    """A candidate whose torque change equals a change of a calibrated parameter cannot be told from it: nothing of
    its signature survives the projection, it removes nothing, and the parameter it mimics is named."""
    rng = np.random.default_rng(1)
    J = rng.normal(size=(500, 3))
    r = _calibrated_residual(J, rng.normal(size=500))
    result = score(_signature(2.0 * J[:, 1]), _fit(J, r))
    assert result.identifiable_fraction < 1e-8
    assert result.removed_rss == 0.0 and result.statistic == 0.0
    assert result.confounded_with == "base.p1"


def test_the_score_recovers_a_linear_hidden_strength():
    """Data = base parameters' effect + s w + unit noise: after calibration the score's linear estimate of the
    strength is s within its standard error 1 / |w~| (here 3 standard errors)."""
    rng = np.random.default_rng(2)
    n = 2000
    J = rng.normal(size=(n, 3))
    w = 0.6 * J[:, 0] + rng.normal(size=n) * 0.05  # mostly confounded, partly its own
    data = J @ np.array([1.0, -2.0, 0.5]) + 40.0 * w + rng.normal(size=n)
    result = score(_signature(w), _fit(J, _calibrated_residual(J, data)))
    projected = w - J @ np.linalg.lstsq(J, w, rcond=None)[0]
    standard_error = 1.0 / np.linalg.norm(projected)
    assert abs(result.linear_strength - 40.0) < 3.0 * standard_error
    assert result.statistic > 100.0


def test_under_the_null_the_score_is_half_a_chi_square():
    """With nothing hidden the score u = w~ . r is normal, so u^2 / (|w~|^2 s^2) is chi-square(1); strengths cannot
    be negative, so half the draws score 0: mean 0.5, and 2.5 % of draws exceed 3.84."""
    rng = np.random.default_rng(3)
    n = 400
    J = rng.normal(size=(n, 2))
    w = rng.normal(size=n)
    stats = [score(_signature(w), _fit(J, _calibrated_residual(J, rng.normal(size=n)))).statistic for _ in range(2000)]
    stats = np.array(stats)
    assert np.mean(stats == 0.0) == pytest.approx(0.5, abs=0.04)
    assert np.mean(stats) == pytest.approx(0.5, abs=0.08)
    assert np.mean(stats > 3.84) == pytest.approx(0.025, abs=0.012)


def test_a_residual_asking_for_a_negative_strength_scores_zero():
    """A friction or a mass cannot be negative: a residual that the candidate would explain only with a negative
    strength gives it no score."""
    rng = np.random.default_rng(4)
    J = rng.normal(size=(300, 2))
    w = rng.normal(size=300)
    r = _calibrated_residual(J, -5.0 * w + rng.normal(size=300))
    result = score(_signature(w), _fit(J, r))
    assert result.linear_strength < 0 and result.statistic == 0.0 and result.removed_rss == 0.0


def test_the_strength_is_the_parameter_whose_default_means_absent():
    """'strength' names it; otherwise the one parameter whose default is 0 from a range starting at 0; two such
    parameters leave it ambiguous (not testable)."""
    assert strength_parameter(_Candidate()).name == "strength"
    assert strength_parameter(_OneZeroDefault()).name == "force"
    assert strength_parameter(_TwoZeroDefaults()) is None


class _Saturating:
    """A replay engine whose torque change grows as strength^3: a probe sized from a linear guess overshoots and
    undershoots in turn, so a short search ends without reaching its target."""

    def __init__(self) -> None:
        self.shape = np.linspace(-1.0, 1.0, 50)

    def predict(self, problem, effects, overrides):
        s = overrides["toy_candidate.strength"]
        return [self.shape * s**3]


class _Files:
    uses_angle = False

    def scale(self, arrays):
        return np.concatenate(arrays) / 0.1


def test_a_probe_that_runs_out_of_tries_divides_its_change_by_the_strength_it_was_made_at():
    """A signature is a derivative: the torque change of the last probe over the strength that probe was made at.
    When the search stops at its last try, the strength it would have tried next was never replayed, and the
    signature's strength must be the one behind its torque: its probed torque is the replay at its strength, and its
    weighted signature times that strength is the weighted change."""
    from dataclasses import replace

    from parksteer.diagnose.candidates import probe_signature
    from parksteer.diagnose.settings import DEFAULT_SETTINGS

    engine = _Saturating()
    settings = replace(DEFAULT_SETTINGS, probe_max_tries=2)
    signature = probe_signature(engine, _Files(), [], _Candidate(), {}, target_Nm=0.01, settings=settings)
    assert not 0.5 <= signature.rms_change_Nm / 0.01 <= 2.0  # the search did run out of tries
    replayed = engine.predict(None, [], {"toy_candidate.strength": signature.probe})[0]
    assert np.allclose(signature.probed[0], replayed, rtol=1e-12, atol=0.0)
    assert np.allclose(signature.weighted * signature.probe, replayed / 0.1, rtol=1e-12, atol=0.0)
