"""Breakaway (Stribeck) friction of the rack above its kinetic level (a candidate beyond the paper)."""

from __future__ import annotations

import sympy as sp

from ..components import Effect
from ..system import action_reaction


class RackStiction(Effect):
    name = "rack_stiction"
    description = (
        "Extra rack friction at low rack speed v (breakaway above the kinetic level, Stribeck): "
        "-(F_s - F) exp(-(v / v_s)^2) tanh(beta v); 0 = absent"
    )
    in_default_set = False
    uses = ("rack_stiction.breakaway_excess", "rack_stiction.stribeck_speed", "steering.friction_smoothing")

    def loads(self, model):
        k = model.kinematics
        v = model.rack_u
        excess = model.p("rack_stiction.breakaway_excess") * sp.exp(-(v / model.p("rack_stiction.stribeck_speed")) ** 2)
        force = excess * sp.tanh(model.p("steering.friction_smoothing") * v)
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


EFFECT = RackStiction()
