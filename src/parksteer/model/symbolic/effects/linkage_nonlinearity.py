"""A symmetric nonlinearity of the linkage ratio: the steer angle grows faster than the rack towards lock (a rival).

Physics. The paper's linkage steers both wheels by roadwheel_to_rack_ratio * rack, a constant
ratio. A real rack, track rod and steering arm turn the arm's angle by asin-like laws of the rack
travel, so the ratio varies along the travel; for a symmetric layout the variation is even in
the rack. To leading order

    delta = G x (1 + c (G x)^2),   G = roadwheel_to_rack_ratio,

the same at both wheels (c > 0: the ratio rises towards lock, by 1 + 3 c (G x)^2; 0 = the
paper's constant ratio, absent). The rack force the road wheels' moments need is multiplied by
d(delta)/dx = G (1 + 3 c (G x)^2), so every road-wheel share at the handwheel (tyre, lifting,
carcass) rises towards lock by that factor.

It fills the steer_function slot, as ackermann does: both give the map from rack to each wheel's
steer angle, and a model has one such map, so the two cannot be combined (a linkage with both
would be one new law of its own: the Ackermann split of a nonlinear mean angle).

Signature against the rack: a rise towards lock proportional to the road-wheel torque, so it
scales with the tyre moment (W^1.5, the same share unladen and part laden in relative terms)
and does not depend on the spacer offset; it also changes the steer angle at lock for the same
rack travel (measurable by the wheel's angle against the rack, which separates it from every
torque-only mechanism). Lifting's rise is proportional to W and grows with the offset.
Provenance: a candidate beyond the paper; c is chosen, the linkage's geometry is not given.
"""

from __future__ import annotations

from ....parameters import Quantity
from ..components import Effect, Rival


class LinkageNonlinearity(Effect):
    name = "linkage_nonlinearity"
    description = (
        "Linkage ratio rising symmetrically towards lock: steer = G rack (1 + c (G rack)^2), G = "
        "roadwheel_to_rack_ratio, at both wheels; 0 = the paper's constant ratio (absent)"
    )
    in_default_set = False
    rival = Rival(closest="ackermann", related=(),
                  why="both change the map from rack travel to steer angle, and with it the road-wheel torque seen "
                      "at the handwheel towards lock",
                  probe_strength=0.1)
    quantities = (
        Quantity("linkage_nonlinearity.cubic_coefficient", "1", 0.0, 1.0, lower_inclusive=True, default=0.0,
                 source="candidate: c in steer = G x (1 + c (G x)^2), the linkage ratio rising towards lock by 1 + "
                        "3 c delta^2; rack-and-arm linkages vary their ratio by some per cent over the travel, so "
                        "0-0.3 (0.1 raises the ratio at the 0.56 rad lock by 9 %); 0 = the paper's constant ratio "
                        "(absent)"),
    )
    uses = ("steering.roadwheel_to_rack_ratio", "linkage_nonlinearity.cubic_coefficient")
    replaces = "steer_function"

    def steer_angle(self, model, side):
        reference = model.p("steering.roadwheel_to_rack_ratio") * model.rack_q
        return reference * (1 + model.p("linkage_nonlinearity.cubic_coefficient") * reference**2)


EFFECT = LinkageNonlinearity()
