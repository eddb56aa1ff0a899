"""The pre-sliding (Dahl-type) rack friction: absent at 0, a Coulomb friction of its force in steady sliding,
and a force that reverses over a rack travel of the pre-sliding displacement, not over a speed."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.model.numeric.simulate import simulate
from parksteer.model.symbolic.components import with_effect_quantities
from parksteer.parameters import load_parameters

FORCE_N = 100.0


@pytest.fixture(scope="module")
def runs():
    dt = 0.001
    base = simulate("unladen", output_dt_s=dt)
    bristle = simulate("unladen", effects="+rack_presliding", overrides={"rack_presliding.force": FORCE_N},
                       output_dt_s=dt)
    absent = simulate("unladen", effects="+rack_presliding", output_dt_s=dt)
    params = load_parameters()
    coulomb = simulate("unladen", output_dt_s=dt, overrides={
        "steering.rack_friction_force": params["steering.rack_friction_force"] + FORCE_N})
    return {k: {c: np.asarray(v.columns[c]) for c in ("time_s", "rack_m", "handwheel_torque_Nm")}
            for k, v in (("base", base), ("bristle", bristle), ("absent", absent), ("coulomb", coulomb))}


def test_absent_at_zero_force(runs):
    """With F_d = 0 spring and slider vanish: the torque is the paper model's (to the integrator's noise)."""
    d = runs["absent"]["handwheel_torque_Nm"] - runs["base"]["handwheel_torque_Nm"]
    assert np.max(np.abs(d)) < 0.01


def test_steady_sliding_is_coulomb_friction_of_the_force(runs):
    """Once the bristle has slid it carries F_d exactly: in the strokes' cruise the extra torque is that of a
    Coulomb rack friction raised by F_d (to 1 %)."""
    t = runs["base"]["time_s"]
    extra = runs["bristle"]["handwheel_torque_Nm"] - runs["base"]["handwheel_torque_Nm"]
    coulomb = runs["coulomb"]["handwheel_torque_Nm"] - runs["base"]["handwheel_torque_Nm"]
    speed = np.gradient(runs["base"]["rack_m"], t)
    cruise = np.abs(speed) > 0.5 * np.max(np.abs(speed))
    assert np.abs(coulomb[cruise]).min() > 0.3  # a friction share of about F_d / 186 N m per N
    assert np.max(np.abs(extra[cruise] - coulomb[cruise])) < 0.01 * np.abs(coulomb[cruise]).max()


def test_reversal_spreads_over_the_presliding_displacement(runs):
    """At the reversal at right lock the bristle unloads elastically: its force, F_d before, passes zero after
    the rack has travelled back about x_p (0.2 mm; between 0.5 and 2 x_p allows for the knee's rounding), while
    the Coulomb friction has already flipped there."""
    params = with_effect_quantities(load_parameters())
    x_p = params["rack_presliding.presliding_displacement"]
    rack = runs["bristle"]["rack_m"]
    extra = runs["bristle"]["handwheel_torque_Nm"] - runs["base"]["handwheel_torque_Nm"]
    coulomb = runs["coulomb"]["handwheel_torque_Nm"] - runs["base"]["handwheel_torque_Nm"]
    top = int(np.argmax(rack))
    after = np.arange(top, len(rack))
    cross = after[np.argmax(extra[after] < 0.0)]
    travel = rack[top] - rack[cross]
    assert 0.5 * x_p < travel < 2.0 * x_p
    half = after[np.argmax(rack[top] - rack[after] > 0.5 * x_p)]  # half way to the crossing
    assert extra[half] > 0.0 and coulomb[half] < 0.0


def test_the_root_damper_only_removes_the_root_masss_own_mode(runs):
    """The damper in parallel with the bristle spring (damping_ratio) is there to end the oscillation of the root's
    small mass on the spring, a mode the massless bristle does not have. Its force, c times the bristle's
    deformation rate with c = 2 zeta sqrt(k m), is zero in steady sliding and small in pre-sliding: at a tenth of
    the root mass (c down by sqrt(10)), or at half and twice the damping ratio, the torque moves by less than
    0.02 N m (a tenth of an 8-bit converter step), against the bristle's own effect of 0.6 N m at 100 N."""
    dt = 0.001
    effect = np.max(np.abs(runs["bristle"]["handwheel_torque_Nm"] - runs["base"]["handwheel_torque_Nm"]))
    assert effect > 0.5
    for overrides in ({"rack_presliding.node_mass": 0.001}, {"rack_presliding.damping_ratio": 0.5},
                      {"rack_presliding.damping_ratio": 2.0}):
        other = simulate("unladen", effects="+rack_presliding", output_dt_s=dt,
                         overrides={"rack_presliding.force": FORCE_N, **overrides})
        moved = np.max(np.abs(np.asarray(other.columns["handwheel_torque_Nm"]) - runs["bristle"]["handwheel_torque_Nm"]))
        assert moved < 0.02, (overrides, moved)
