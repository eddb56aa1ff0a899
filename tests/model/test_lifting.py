"""Quasi-static lifting torque of the model against equation (A1)."""

from __future__ import annotations

import dataclasses

import numpy as np

from parksteer.geometry import lifting_torque_a1
from parksteer.model.numeric.simulate import simulate

ONLY_LIFTING = {"steering.rack_friction_force": 0.0, "steering.hooke_joint_angle": 0.0}


def test_handwheel_torque_equals_equation_a1_with_the_acting_loads(params):
    """With tyre friction off (air bearings), no rack friction and a straight column (Hooke joint angle 0), the
    handwheel torque while the handwheel turns at constant rate (lock to lock, from five column time constants
    c/k = 0.2 s after each corner on) is the virtual work of the vertical loads on the steered geometry,
    equation (A1), within 2 %.

    (A1) assumes fixed static loads; here it is evaluated with the loads that actually act at each instant: the
    tyre loads of the simulation (they change as the body lifts and rolls) less the weight of the parts whose
    height follows the wheel centre (the tread ring, at the wheel centre; the steering assembly's mass centre is
    on the king-pin axis, steering_assembly_cg_outboard = 0, so it does not move)."""
    assert params["steering.steering_assembly_cg_outboard"] == 0.0
    result = simulate("unladen", overrides=ONLY_LIFTING, surface="air_bearing", params=params, t_end_s=13.5)
    c = result.columns
    half = params["input.reversal_rounding_time"] / 2
    t_lock = params["input.time_to_right_lock"]
    t_left = t_lock + params["input.time_right_to_left_lock"]
    settle = 5 * params["steering.column_torsional_damping"] / params["steering.column_torsional_stiffness"]
    steady = ((c["time_s"] > half + settle) & (c["time_s"] < t_lock - half)) | (
        (c["time_s"] > t_lock + half + settle) & (c["time_s"] < t_left - half))
    ring_weight_N = params["tyre.tread_ring_mass"] * params["vehicle.gravity"]
    expected = np.empty(len(c["time_s"]))
    for k in np.flatnonzero(steady):
        case = dict(params.case("unladen"))
        case["load_left"] = c["load_left_N"][k] - ring_weight_N
        case["load_right"] = c["load_right_N"][k] - ring_weight_N
        acting = dataclasses.replace(params, cases={**params.cases, "unladen": case})
        expected[k] = lifting_torque_a1(acting, "unladen", c["steer_left_rad"][k])
    torque = c["handwheel_torque_Nm"][steady]
    expected = expected[steady]
    lock_torque = np.max(np.abs(expected))
    assert lock_torque > 1.0  # about 1.7 N m at lock (reconstruction notes): a real test, not 0 = 0
    significant = np.abs(expected) > 0.1 * lock_torque
    assert np.all(np.abs(torque - expected)[significant] <= 0.02 * np.abs(expected[significant]))
    assert np.all(np.abs(torque - expected)[~significant] <= 0.02 * 0.1 * lock_torque)
