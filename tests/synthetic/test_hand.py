"""The driver's hand: the paper's saw tooth (section 4) and the irregular hand of the synthetic data."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.synthetic.hand import HandVariation, irregular_hand_profile, sawtooth_hand_profile

LOCK_RAD = 12.566
CORNERS_S = (0.0, 4.5, 13.5, 18.0)
VARIATION = HandVariation(0.3, 3, (0.05, 0.5), knots_per_stroke=4, seed=9)


def test_sawtooth_matches_section_4(params):
    """Straight ahead, right lock at 4.5 s, left lock at 13.5 s, straight ahead at 18 s, stopping at each

    corner; with 0.2 s ramps at each end of a stroke the cruise rate is travel / (duration - 0.2 s)."""
    hand = sawtooth_hand_profile(params, output_dt_s=0.001)
    angle, rate = hand.angle_rate(np.array(CORNERS_S))
    np.testing.assert_allclose(angle, [0.0, LOCK_RAD, -LOCK_RAD, 0.0], atol=1e-12)
    np.testing.assert_allclose(rate, 0.0, atol=1e-12)
    assert hand.angle_rate(np.array([2.0]))[1][0] == pytest.approx(LOCK_RAD / 4.3)
    assert hand.angle_rate(np.array([9.0]))[1][0] == pytest.approx(-2 * LOCK_RAD / 8.8)


def test_irregular_hand_keeps_reversal_times_and_lock_angles(params):
    """The hand speed wanders, but it stops at each lock at the corner time, is monotone between

    reversals, and its angle is the time integral of its rate (exact by the trapezoid rule for a
    continuous, piecewise-linear rate, up to the kinks inside a step)."""
    hand = irregular_hand_profile(params, VARIATION, output_dt_s=0.001)
    angle, rate = hand.angle_rate(np.array(CORNERS_S))
    np.testing.assert_allclose(angle, [0.0, LOCK_RAD, -LOCK_RAD, 0.0], atol=1e-9)
    np.testing.assert_allclose(rate, 0.0, atol=1e-12)
    for a, b, direction in ((0.0, 4.5, 1), (4.5, 13.5, -1), (13.5, 18.0, 1)):
        inside = (hand.time_s >= a) & (hand.time_s <= b)
        assert (direction * np.diff(hand.angle_rad[inside]) > 0).all()
    trapezoid = 0.5 * (hand.rate_rad_s[1:] + hand.rate_rad_s[:-1]) * np.diff(hand.time_s)
    np.testing.assert_allclose(np.diff(hand.angle_rad), trapezoid, atol=1e-7)
    # in the cruise the speed is the saw tooth's times a factor within about 1 +- 0.3, and it does vary
    cruise = np.all([np.abs(hand.time_s - c) > 0.3 for c in CORNERS_S], axis=0)
    factor = np.abs(hand.rate_rad_s[cruise]) / (LOCK_RAD / 4.3)
    assert 0.6 < factor.min() and factor.max() < 1.5
    assert factor.max() - factor.min() > 0.15
    assert hand.metadata["hand_seed"] == 9 and hand.metadata["hand_speed_variation"] == 0.3


def test_irregular_hand_drives_the_compiled_model_and_reduces_to_the_saw_tooth(params):
    """The profile fits the compiled model's input table, and with no variation it is the model's saw tooth."""
    from parksteer.model.codegen.generate import MAX_INPUT_PIECES

    hand = irregular_hand_profile(params, VARIATION)
    table = hand.handwheel_profile().table(MAX_INPUT_PIECES)
    assert table[0] == len(hand.pieces)
    steady = irregular_hand_profile(params, HandVariation(0.0, 1, (0.1, 0.1), knots_per_stroke=4, seed=1), 0.001)
    nominal = sawtooth_hand_profile(params, output_dt_s=0.001)
    np.testing.assert_allclose(steady.angle_rad, nominal.angle_rad, atol=1e-12)
    np.testing.assert_allclose(steady.rate_rad_s, nominal.rate_rad_s, atol=1e-12)


def test_hand_variation_that_could_stop_the_hand_is_refused():
    """A speed factor 1 - variation must stay positive, or the hand would stop or back up mid-stroke."""
    with pytest.raises(UsageError, match=r"in \[0, 1\)"):
        HandVariation(1.0, 3, (0.05, 0.5), knots_per_stroke=4, seed=1)
