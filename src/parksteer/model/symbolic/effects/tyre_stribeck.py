"""Rubber friction falling with sliding speed: a breakaway peak of the tyre's friction moment (a rival).

Physics. The paper's tyre moment is Coulomb: M(W) of equation (2) at any sliding speed,
smoothed by tanh. Rubber on a road often breaks away at a higher friction than it slides with
(adhesion of the tread at rest, falling as the sliding speed rises: a Stribeck-type curve), so
the tread's moment would peak when the patch starts to slide, after the carcass has wound up at
the start and after each reversal, and fall back to the sliding level. Model: the moment of each
tread ring is multiplied by

    1 + a exp(-(omega / omega_s)^2),

omega the ring's yaw rate: the effect adds -a M(W) exp(-(omega / omega_s)^2) tanh(beta omega) (grip
as for tyre_friction: 0 on air bearings). a is the breakaway excess (0 = Coulomb, absent), omega_s
the Stribeck rate (the tread's sliding speed at the patch rim is omega R, R about 0.08 m).
Requires tyre_friction (its moment law and quantities).

Signature against the rack: humps of the torque where the tread is slow: where it breaks away at
the end of the carcass wind-up (at the start and after each reversal) and as it slows into each
reversal; none in steady sliding (the ring's yaw rate there, about 0.12 rad/s, is six omega_s), scaled like the tyre moment (W^1.5, falling
with pressure) and independent of the spacer offset. Lifting adds a torque that grows steadily
towards lock, proportional to W and growing with the offset. Provenance: a candidate beyond the
paper (rubber friction against sliding speed, e.g. Persson's and Grosch's measurements); values
are chosen, none are measured for this tyre.
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
