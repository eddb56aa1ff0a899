"""Coulomb friction of the steering rack, smoothed with tanh (paper Fig. 11)."""

from __future__ import annotations

from ..lazy_sympy import sp

from ..components import Effect
from ..system import action_reaction


class RackFriction(Effect):
    name = "rack_friction"
    description = "Friction force on the rack along its axis: -F tanh(beta * rack speed)"
    uses = ("steering.rack_friction_force", "steering.friction_smoothing")

    def loads(self, model):
        k = model.kinematics
        force = model.p("steering.rack_friction_force") * sp.tanh(model.p("steering.friction_smoothing") * model.rack_u)
        # Friction between rack and housing: equal and opposite on the rack and on the body.
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


EFFECT = RackFriction()
