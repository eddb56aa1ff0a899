"""Torque ripple of the Hooke joint in the column."""

from __future__ import annotations

import numpy as np

from parksteer.model.numeric.simulate import simulate


def test_ripple_has_two_cycles_per_revolution_and_the_joint_amplitude(params):
    """With the rack friction alone resisting (air bearings, no lifting) the rack force is constant, F, and virtual
    work through tan(theta_c) = cos(a) tan(theta_p) gives T = (F / G) (cos^2 theta_p + cos^2 a sin^2 theta_p) / cos a
    = (F / G) [(1 - sin^2 a / 2) / cos a + (sin^2 a / (2 cos a)) cos 2 theta_p]: a ripple of two cycles per
    pinion revolution, of relative amplitude (1/cos a - cos a) / 2. A Fourier fit of the simulated torque over the
    steady part of the first steer must find that second harmonic (amplitude and phase) and no other."""
    result = simulate("unladen", effects="-lifting", surface="air_bearing", params=params, t_end_s=4.5,
                      output_dt_s=0.002)
    c = result.columns
    half = params["input.reversal_rounding_time"] / 2
    steady = (c["time_s"] > 2 * half) & (c["time_s"] < params["input.time_to_right_lock"] - 2 * half)
    pinion = params["steering.handwheel_to_rack_ratio"] * c["rack_m"][steady] - params["steering.hooke_joint_phase"]
    torque = c["handwheel_torque_Nm"][steady]
    assert np.ptp(pinion) > 2 * np.pi  # more than a revolution: several ripple cycles in the fit
    harmonics = (1, 2, 3, 4)
    basis = [np.ones_like(pinion)] + [f(k * pinion) for k in harmonics for f in (np.cos, np.sin)]
    coef, *_ = np.linalg.lstsq(np.column_stack(basis), torque, rcond=None)
    amplitude = {k: np.hypot(coef[2 * i + 1], coef[2 * i + 2]) for i, k in enumerate(harmonics)}
    a = params["steering.hooke_joint_angle"]
    rack_share_Nm = params["steering.rack_friction_force"] / params["steering.handwheel_to_rack_ratio"]
    assert abs(amplitude[2] / rack_share_Nm - (1 / np.cos(a) - np.cos(a)) / 2) < 0.03 * (1 / np.cos(a) - np.cos(a)) / 2
    assert coef[3] > 0.97 * amplitude[2]  # in phase with cos 2 theta_p: largest torque with the yokes in line
    assert abs(coef[0] / rack_share_Nm - (1 - np.sin(a) ** 2 / 2) / np.cos(a)) < 0.01
    assert max(amplitude[1], amplitude[3], amplitude[4]) < 0.05 * amplitude[2]
