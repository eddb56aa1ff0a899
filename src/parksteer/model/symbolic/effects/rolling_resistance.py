"""Rolling resistance of the free-rolling wheel, acting through the ground scrub radius (a rival).

Strength C_rr (dimensionless, 0 = absent): a torque C_rr W |e| (N m) about each steer axis against the tread ring's
steer rate, W the wheel load (N), e the scrub offset (m). The derivation, its reasoning and its sources:
docs/model.md, "Rolling resistance (`rolling_resistance`)".
"""

from __future__ import annotations

from ..lazy_sympy import me, sp

from ....names import SIDES
from ....parameters import Quantity
from ..components import Effect, Rival
from .braked_wheels import EFFECT as BRAKED_WHEELS


class RollingResistance(Effect):
    name = "rolling_resistance"
    description = (
        "Rolling-resistance moment of the free-rolling wheel about its steer axis, -C_rr W |scrub radius| "
        "tanh(beta * steer rate); 0 = absent"
    )
    in_default_set = False
    rival = Rival(closest="braked_wheels", related=("kingpin_friction",),
                  why="both are a force at the contact patch acting on the scrub radius, W |e|, against the steer "
                      "rate; kingpin_friction is a friction moment about the same axis growing with W",
                  probe_strength=0.015)
    quantities = (
        Quantity("rolling_resistance.coefficient", "1", 0.0, 0.1, lower_inclusive=True, default=0.0,
                 source="candidate: rolling-resistance coefficient C_rr of the tyre rolling on the floor as the "
                        "patch travels round the steer axis; car tyres have 0.01-0.015 on hard floors, more at low "
                        "pressure; 0 = absent"),
    )
    uses = ("rolling_resistance.coefficient", "steering.friction_smoothing")

    def loads(self, model):
        k = model.kinematics
        coefficient, beta = model.p("rolling_resistance.coefficient"), model.p("steering.friction_smoothing")
        grip = model.d("surface_grip")
        out = []
        for side in SIDES:
            axis_frame, ring = k.axis_frame[side], k.ring_frame[side]
            rate = ring.ang_vel_in(axis_frame).dot(axis_frame.z)
            load = k.wheel_load[side]
            pressing = sp.Piecewise((load, load > 0), (0, True))  # a wheel off the ground rolls on nothing
            arm = sp.sqrt(BRAKED_WHEELS.scrub_offset_squared(model, side))
            torque = grip * coefficient * pressing * arm * sp.tanh(beta * rate)
            # the ground's force on the tread (the ground takes the reaction): a torque on the ring about the axis
            out.append(me.Torque(ring, -torque * axis_frame.z))
        return out


EFFECT = RollingResistance()
