"""Friction in the king-pin bearings (strut top mount and lower ball joint), growing with the wheel load."""

from __future__ import annotations

from ..lazy_sympy import sp

from ....names import SIDES
from ....parameters import Quantity
from ..components import Effect
from ..system import torque_between


class KingpinFriction(Effect):
    name = "kingpin_friction"
    description = (
        "Friction torque about each king-pin axis proportional to that wheel's load W: "
        "-r_f W tanh(beta * steer rate), r_f = mu_bearing * bearing radius; 0 = absent"
    )
    in_default_set = False
    quantities = (
        Quantity("kingpin_friction.friction_radius", "m", 0.0, 0.05, lower_inclusive=True, default=0.0,
                 source="candidate: effective friction radius mu_k * r_b of the strut's top-mount bearing and lower "
                        "ball joint, which carry the wheel load; e.g. mu 0.05-0.1 at radii 25-50 mm gives 0-5 mm, "
                        "i.e. up to about 14 N m per wheel at 2.8 kN (1.3 N m at the handwheel for both); 0 = "
                        "absent"),
    )
    uses = ("kingpin_friction.friction_radius", "steering.friction_smoothing")

    def loads(self, model):
        k = model.kinematics
        radius, beta = model.p("kingpin_friction.friction_radius"), model.p("steering.friction_smoothing")
        out = []
        for side in SIDES:
            axis_frame, wheel = k.axis_frame[side], k.steer_frame[side]
            steer_rate = wheel.ang_vel_in(axis_frame).dot(axis_frame.z)
            load = k.wheel_load[side]
            pressing = sp.Piecewise((load, load > 0), (0, True))  # a wheel off the ground loads no bearing
            torque = radius * pressing * sp.tanh(beta * steer_rate)
            # Between the steered assembly and the body (the axis frame is fixed in it).
            out += torque_between(-torque, axis_frame.z, wheel, axis_frame)
        return out


EFFECT = KingpinFriction()
