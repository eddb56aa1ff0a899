"""The handwheel input of the paper's cycle."""

from __future__ import annotations

import numpy as np

from parksteer.model.numeric.inputs import sawtooth_profile
from parksteer.model.numeric.simulate import with_overrides


def test_cycle_reaches_each_lock_at_the_papers_times(params):
    """Straight ahead to full right lock at 4.5 s, full left lock 9 s later, straight ahead at 18 s (section 4),
    at rest at each of these instants, with the angle and rate continuous throughout."""
    profile = sawtooth_profile(params)
    lock = params["input.handwheel_lock_angle"]
    angle, rate = profile.angle_rate([0.0, 4.5, 13.5, 18.0, 20.0])
    np.testing.assert_allclose(angle, [0.0, lock, -lock, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(rate, 0.0, atol=1e-12)
    t = np.linspace(0, 18, 180001)
    dt = t[1] - t[0]
    angle, rate = profile.angle_rate(t)
    half = params["input.reversal_rounding_time"] / 2
    max_rate = max(lock / (4.5 - half), 2 * lock / (9.0 - half))
    # no jumps: each step changes the angle by at most max rate * dt and the rate by at most max accel * dt
    assert np.max(np.abs(np.diff(angle))) <= 1.001 * max_rate * dt
    assert np.max(np.abs(np.diff(rate))) <= 1.001 * max_rate / half * dt
    assert np.max(angle) <= lock + 1e-12 and np.min(angle) >= -lock - 1e-12


def test_corners_are_rounded_with_constant_acceleration(params):
    """Within half the rounding time of a corner the rate changes linearly (constant angular acceleration); between
    corners the rate is constant and such that the travel (lock) is covered in the segment's time."""
    profile = sawtooth_profile(params)
    half = params["input.reversal_rounding_time"] / 2
    lock = params["input.handwheel_lock_angle"]
    _, rate = profile.angle_rate([2.0])
    assert abs(rate[0] - lock / (4.5 - half)) < 1e-12
    _, ramp = profile.angle_rate(np.linspace(4.5 - half, 4.5, 11))
    assert np.allclose(np.diff(ramp, 2), 0.0, atol=1e-12) and ramp[0] > ramp[-1] == 0.0


def test_ideal_saw_tooth_without_rounding(params):
    """With no rounding the rate is constant on each leg: lock / 4.5 s, then -2 lock / 9 s, then lock / 4.5 s."""
    profile = sawtooth_profile(with_overrides(params, "input", reversal_rounding_time=0.0))
    lock = params["input.handwheel_lock_angle"]
    _, rate = profile.angle_rate([1.0, 4.4, 4.6, 13.4, 13.6])
    np.testing.assert_allclose(rate, [lock / 4.5, lock / 4.5, -2 * lock / 9, -2 * lock / 9, lock / 4.5])


def test_a_given_handwheel_profile_drives_the_model(params):
    """A HandwheelProfile given to simulate replaces the saw tooth: the run follows that angle (here a steer to
    3 rad and hold) and ends with it; the header says the drive was prescribed."""
    from parksteer.model.numeric.inputs import profile_from_rates
    from parksteer.model.numeric.simulate import simulate

    profile = profile_from_rates([(0.5, 4.0), (1.0, 0.0), (0.5, -4.0), (1.0, 0.0)])  # 0.5 + 2 + 0.5 = 3 rad, hold
    result = simulate("unladen", params=params, handwheel=profile)
    c = result.columns
    assert abs(c["time_s"][-1] - 3.0) < 1e-9
    np.testing.assert_allclose(c["handwheel_angle_rad"][-1], 3.0, atol=1e-12)
    assert result.header["drive"] == "prescribed handwheel profile"
    expected_rack_m = 3.0 / params["steering.handwheel_to_rack_ratio"]
    assert abs(c["rack_m"][-1] - expected_rack_m) < 0.05 * expected_rack_m  # column twist: a few per cent
