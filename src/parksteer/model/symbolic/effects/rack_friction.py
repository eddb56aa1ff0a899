"""Coulomb friction of the steering rack, smoothed with tanh (paper Fig. 11)."""

from __future__ import annotations

import sympy as sp

from ..components import Effect, EffectParameter


class RackFriction(Effect):
    name = "rack_friction"
    description = "Friction force on the rack along its axis: -F tanh(beta * rack speed)"
    parameters = (
        EffectParameter("friction_force", "N", 0.0, 1.0e5, "Appendix B, F", file_key="steering.rack_friction_force"),
        EffectParameter("smoothing", "s/m", 1.0, 1.0e6, "Appendix B, beta", file_key="steering.friction_smoothing"),
    )

    def loads(self, model):
        force = model.p(self, "friction_force") * sp.tanh(model.p(self, "smoothing") * model.rack_u)
        # Friction between rack and housing: equal and opposite on the rack and on the body.
        return [(model.rack_point, -force * model.B.y), (model.rack_housing_point, force * model.B.y)]


EFFECT = RackFriction()
