"""Rolling resistance of the free-rolling wheel, acting through the ground scrub radius (a rival).

Physics. With the wheel free to roll (the paper's model), steering carries the contact patch
centre round the king-pin axis's ground intercept along the wheel's rolling direction, at omega e
(e the scrub radius at the ground), and the wheel rolls to take it up (section 2, Table 1). Rolling
is not free of loss: the tyre's rolling resistance, a force C_rr W against the rolling, acts at
the patch centre, a moment C_rr W |e| about the steer axis against the steer rate. The paper's
model leaves it out. Model: at each wheel a torque about the steer axis on the tread ring,

    T = -C_rr W |e| tanh(beta * ring steer rate),

with the ring's rate about the axis relative to the body (the tread is what rolls), W the wheel
load (0 off the ground), |e| the scrub offset as computed for braked_wheels (5.8 mm standard,
62.7 mm with the 68.5 mm spacer), times the surface grip (0 on air bearings: nothing rolls).
C_rr (0 = absent) is chosen: car tyres on a hard floor have 0.01-0.015, more at low pressure.

Signature against the rack: a friction share, flipping at each reversal (dissipative, unlike
lifting), proportional to the wheel load W like lifting, and growing in proportion to the scrub
offset |e| with the spacers (about ten times larger at 68.5 mm than standard), so load and offset
do not separate it from lifting, but its sign does: lifting's share follows the rack position and
is returned on the way back, this one follows the rack speed. It is small: 0.012 W |e| is
0.2 N m per wheel on the standard car. Provenance: a candidate beyond the paper.
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
