"""Breakaway (Stribeck) friction of the rack above its kinetic level (a candidate beyond the paper)."""

from __future__ import annotations

import sympy as sp

from ..components import Effect, EffectParameter


class RackStiction(Effect):
    name = "rack_stiction"
    description = (
        "Extra rack friction at low rack speed v (breakaway above the kinetic level, Stribeck): "
        "-(F_s - F) exp(-(v / v_s)^2) tanh(beta v); 0 = absent"
    )
    in_default_set = False
    parameters = (
        EffectParameter(
            "breakaway_excess", "N", 0.0, 5000.0,
            "candidate: static minus kinetic rack friction, F_s - F; typically 0-400 N beside F = 730 N "
            "(0-55 %); 0 = absent",
            default=0.0,
        ),
        EffectParameter(
            "stribeck_speed", "m/s", 1.0e-4, 0.1,
            "candidate: Stribeck speed of greased steel on steel/polymer, 1e-4 to 1e-2 m/s; 5 mm/s is five "
            "widths 1/beta of the tanh, so the excess peaks at 83 % of F_s - F (at 1 mm/s the tanh would cap it "
            "at 38 %), and a third of the cycle's 15 mm/s rack speed, so it has vanished (exp(-9)) in steady "
            "steering",
            default=0.005,
        ),
        EffectParameter(
            "smoothing", "s/m", 1.0, 1.0e6, "Appendix B, beta (as the rack friction)",
            file_key="steering.friction_smoothing",
        ),
    )

    def loads(self, model):
        v = model.rack_u
        excess = model.p(self, "breakaway_excess") * sp.exp(-(v / model.p(self, "stribeck_speed")) ** 2)
        force = excess * sp.tanh(model.p(self, "smoothing") * v)
        return [(model.rack_point, -force * model.B.y), (model.rack_housing_point, force * model.B.y)]


EFFECT = RackStiction()
