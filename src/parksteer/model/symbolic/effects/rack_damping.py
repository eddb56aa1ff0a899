"""Viscous damping of the rack in its housing (a candidate beyond the paper)."""

from __future__ import annotations

from ....parameters import Quantity
from ..components import Effect
from ..system import action_reaction


class RackDamping(Effect):
    name = "rack_damping"
    description = "Viscous force on the rack along its axis, -c * rack speed (grease and seals); 0 = absent"
    in_default_set = False
    quantities = (
        Quantity("rack_damping.damping", "N s/m", 0.0, 1.0e5, lower_inclusive=True, default=0.0,
                 source="candidate: grease shear and seal drag of the rack; 0 = absent; a few thousand N s/m gives "
                        "a few N m at the handwheel at the cycle's 15 mm/s (c v / 186.47 rad/m: 5000 N s/m -> 0.4 N "
                        "m)"),
    )
    uses = ("rack_damping.damping",)

    def loads(self, model):
        k = model.kinematics
        force = model.p("rack_damping.damping") * model.rack_u
        # Between rack and housing: equal and opposite on the rack and on the body.
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


EFFECT = RackDamping()
