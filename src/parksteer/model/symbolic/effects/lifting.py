"""Lifting of the car by steering: vertical loads follow the steered wheel geometry (Appendix A)."""

from __future__ import annotations

from ..components import Effect
from ..system import SIDES


class Lifting(Effect):
    name = "lifting"
    description = (
        "Tyre contact forces and the weights of the steered parts act where the king-pin geometry puts them, "
        "so steering lifts the car (without it they act at their zero-steer points, fixed in the body)"
    )

    def configure(self, model):
        model.contact_follows_steer = True  # the tyre deflection follows the steered contact height

    def loads(self, model):
        """Move each vertical load from its chassis-fixed point (where the core applies it) to its true point."""
        n_z = model.N.z
        g = model.core("vehicle.gravity")
        out = []
        for side in SIDES:
            load = model.wheel_load[side]
            out += [(model.contact_point[side], -load * n_z), (model.contact_point_unsteered[side], load * n_z)]
        for point, mass, unsteered in model.weights:
            if unsteered is not None:
                out += [(point, mass * g * n_z), (unsteered, -mass * g * n_z)]
        return out

    def potential_energy(self, model):
        g = model.core("vehicle.gravity")
        return sum(
            -mass * g * (point.pos_from(model.origin) - unsteered.pos_from(model.origin)).dot(model.N.z)
            for point, mass, unsteered in model.weights
            if unsteered is not None
        )


EFFECT = Lifting()
