"""The assist's reduction: its efficiencies from the thread's geometry and friction, the defaults they give, and the
least back-driven efficiency at which the replay's law stays increasing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.model.numeric.assisted import check_back_efficiency, least_back_efficiency
from parksteer.model.symbolic.components import discover_effects
from parksteer.model.symbolic.effects.assist_common import directional_efficiency
from parksteer.reduction_efficiency import (back_efficiency, ball_nut_lead_angle, forward_efficiency,
                                            friction_angle, friction_angle_for_forward, lead_angle_for_forward)

DEG = math.pi / 180.0


def power_screw(lead_angle, mu):
    """Forward and back-driven efficiencies of a square thread from the force balance on the nut (the power-screw
    closed form written in sin and cos, not in the friction angle): raising a load W takes the tangential force
    P = W (sin l + mu cos l) / (cos l - mu sin l); lowering it releases P' = W (sin l - mu cos l) / (cos l + mu sin l);
    the work a turn moves the load is W tan(l) per unit of tangential travel."""
    s, c = math.sin(lead_angle), math.cos(lead_angle)
    raise_force = (s + mu * c) / (c - mu * s)
    lower_force = (s - mu * c) / (c + mu * s)
    return math.tan(lead_angle) / raise_force, max(lower_force, 0.0) / math.tan(lead_angle)


@pytest.mark.parametrize("lead_deg,mu", [(18.6, math.tan(3 * DEG)), (5.0, 0.1), (25.0, 0.05), (4.55, 0.003),
                                         (2.0, 0.1)])
def test_thread_efficiencies_are_the_force_balance_of_the_nut(lead_deg, mu):
    """eta_f = tan(l) / tan(l + rho) and eta_b = tan(l - rho) / tan(l) are the nut's force balance in both
    directions (the power-screw closed form in sin and cos), including the self-locking thread (l <= rho: eta_b
    = 0, the load cannot turn the screw)."""
    forward, back = power_screw(lead_deg * DEG, mu)
    assert forward_efficiency(lead_deg * DEG, friction_angle(mu)) == pytest.approx(forward, rel=1e-12)
    assert back_efficiency(lead_deg * DEG, friction_angle(mu)) == pytest.approx(back, rel=1e-12, abs=1e-15)


def test_worm_at_the_referees_corner_and_the_column_default():
    """At a lead angle of 18.6 deg and a friction angle of 3 deg a worm drives at 0.85 and is back-driven at
    0.83-0.84 (the published form of the worm-gear efficiencies); the column and pinion assists' defaults are that
    worm: eta_f 0.85, and eta_b the back-driven value of the lead angle that gives it, within 0.002 of 0.830."""
    assert forward_efficiency(18.6 * DEG, 3 * DEG) == pytest.approx(0.85, abs=0.001)
    assert round(back_efficiency(18.6 * DEG, 3 * DEG), 2) in (0.83, 0.84)
    effects = discover_effects()
    for name in ("electric_assist_column", "electric_assist_pinion"):
        q = {x.name: x for x in effects[name].quantities}
        assert q["efficiency"].default == 0.85
        lead = lead_angle_for_forward(0.85, 3 * DEG)
        assert lead / DEG == pytest.approx(18.6, abs=0.01)
        _, back = power_screw(lead, math.tan(3 * DEG))
        assert q["back_efficiency"].default == pytest.approx(back, rel=1e-9)
        assert abs(q["back_efficiency"].default - 0.830) < 0.002


def test_ball_nut_catalogue_form_and_the_rack_default():
    """A ball nut's catalogue efficiencies, (1 - mu tan l) / (1 + mu / tan l) driven and (1 - mu / tan l) / (1 + mu
    tan l) back-driven, with tan l = lead / (pi d): at a 7 mm lead on a 28 mm ball circle and a rolling friction of
    0.003-0.01 the two are within 0.02 of each other; the rack assist's default (eta_f 0.90, the same nut) has eta_b
    within 0.02 of it."""
    lead = ball_nut_lead_angle(0.007, 0.028)
    t = 0.007 / (math.pi * 0.028)
    for mu in (0.003, 0.005, 0.01):
        forward = (1 - mu * t) / (1 + mu / t)
        back = (1 - mu / t) / (1 + mu * t)
        assert forward_efficiency(lead, friction_angle(mu)) == pytest.approx(forward, rel=1e-12)
        assert back_efficiency(lead, friction_angle(mu)) == pytest.approx(back, rel=1e-12)
        assert 0.0 < forward - back < 0.02
    q = {x.name: x for x in discover_effects()["electric_assist_rack"].quantities}
    assert q["efficiency"].default == 0.90
    rho = friction_angle_for_forward(0.90, lead)
    assert forward_efficiency(lead, rho) == pytest.approx(0.90, rel=1e-12)
    assert 0.0 < 0.90 - q["back_efficiency"].default < 0.02


def delivered(motor, rotor_speed, forward, back, width=0.05, friction_speed=0.5):
    return motor * directional_efficiency(motor, rotor_speed, forward, back, width, 1.0 / friction_speed)


def test_the_law_stays_increasing_down_to_the_least_back_efficiency_and_not_below():
    """The replay inverts T + A(T) = y, so the gear's delivered torque m f(s(m)) must rise with the motor torque m at
    every rotor speed. The least eta_b (0.147 at eta_f 0.85, from the condition on the quartic in the smoothed power
    sign s) is a corner: just above it the delivered torque of the assist's own function rises on a fine grid of
    motor torques at every rotor speed, just below it there is a speed at which it falls."""
    forward = 0.85
    least = least_back_efficiency(forward)
    assert 0.14 < least < 0.16
    m = np.linspace(-1.0, 1.0, 40001)
    speeds = np.linspace(0.0, 5.0, 201)  # tanh(speed / 0.5): 0 to 1 - 4e-9

    def falls(back):
        return any(np.min(np.diff(delivered(m, w, forward, back))) < 0.0 for w in speeds)

    assert not falls(least + 0.002)
    assert falls(least - 0.01)
    # the shipped defaults are far above it
    assert not falls(0.83) and not falls(0.889)


def test_a_back_efficiency_below_the_bound_is_refused_in_one_line():
    """Below the bound the replay's law is not increasing: the check refuses it in one line naming the quantity."""
    check_back_efficiency("electric_assist_column", 0.85, 0.83)
    with pytest.raises(UsageError) as err:
        check_back_efficiency("electric_assist_column", 0.85, 0.1)
    assert "electric_assist_column.back_efficiency 0.1" in str(err.value) and "\n" not in str(err.value)
