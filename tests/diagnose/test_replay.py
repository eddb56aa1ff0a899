"""Smoothing a logged rack and replaying it through the model."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.diagnose.replay import Replay, smooth_rack
from parksteer.synthetic.logger import add_noise, quantise, quantisation_step
from parksteer.model.symbolic.components import resolve_effects
from parksteer.model.numeric.inputs import rack_drive_from_arrays
from parksteer.model.numeric.simulate import simulate

FULL_SCALE_M = 0.1


def _logged_rack(seed: int, start_at_rest: bool):
    """A lock-to-lock rack motion, 8-bit logged at 50 Hz: (time, logged rack, true rack).

    The speed is a trapezoid per stroke (straight ahead to +67 mm in 4.5 s, to -67 mm in 9 s, back in 4.5 s),
    ramping linearly over 0.2 s at the start, through each reversal and at the end: the hand's motion.
    """
    t = np.arange(0.0, 18.0 + 1e-9, 0.02)
    fine = np.linspace(0.0, 18.0, 18001)
    ramp = 0.2
    corners = [0.0, 4.5, 13.5, 18.0]
    travel = [0.067, -0.134, 0.067]
    speed = np.zeros_like(fine)
    for (a, b), dx in zip(zip(corners[:-1], corners[1:]), travel):
        cruise = dx / (b - a - ramp)  # area of a trapezoid with ramps of `ramp` at both ends
        shape = np.clip(np.minimum(fine - a, b - fine) / ramp, 0.0, 1.0)
        speed += np.where((fine >= a) & (fine <= b), cruise * shape, 0.0)
    x_fine = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(fine))])
    x = np.interp(t, fine, x_fine)
    logged = quantise(add_noise(x, 0.0002, np.random.default_rng(seed)), FULL_SCALE_M)
    if not start_at_rest:
        keep = t >= 1.0
        return t[keep], logged[keep], x[keep]
    return t, logged, x


def test_spline_follows_the_motion_not_the_converter_steps():
    """The smoothed rack stays within a fraction of a converter step of the true motion, and its fit residual
    is the rack's noise (quantisation step / sqrt(12) with the analog noise), not less (it does not chase steps)."""
    t, logged, true = _logged_rack(1, True)
    rack = smooth_rack(t, logged)
    position, speed, _ = rack.evaluate(t)
    step = quantisation_step(FULL_SCALE_M)
    noise = np.hypot(step / np.sqrt(12.0), 0.0002)
    assert np.sqrt(np.mean((position - true) ** 2)) < 0.25 * step
    assert 0.8 * noise < rack.fit_rms_m <= rack.noise_rms_m * 1.0 + 1e-12
    assert 0.05 <= rack.knot_spacing_s <= 1.0


def test_a_record_that_starts_at_rest_is_held_at_rest_and_one_that_starts_moving_is_not():
    """The cycle starts from rest, so the spline's speed at the first sample is zero; a record cut in the middle
    of a stroke keeps its speed (about 15 mm/s)."""
    t, logged, _ = _logged_rack(2, True)
    rack = smooth_rack(t, logged)
    assert rack.held_at_rest[0]
    assert abs(rack.evaluate(t[:1])[1][0]) < 1e-12
    t2, logged2, _ = _logged_rack(2, False)
    moving = smooth_rack(t2, logged2)
    assert not moving.held_at_rest[0]
    assert abs(moving.evaluate(t2[:1])[1][0]) > 0.01


def test_drawn_racks_scatter_as_the_data_allow():
    """Racks drawn from the spline's least-squares distribution differ from it by about the spline's own
    uncertainty: a small fraction of the rack noise, never more than the noise itself."""
    t, logged, _ = _logged_rack(3, True)
    rack = smooth_rack(t, logged)
    rng = np.random.default_rng(0)
    spread = np.std([rack.perturbed(rng).evaluate(t)[0] - rack.evaluate(t)[0] for _ in range(20)], axis=0)
    assert 0.1 * rack.noise_rms_m < np.median(spread) < rack.noise_rms_m


def test_fast_replay_agrees_with_the_models_prescribed_rack_solve(params):
    """The replay integrates the same equations as simulate(rack_drive=...) (only faster): on the same rack the two
    torques agree to a few thousandths of a N m, far below a converter step (0.2 N m), reversals included."""
    t, logged, _ = _logged_rack(4, True)
    rack = smooth_rack(t, logged)
    fine = np.arange(t[0], t[-1] + 1e-9, 0.005)
    drive = rack_drive_from_arrays(fine, rack.evaluate(fine)[0])
    reference = simulate("unladen", params=params, rack_drive=drive, output_dt_s=0.02)
    replay = Replay(resolve_effects(None), "unladen", "ground", params, rack, t)
    torque = replay.torque()
    expected = np.interp(t, reference.columns["time_s"], reference.columns["handwheel_torque_Nm"])
    assert np.max(np.abs(torque - expected)) < 0.005
    assert np.sqrt(np.mean((torque - expected) ** 2)) < 0.002


def test_an_effect_parameter_override_changes_the_torque_by_its_physical_share(params):
    """Raising the rack friction force by 100 N raises the sliding torque by 100 N / 186.47 rad/m = 0.54 N m
    at the handwheel (times the Hooke joint's speed ratio, 0.90 to 1.11)."""
    t, logged, _ = _logged_rack(5, True)
    rack = smooth_rack(t, logged)
    replay = Replay(resolve_effects(None), "unladen", "ground", params, rack, t)
    base = replay.torque()
    more = replay.torque({"rack_friction.friction_force": params["steering.rack_friction_force"] + 100.0})
    speed = rack.evaluate(t)[1]
    sliding = np.abs(speed) > 0.008
    share = (more - base)[sliding] * np.sign(speed[sliding])
    expected = 100.0 / params["steering.handwheel_to_rack_ratio"]
    assert np.all(share > 0.85 * expected) and np.all(share < 1.16 * expected)
    assert np.mean(share) == pytest.approx(expected, rel=0.05)
