"""Viscous damping of the rack in its housing (a candidate beyond the paper)."""

from __future__ import annotations

from ..components import Effect
from ..system import action_reaction


class RackDamping(Effect):
    name = "rack_damping"
    description = "Viscous force on the rack along its axis, -c * rack speed (grease and seals); 0 = absent"
    in_default_set = False
    uses = ("rack_damping.damping",)

    def loads(self, model):
        k = model.kinematics
        force = model.p("rack_damping.damping") * model.rack_u
        # Between rack and housing: equal and opposite on the rack and on the body.
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


EFFECT = RackDamping()
