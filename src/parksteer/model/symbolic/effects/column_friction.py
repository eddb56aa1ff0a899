"""Coulomb friction in the steering column's bearings, above the Hooke joint (a candidate beyond the paper)."""

from __future__ import annotations

from ..lazy_sympy import sp

from ....parameters import Quantity
from ..components import Effect
from ..system import torque_between


class ColumnFriction(Effect):
    name = "column_friction"
    description = (
        "Friction torque of the column bearings on the column shaft (handwheel side of the Hooke joint), "
        "-T_c tanh(beta * column rate / handwheel_to_rack_ratio); 0 = absent"
    )
    in_default_set = False
    quantities = (
        Quantity("column_friction.friction_torque", "N m", 0.0, 20.0, lower_inclusive=True, default=0.0,
                 source="candidate: breakaway torque of the column's bearings and seals, typically 0-2 N m at the "
                        "handwheel; 0 = absent"),
    )
    uses = ("column_friction.friction_torque", "steering.friction_smoothing", "steering.handwheel_to_rack_ratio")

    def loads(self, model):
        k = model.kinematics
        rack_equivalent_speed = k.column_rate / model.p("steering.handwheel_to_rack_ratio")
        torque = model.p("column_friction.friction_torque") * sp.tanh(
            model.p("steering.friction_smoothing") * rack_equivalent_speed)
        # Between the column shaft and its bearings in the body: equal and opposite.
        return torque_between(-torque, k.B.y, k.column_frame, k.B)


EFFECT = ColumnFriction()
