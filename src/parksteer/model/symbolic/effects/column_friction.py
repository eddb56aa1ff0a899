"""Coulomb friction in the steering column's bearings, above the Hooke joint (a candidate beyond the paper)."""

from __future__ import annotations

import sympy as sp

from ..components import Effect, EffectParameter


class ColumnFriction(Effect):
    name = "column_friction"
    description = (
        "Friction torque of the column bearings on the column shaft (handwheel side of the Hooke joint), "
        "-T_c tanh(beta * column rate / handwheel_to_rack_ratio); 0 = absent"
    )
    in_default_set = False
    parameters = (
        EffectParameter(
            "friction_torque", "N m", 0.0, 20.0,
            "candidate: breakaway torque of the column's bearings and seals, typically 0-2 N m at the handwheel; "
            "0 = absent",
            default=0.0,
        ),
        EffectParameter(
            "smoothing", "s/m", 1.0, 1.0e6,
            "Appendix B beta, applied to the rack speed the column rate corresponds to (column rate / "
            "handwheel_to_rack_ratio), so the friction switches over the same ~1 mm/s of rack speed as the "
            "paper's rack friction",
            file_key="steering.friction_smoothing",
        ),
    )

    def loads(self, model):
        rack_equivalent_speed = model.column_rate / model.core("steering.handwheel_to_rack_ratio")
        torque = model.p(self, "friction_torque") * sp.tanh(model.p(self, "smoothing") * rack_equivalent_speed)
        # Between the column shaft and its bearings in the body: equal and opposite.
        return [(model.column_frame, -torque * model.B.y), (model.B, torque * model.B.y)]


EFFECT = ColumnFriction()
