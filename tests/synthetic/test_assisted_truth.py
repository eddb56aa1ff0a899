"""The independent assisted truth (parksteer.synthetic.assisted_truth): its column, worm, control unit and map."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from parksteer.geometry import pinion_angle_from_column
from parksteer.synthetic.assisted_truth import Hidden, Road, TruthGear, TruthMap, column_of_pinion
from parksteer.synthetic.column_eps_layer import _delivered, eps_layer


def _road(torque, rate=None, accel=None) -> Road:
    torque = np.asarray(torque, dtype=float)
    n = len(torque)
    t = np.arange(n) * 0.002
    rate = np.full(n, 0.5) if rate is None else np.asarray(rate, dtype=float)
    return Road(t, np.zeros(n), np.cumsum(rate) * 0.002, rate, np.zeros(n) if accel is None else accel, torque)


def test_column_of_pinion_inverts_the_hooke_joint_over_turns():
    """The column angle the truth takes from the pinion is the Hooke joint's inverse, over three turns each way
    and at a phase: the joint's forward map of it gives the pinion angle back."""
    theta_c = np.linspace(-20.0, 20.0, 4001)
    for alpha, phase in ((0.45, 0.0), (0.3, 0.7)):
        back = column_of_pinion(pinion_angle_from_column(theta_c, alpha, phase), alpha, phase)
        assert np.max(np.abs(back - theta_c)) < 1e-12


def test_worm_gives_eta_f_driving_one_over_eta_b_back_driven_and_never_creates_power():
    """At speed the column receives eta_f N o when the motor drives it and N o / eta_b when it drives the motor;
    at any speed the power the gear loses, (N o - D) times the column's rate, is never negative."""
    gear = TruthGear(reduction=18.0, efficiency=0.85, back_efficiency=0.8, direction_speed_rad_s=1.0)
    fast = 0.5  # rad/s at the column: 9 rad/s at the rotor, beyond the 1 rad/s band
    assert _delivered(np.array([0.1]), np.array([fast]), gear)[0] == pytest.approx(0.85 * 18.0 * 0.1)
    assert _delivered(np.array([0.1]), np.array([-fast]), gear)[0] == pytest.approx(18.0 * 0.1 / 0.8)
    rng = np.random.default_rng(3)
    o, rate = rng.normal(0.0, 0.2, 2000), rng.normal(0.0, 0.05, 2000)
    loss = (18.0 * o - _delivered(o, rate, gear)) * rate
    assert np.all(loss >= -1e-15)


def test_inside_the_dead_band_the_driver_carries_the_column():
    """With no motor friction or inertia, a column torque inside the map's dead band is all the torsion bar's, and
    the control unit asks for no current."""
    gear = TruthGear(motor_friction_Nm=0.0, motor_inertia_kg_m2=0.0)
    y = np.linspace(-0.3, 0.3, 61)
    solution = eps_layer(_road(y), TruthMap(dead_band_Nm=0.4), gear, 0.005, 10.24)
    assert np.max(np.abs(solution.torsion_bar_Nm - y)) <= 0.005
    assert np.max(np.abs(solution.current_A)) < 1e-12


def test_steady_motion_balances_bar_map_and_friction_through_the_worm():
    """In steady motion (driving, no acceleration) the bar's torque T_s solves T_s + A(T_s) - eta_f N T_c = T_road
    (the map's assist delivered, the rotor's friction taken back through the worm), to within the control unit's
    step; the current is A(T_s) / (eta_f N k_t)."""
    gear = TruthGear(motor_friction_Nm=0.02, motor_inertia_kg_m2=0.0)
    boost = TruthMap()
    y = np.array([5.0, 12.0, 20.0])
    solution = eps_layer(_road(y, rate=np.full(3, 0.5)), boost, gear, 0.001, 10.24)
    for k, target in enumerate(y):
        expected = brentq(lambda s: s + boost(np.array([s]))[0] - 0.85 * 18.0 * 0.02 - target, 0.0, 10.0)
        assert solution.torsion_bar_Nm[k] == pytest.approx(expected, abs=0.002)
        assert solution.current_A[k] == pytest.approx(boost(np.array([expected]))[0] / (0.85 * 18.0 * 0.05), rel=2e-3)


def test_map_hysteresis_widens_the_loop_by_its_play():
    """A play of half-width h on the control unit's reading makes the bar carry more on the way up and less on the
    way down at the same column torque: each branch moves by h a / (1 + a), a the map's slope through the worm
    there (about 10 at 15 N m of column torque, so each branch moves by 0.85 h to h), on top of the loop the
    worm's two efficiencies open already."""
    gear = TruthGear(motor_friction_Nm=0.0, motor_inertia_kg_m2=0.0)
    up = np.linspace(0.0, 20.0, 2001)
    y = np.concatenate([up, up[::-1]])
    rate = np.concatenate([np.full(2001, 0.5), np.full(2001, -0.5)])
    h = 0.1
    k = 1500  # y = 15 N m on both branches

    def loop(hidden):
        ts = eps_layer(_road(y, rate=rate), TruthMap(), gear, 0.0005, 10.24, hidden).torsion_bar_Nm
        return ts[k] - ts[len(y) - 1 - k]

    extra = loop(Hidden(hysteresis_Nm=h)) - loop(Hidden())
    assert 2 * 0.85 * h < extra < 2 * h + 0.002
