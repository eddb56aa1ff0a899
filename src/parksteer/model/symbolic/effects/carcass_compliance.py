"""Torsional compliance of the tyre carcass: each tread ring twists about the steer axis relative to its wheel."""

from __future__ import annotations

from ..components import Effect, EffectParameter
from ..system import SIDES


class CarcassCompliance(Effect):
    name = "carcass_compliance"
    description = (
        "Tread ring joined to its wheel by the sidewall's torsional stiffness and damping; adds one twist "
        "coordinate per side (without it the ring is rigid to the wheel)"
    )
    parameters = (
        EffectParameter("torsional_stiffness", "N m/rad", 1.0, 1.0e6, "Appendix B",
                        file_key="tyre.carcass_torsional_stiffness"),
        EffectParameter("torsional_damping", "N m s/rad", 0.0, 1.0e4, "Appendix B",
                        file_key="tyre.carcass_torsional_damping"),
    )

    def configure(self, model):
        self.twist = {}
        for side in SIDES:
            q, u = model.add_coordinate(f"twist_{side}", "rad", owner=self.name)
            model.set_ring_twist(side, q)
            self.twist[side] = (q, u)

    def _torque(self, model, side):
        q, u = self.twist[side]
        return model.p(self, "torsional_stiffness") * q + model.p(self, "torsional_damping") * u

    def loads(self, model):
        out = []
        for side in SIDES:
            axis = model.steer_frame[side].z
            torque = self._torque(model, side)
            out += [(model.ring_frame[side], -torque * axis), (model.steer_frame[side], torque * axis)]
        return out

    def potential_energy(self, model):
        return sum(model.p(self, "torsional_stiffness") * self.twist[s][0] ** 2 / 2 for s in SIDES)


EFFECT = CarcassCompliance()
