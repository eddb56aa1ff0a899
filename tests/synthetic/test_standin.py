"""The analytic stand-in cycle: each mechanism against its closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from parksteer.synthetic import standin
from parksteer.synthetic.hand import sawtooth_hand_profile

JOINT_RAD = 0.45


def test_elastic_plastic_carcass_slides_at_the_limit_and_unloads_with_the_carcass_stiffness():
    """Loading past the limit holds the moment at the limit; reversing unloads at slope k, so the tread

    only slides again after 2 limit / k of reverse steer (the width of the hysteresis loop)."""
    k, limit = 728.0, 122.0
    steer = np.concatenate((np.linspace(0.0, 0.4, 401), np.linspace(0.4, -0.4, 801)[1:]))
    moment = standin.elastic_plastic_moment_Nm(steer, k, limit)
    assert moment.max() == pytest.approx(limit) and moment.min() == pytest.approx(-limit)
    np.testing.assert_allclose(moment[:100], k * steer[:100])  # 0.1 rad < limit / k = 0.168 rad
    after_turn = np.flatnonzero(steer[400:] <= 0.4 - 2 * limit / k)[0] + 400
    np.testing.assert_allclose(moment[400 : after_turn - 1], limit - k * (0.4 - steer[400 : after_turn - 1]))
    assert moment[after_turn + 5] == pytest.approx(-limit)


def test_hooke_joint_speed_ratio():
    """A Hooke joint at angle b: speed ratio between cos b and 1/cos b, twice per turn, averaging 1;

    the output angle is the integral of the ratio and meets the input every quarter turn."""
    theta = np.linspace(0.0, 4 * np.pi, 40001)
    ratio = standin.hooke_speed_ratio(theta, JOINT_RAD, 0.0)
    assert ratio.min() == pytest.approx(math.cos(JOINT_RAD)) and ratio.max() == pytest.approx(1 / math.cos(JOINT_RAD))
    out = standin.hooke_output_angle(theta, JOINT_RAD, 0.0)
    np.testing.assert_allclose(np.gradient(out, theta)[1:-1], ratio[1:-1], rtol=1e-5)
    quarter = np.arange(0, 40001, 5000)  # every pi/2
    np.testing.assert_allclose(out[quarter], theta[quarter], atol=1e-12)
    assert np.trapezoid(ratio, theta) / (4 * np.pi) == pytest.approx(1.0, rel=1e-9)


def test_sliding_torque_at_straight_ahead_is_rack_friction_plus_both_tyre_limits(params):
    """Mid-way from right to left lock both treads slide: the pinion torque is F / 186.47 plus the

    equation (2) limits of both wheels over G = 22.28 (plus the tiny castor term of (A1) at zero
    steer); at straight ahead the Hooke joint (phase 0) multiplies it by 1 / cos(0.45)."""
    hand = sawtooth_hand_profile(params, output_dt_s=0.001)
    cycle = standin.quasi_static_cycle(params, "unladen", hand, "ground")
    i = int(np.argmin(np.abs(hand.time_s - 9.0)))
    mu, p0, n, p = 0.666, 245000.0, 0.78, 122500.0

    def limit(load):  # equation (2)
        return p0 ** (n - 0.5) * 2 * mu / (3 * math.sqrt(math.pi)) * load**1.5 / p**n

    tyres = (limit(2698.0) + limit(2878.0)) / (186.47 / 8.3682)
    assert tyres == pytest.approx(11.5, abs=0.1)  # reconstruction notes: 122 + 134 N m at the wheels
    pinion = 730.0 / 186.47 + tyres
    assert cycle["handwheel_torque_Nm"][i] == pytest.approx(-pinion / math.cos(JOINT_RAD), abs=0.02)
    air = standin.quasi_static_cycle(params, "unladen", hand, "air_bearing")
    assert air["handwheel_torque_Nm"][i] == pytest.approx(-(730.0 / 186.47) / math.cos(JOINT_RAD), abs=0.02)


def test_carcass_wind_up_takes_about_20_mm_of_rack(params):
    """From straight ahead the lighter (left) wheel starts to slide once k * steer reaches its limit:

    rack = 122 N m / 728 N m/rad / 8.3682 rad/m = 20 mm (reconstruction notes); the slope of the
    handwheel torque against rack then drops by half."""
    hand = sawtooth_hand_profile(params, output_dt_s=0.001)
    cycle = standin.quasi_static_cycle(params, "unladen", hand, "ground")
    ratio = standin.hooke_speed_ratio(hand.angle_rad, JOINT_RAD, 0.0)
    stroke = hand.time_s < 4.0
    rack = cycle["rack_m"][stroke]
    pinion = cycle["handwheel_torque_Nm"][stroke] / ratio[stroke]
    slope = np.gradient(pinion, rack)
    both_twisting = 2 * 728.0 * 8.3682 / (186.47 / 8.3682)
    first_slide = rack[np.flatnonzero(slope < 0.75 * both_twisting)[1]]  # index 0 is the friction jump at t = 0
    assert first_slide == pytest.approx(0.020, abs=0.001)
