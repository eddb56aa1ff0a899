"""A symmetric nonlinearity of the linkage ratio: the steer angle grows faster than the rack towards lock (a rival).

It fills the steer_function slot, as ackermann does: both give the map from rack to each wheel's
steer angle, and a model has one such map, so the two cannot be combined (a linkage with both
would be one new law of its own: the Ackermann split of a nonlinear mean angle).

Strength c (0 = the paper's constant ratio): delta = G x (1 + c (G x)^2), x the rack travel (m), delta the steer
angle (rad). The derivation, its reasoning and its sources: docs/model.md, "The linkage's nonlinearity
(`linkage_nonlinearity`)".
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
