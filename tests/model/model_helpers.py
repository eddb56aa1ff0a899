"""Helpers shared by the model tests (plain functions, imported by name)."""

from __future__ import annotations

import numpy as np


def first_ramp(result, rack_from_m: float = 0.02, rack_to_m: float = 0.06):
    """Mask of the first steer towards right lock with the rack between the two positions (the plateau)."""
    c = result.columns
    t_lock = result.values.params["input.time_to_right_lock"]
    return (c["time_s"] < t_lock) & (c["rack_m"] >= rack_from_m) & (c["rack_m"] <= rack_to_m)


def plateau_mean(result, column: str = "handwheel_torque_Nm") -> float:
    return float(np.mean(result.columns[column][first_ramp(result)]))

# Every friction and damper of the paper's model off (for energy balances).
DISSIPATION_OFF = {
    "rack_friction.friction_force": 0.0,
    "carcass_compliance.torsional_damping": 0.0,
    "steering.column_torsional_damping": 0.0,
    "tyre.radial_damping": 0.0,
    "vehicle.chassis_roll_damping": 0.0,
}
