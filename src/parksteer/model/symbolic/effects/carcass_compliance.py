"""Torsional compliance of the tyre carcass: each tread ring twists about the steer axis relative to its wheel."""

from __future__ import annotations

from ....names import SIDES
from ..components import Effect
from ..system import torque_between


class CarcassCompliance(Effect):
    name = "carcass_compliance"
    description = (
        "Tread ring joined to its wheel by the sidewall's torsional stiffness and damping; adds one twist "
        "coordinate per side (without it the ring is rigid to the wheel)"
    )
    uses = ("tyre.carcass_torsional_stiffness", "tyre.carcass_torsional_damping")
    replaces = "ring_twist"

    def configure(self, model):
        model.state(self).twist = {
            side: model.add_coordinate(f"twist_{side}", "rad", owner=self.name) for side in SIDES
        }

    def ring_twist(self, model, side):
        return model.state(self).twist[side][0]

    def _torque(self, model, side):
        q, u = model.state(self).twist[side]
        return model.p("tyre.carcass_torsional_stiffness") * q + model.p("tyre.carcass_torsional_damping") * u

    def loads(self, model):
        k = model.kinematics
        out = []
        for side in SIDES:
            # The sidewall between the tread ring and its wheel: equal and opposite about the steer axis.
            out += torque_between(-self._torque(model, side), k.steer_frame[side].z, k.ring_frame[side],
                                  k.steer_frame[side])
        return out

    def potential_energy(self, model):
        twist = model.state(self).twist
        return sum(model.p("tyre.carcass_torsional_stiffness") * twist[s][0] ** 2 / 2 for s in SIDES)


EFFECT = CarcassCompliance()
