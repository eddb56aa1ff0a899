"""The column assist's gear in the assistance study (:mod:`parksteer.figures.assist_study`): the efficiencies of
its worm and ball-nut gears as the effects' defaults take them, and how much of the standstill cycle the gear is
back-driven (the rack driving the motor)."""

from __future__ import annotations

import numpy as np

from ..model.numeric.simulate import SimulationResult
from ..parameters import Parameters
from ..vehicle import ASSIST_EFFECTS


def gear_numbers() -> dict:
    """The assist gears' efficiencies from their thread (parksteer.reduction_efficiency) as the effects' defaults take
    them, the least eta_b at which the replay's law rises, the units guard's window of rack forces and the largest
    boost map (points, speed rows)."""
    from .. import reduction_efficiency as re_
    from ..boost_table import MAX_POINTS, MAX_SPEEDS
    from ..model.numeric.assist import rack_force_window_N
    from ..model.symbolic.effects import electric_assist as ea

    degrees = 180.0 / re_.PI
    low, high = rack_force_window_N()
    return {
        "worm": {"efficiency": ea.WORM_FORWARD_EFFICIENCY, "back_efficiency": ea.WORM_BACK_EFFICIENCY,
                 "friction_angle_deg": ea.WORM_FRICTION_ANGLE_RAD * degrees,
                 "lead_angle_deg": ea._WORM_LEAD_ANGLE_RAD * degrees,
                 "least_back_efficiency": re_.min_monotone_back_efficiency(ea.WORM_FORWARD_EFFICIENCY)},
        "ball_nut": {"efficiency": ea.BALL_NUT_FORWARD_EFFICIENCY, "back_efficiency": ea.BALL_NUT_BACK_EFFICIENCY,
                     "lead_mm": ea.BALL_NUT_LEAD_M * 1e3, "ball_circle_mm": ea.BALL_NUT_BALL_CIRCLE_M * 1e3,
                     "lead_angle_deg": ea._NUT_LEAD_ANGLE_RAD * degrees,
                     "friction_angle_deg": ea._NUT_FRICTION_ANGLE_RAD * degrees},
        "rack_force_window_N": [low, high],
        "map_size": {"points": MAX_POINTS, "speeds": MAX_SPEEDS},
    }


def back_driven(result: SimulationResult, params: Parameters, least_Nm: float = 1.0) -> dict:
    """How much of the standstill cycle the column assist's gear is back-driven: the share of the samples with more
    than `least_Nm` of assist at the column where it delivers more than N T_m (the rack driving the motor), and the
    largest delivered factor, assist / (N T_m), over those samples."""
    c = result.columns
    name = ASSIST_EFFECTS["column"]
    n = result.values.value(f"{name}.reduction_ratio")
    strong = np.abs(c["assist_torque_Nm"]) > least_Nm
    factor = c["assist_torque_Nm"][strong] / (n * c["motor_torque_Nm"][strong])
    return {"least_assist_Nm": least_Nm, "share": float(np.mean(factor > 1.0)), "largest_factor": float(np.max(factor)),
            "forward_factor": float(np.min(factor))}
