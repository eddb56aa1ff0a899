"""Breakaway (Stribeck) friction of the rack above its kinetic level (a candidate beyond the paper)."""

from __future__ import annotations

from ..lazy_sympy import sp

from ....parameters import Quantity
from ..components import Effect
from ..system import action_reaction


class RackStiction(Effect):
    name = "rack_stiction"
    description = (
        "Extra rack friction at low rack speed v (breakaway above the kinetic level, Stribeck): "
        "-(F_s - F) exp(-(v / v_s)^2) tanh(beta v); 0 = absent"
    )
    in_default_set = False
    quantities = (
        Quantity("rack_stiction.breakaway_excess", "N", 0.0, 5000.0, lower_inclusive=True, default=0.0,
                 source="candidate: static minus kinetic rack friction, F_s - F; typically 0-400 N beside F = 730 N "
                        "(0-55 %); 0 = absent"),
        Quantity("rack_stiction.stribeck_speed", "m/s", 1.0e-4, 0.1, lower_inclusive=True, default=0.005,
                 source="candidate: Stribeck speed of greased steel on steel/polymer, 1e-4 to 1e-2 m/s; 5 mm/s is "
                        "five widths 1/beta of the tanh, so the excess peaks at 83 % of F_s - F (at 1 mm/s the tanh "
                        "would cap it at 38 %), and a third of the cycle's 15 mm/s rack speed, so it has vanished "
                        "(exp(-9)) in steady steering"),
    )
    uses = ("rack_stiction.breakaway_excess", "rack_stiction.stribeck_speed", "steering.friction_smoothing")

    def loads(self, model):
        k = model.kinematics
        v = model.rack_u
        excess = model.p("rack_stiction.breakaway_excess") * sp.exp(-(v / model.p("rack_stiction.stribeck_speed")) ** 2)
        force = excess * sp.tanh(model.p("steering.friction_smoothing") * v)
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


EFFECT = RackStiction()
