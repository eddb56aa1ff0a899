"""ANALYTIC STAND-IN for the multibody model: a quasi-static steering cycle in closed form.

This is not the paper's model (that is :mod:`parksteer.model`). It exists so that measurement
files, phases and metrics can be exercised, quickly and independently of the model, with a
cycle whose every feature is known in closed form. It keeps the mechanisms of Section 4 that
shape the torque-rack loop, each in its simplest form:

- a rigid column and rack: rack = pinion angle / handwheel_to_rack_ratio;
- rack friction F tanh(beta v) (Appendix B), at the handwheel F / handwheel_to_rack_ratio;
- each tyre an elastic-perfectly-plastic carcass: moment = carcass stiffness * (steer - tread
  angle), the tread sliding once the moment reaches the equation (2) limit for that wheel's
  static load (no tread on air bearings); at the handwheel (M_left + M_right) / G;
- lifting, equation (A1), with the static loads;
- the Hooke joint: the handwheel torque is the pinion-side torque times the joint's speed ratio
  cos(b) / (1 - sin(b)^2 cos(theta - phase)^2), and the pinion angle follows
  tan(theta_p - phase) = tan(theta - phase) / cos(b).

Inertia, damping, chassis roll and load transfer are left out; the wheel loads stay static.
"""

from __future__ import annotations

import numpy as np

from .. import portable as pm
from ..geometry import lifting_torque_a1, steering_ratio
from ..names import SURFACES, TORQUE
from ..parameters import Parameters
from ..rig import limiting_torque_Nm
from .hand import HandProfile


def hooke_speed_ratio(column_angle_rad: np.ndarray, joint_angle_rad: float, phase_rad: float) -> np.ndarray:
    """Pinion speed / column speed of a Hooke joint: cos(b) / (1 - sin(b)^2 cos(theta - phase)^2)."""
    c = pm.cos(np.asarray(column_angle_rad) - phase_rad)
    return pm.cos(joint_angle_rad) / (1.0 - pm.sin(joint_angle_rad) ** 2 * c**2)


def hooke_output_angle(column_angle_rad: np.ndarray, joint_angle_rad: float, phase_rad: float) -> np.ndarray:
    """Pinion angle of a Hooke joint, tan(out - phase) = tan(in - phase) / cos(b), continuous in the input."""
    u = np.asarray(column_angle_rad, dtype=float) - phase_rad
    lag = pm.atan2(pm.sin(u), pm.cos(u) * pm.cos(joint_angle_rad)) - u
    lag = (lag + np.pi) % (2.0 * np.pi) - np.pi  # the lag is small; remove the 2 pi wraps
    return column_angle_rad + lag


def elastic_plastic_moment_Nm(steer_rad: np.ndarray, stiffness_Nm_rad: float, limit_Nm: float) -> np.ndarray:
    """Carcass moment along a steer history: k (steer - tread), the tread sliding at |moment| = limit."""
    tread = 0.0
    moment = np.empty(len(steer_rad))
    for i, steer in enumerate(steer_rad):
        twist = steer - tread
        if stiffness_Nm_rad * abs(twist) > limit_Nm:
            tread = steer - np.sign(twist) * limit_Nm / stiffness_Nm_rad
            twist = steer - tread
        moment[i] = stiffness_Nm_rad * twist
    return moment


def rack_of_hand(params: Parameters, handwheel_angle_rad: np.ndarray) -> np.ndarray:
    """Rack displacement (m) a handwheel angle gives through a rigid column and the Hooke joint."""
    s = params.sections["steering"]
    pinion = hooke_output_angle(handwheel_angle_rad, s["hooke_joint_angle"], s["hooke_joint_phase"])
    return pinion / s["handwheel_to_rack_ratio"]


def quasi_static_cycle(
    params: Parameters, case: str, hand: HandProfile, surface: str = "ground"
) -> dict[str, np.ndarray]:
    """Columns (time_s, handwheel_angle_rad, rack_m, handwheel_torque_Nm, load_left_N, load_right_N)."""
    if surface not in SURFACES:
        raise ValueError(f"surface must be one of {', '.join(SURFACES)}, got {surface!r}")
    s = params.sections["steering"]
    c = params.case(case)
    joint, phase = s["hooke_joint_angle"], s["hooke_joint_phase"]
    ratio = hooke_speed_ratio(hand.angle_rad, joint, phase)
    rack_m = rack_of_hand(params, hand.angle_rad)
    rack_speed = hand.rate_rad_s * ratio / s["handwheel_to_rack_ratio"]
    steer = rack_m * s["roadwheel_to_rack_ratio"]
    overall = steering_ratio(params)

    pinion_torque = s["rack_friction_force"] / s["handwheel_to_rack_ratio"] * pm.tanh(
        s["friction_smoothing"] * rack_speed
    )
    if surface == "ground":
        k = params["tyre.carcass_torsional_stiffness"]
        for load in (c["load_left"], c["load_right"]):
            carcass = elastic_plastic_moment_Nm(steer, k, limiting_torque_Nm(params, load))
            pinion_torque = pinion_torque + carcass / overall
    pinion_torque = pinion_torque + lifting_torque_a1(params, case, steer)
    return {
        "time_s": hand.time_s.copy(),
        "handwheel_angle_rad": hand.angle_rad.copy(),
        "rack_m": rack_m,
        TORQUE: pinion_torque * ratio,
        "load_left_N": np.full(len(rack_m), c["load_left"]),
        "load_right_N": np.full(len(rack_m), c["load_right"]),
    }
