"""Viscous damping of the rack in its housing (a candidate beyond the paper)."""

from __future__ import annotations

from ..components import Effect, EffectParameter


class RackDamping(Effect):
    name = "rack_damping"
    description = "Viscous force on the rack along its axis, -c * rack speed (grease and seals); 0 = absent"
    in_default_set = False
    parameters = (
        EffectParameter(
            "damping", "N s/m", 0.0, 1.0e5,
            "candidate: grease shear and seal drag of the rack; 0 = absent; a few thousand N s/m gives a few "
            "N m at the handwheel at the cycle's 15 mm/s (c v / 186.47 rad/m: 5000 N s/m -> 0.4 N m)",
            default=0.0,
        ),
    )

    def loads(self, model):
        force = model.p(self, "damping") * model.rack_u
        # Between rack and housing: equal and opposite on the rack and on the body.
        return [(model.rack_point, -force * model.B.y), (model.rack_housing_point, force * model.B.y)]


EFFECT = RackDamping()
