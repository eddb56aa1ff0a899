"""Lifting of the car by steering: vertical loads follow the steered wheel geometry (Appendix A)."""

from __future__ import annotations

from ....names import SIDES
from ..components import Effect
from ..system import action_reaction


class Lifting(Effect):
    name = "lifting"
    description = (
        "Tyre contact forces and the weights of the steered parts act where the king-pin geometry puts them, "
        "so steering lifts the car (without it they act at their zero-steer points, fixed in the body)"
    )

    replaces = "load_points"  # the tyre deflection, too, follows the steered contact height
    uses = ("vehicle.gravity",)

    def loads(self, model):
        """Move each vertical load from its chassis-fixed point (where the core applies it) to its true point."""
        k = model.kinematics
        n_z = model.N.z
        g = model.p("vehicle.gravity")
        out = []
        for side in SIDES:
            load = k.wheel_load[side]
            out += action_reaction(k.contact_point[side], -load * n_z, k.contact_point_unsteered[side])
        for point, mass, unsteered in k.weights:
            if unsteered is not None:
                out += action_reaction(point, mass * g * n_z, unsteered)
        return out

    def potential_energy(self, model):
        g = model.p("vehicle.gravity")
        return sum(
            -mass * g * (point.pos_from(model.origin) - unsteered.pos_from(model.origin)).dot(model.N.z)
            for point, mass, unsteered in model.kinematics.weights
            if unsteered is not None
        )


EFFECT = Lifting()
