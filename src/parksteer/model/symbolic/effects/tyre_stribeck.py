"""Rubber friction falling with sliding speed: a breakaway peak of the tyre's friction moment (a rival).

Strength a, the breakaway excess of the tyre moment (0 = Coulomb, absent), with the Stribeck rate omega_s (rad/s) of
the tread ring's yaw. Requires tyre_friction. The derivation, its reasoning and its sources: docs/model.md,
"Rubber's breakaway (`tyre_stribeck`)".
"""

from __future__ import annotations

from ..lazy_sympy import me, sp

from ....names import SIDES
from ....parameters import Quantity
from ..components import Effect, Rival
from .tyre_friction import EFFECT as TYRE_FRICTION


class TyreStribeck(Effect):
    name = "tyre_stribeck"
    description = (
        "Breakaway peak of the tyre friction moment: M(W) (1 + a exp(-(omega / omega_s)^2)) at ring yaw rate "
        "omega; 0 = Coulomb tread (absent)"
    )
    in_default_set = False
    rival = Rival(closest="brush_patch", related=("rack_stiction",),
                  why="both reshape the tread's moment where the patch goes from sticking to sliding (start and "
                      "each reversal); rack_stiction has the same breakaway form at the rack",
                  probe_strength=0.2)
    quantities = (
        Quantity("tyre_stribeck.breakaway_excess", "1", 0.0, 1.0, lower_inclusive=True, default=0.0,
                 source="candidate: a, the breakaway excess of the tread's friction moment over the sliding one, 1 "
                        "+ a exp(-(omega / omega_s)^2); rubber's static to sliding friction on dry floors is about "
                        "1-1.3, so 0-0.3; 0 = Coulomb (absent)"),
        Quantity("tyre_stribeck.stribeck_rate", "rad/s", 1.0e-4, 1.0, lower_inclusive=True, default=0.02,
                 source="choice: Stribeck rate omega_s of the tread's yaw; 0.02 rad/s is a sliding speed of about "
                        "1.6 mm/s at the patch rim (R about 0.08 m), a sixth of the cycle's steady 0.12 rad/s, so "
                        "the peak has vanished (exp(-36)) in steady sliding"),
    )
    uses = ("tyre_stribeck.breakaway_excess", "tyre_stribeck.stribeck_rate", *TYRE_FRICTION.uses)
    requires = ("tyre_friction",)

    def loads(self, model):
        k = model.kinematics
        beta = model.p("steering.friction_smoothing")
        grip = model.d("surface_grip")
        excess, rate = model.p("tyre_stribeck.breakaway_excess"), model.p("tyre_stribeck.stribeck_rate")
        out = []
        for side in SIDES:
            ring = k.ring_frame[side]
            yaw_rate = ring.ang_vel_in(model.N).dot(model.N.z)
            moment = grip * excess * TYRE_FRICTION.moment_limit(model, k.wheel_load[side]) * sp.exp(
                -(yaw_rate / rate) ** 2) * sp.tanh(beta * yaw_rate)
            out.append(me.Torque(ring, -moment * model.N.z))
        return out


EFFECT = TyreStribeck()
