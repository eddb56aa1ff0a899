"""Friction in the king-pin bearings (strut top mount and lower ball joint), growing with the wheel load."""

from __future__ import annotations

import sympy as sp

from ..components import Effect, EffectParameter
from ..system import SIDES


class KingpinFriction(Effect):
    name = "kingpin_friction"
    description = (
        "Friction torque about each king-pin axis proportional to that wheel's load W: "
        "-r_f W tanh(beta * steer rate), r_f = mu_bearing * bearing radius; 0 = absent"
    )
    in_default_set = False
    parameters = (
        EffectParameter(
            "friction_radius", "m", 0.0, 0.05,
            "candidate: effective friction radius mu_k * r_b of the strut's top-mount bearing and lower ball "
            "joint, which carry the wheel load; e.g. mu 0.05-0.1 at radii 25-50 mm gives 0-5 mm, i.e. up to "
            "about 14 N m per wheel at 2.8 kN (1.3 N m at the handwheel for both); 0 = absent",
            default=0.0,
        ),
        EffectParameter(
            "smoothing", "s/rad", 1.0, 1.0e6,
            "Appendix B beta, used per rad/s of steer rate (as the tyre friction per rad/s of tread slip)",
            file_key="steering.friction_smoothing",
        ),
    )

    def loads(self, model):
        radius, beta = model.p(self, "friction_radius"), model.p(self, "smoothing")
        out = []
        for side in SIDES:
            axis_frame, wheel = model.axis_frame[side], model.steer_frame[side]
            steer_rate = wheel.ang_vel_in(axis_frame).dot(axis_frame.z)
            load = model.wheel_load[side]
            pressing = sp.Piecewise((load, load > 0), (0, True))  # a wheel off the ground loads no bearing
            torque = radius * pressing * sp.tanh(beta * steer_rate)
            # Between the steered assembly and the body (the axis frame is fixed in it).
            out += [(wheel, -torque * axis_frame.z), (axis_frame, torque * axis_frame.z)]
        return out


EFFECT = KingpinFriction()
