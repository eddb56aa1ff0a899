"""Load-dependent friction of the rack-and-pinion mesh (gear efficiency): a rival of the paper's constant rack friction.

Strength 1 - eta (0 = a lossless mesh): a force (N) between the rack and its housing against the rack's motion, in
proportion to the load the mesh carries. The derivation, its reasoning and its sources: docs/model.md, "The gear
mesh's efficiency (`gear_efficiency`)".
"""

from __future__ import annotations

from ..lazy_sympy import me, sp

from ....parameters import Quantity
from ..components import Effect, Rival
from ..system import action_reaction


class GearEfficiency(Effect):
    name = "gear_efficiency"
    description = (
        "Friction of the rack-and-pinion mesh proportional to the load it transmits: -(1 - eta) |F_road| "
        "tanh(beta * rack speed) on the rack; 0 = lossless (absent)"
    )
    in_default_set = False
    rival = Rival(closest="column_friction", related=("kingpin_friction", "rack_stiction"),
                  why="friction in the steering transmission, reversing with the motion; the mesh's grows with the "
                      "load it carries, the column's does not",
                  probe_strength=0.1)
    quantities = (
        Quantity("gear_efficiency.inefficiency", "1", 0.0, 0.5, lower_inclusive=True, default=0.0,
                 source="candidate: 1 - eta, the share of the transmitted torque the rack-and-pinion mesh (and the "
                        "column joints under load) loses to friction; forward efficiencies of rack-and-pinion "
                        "steering gears are about 0.8-0.9, so 0.1-0.2; 0 = lossless (absent)"),
        Quantity("gear_efficiency.smoothing_force", "N", 0.001, 100.0, lower_inclusive=True, default=1.0,
                 source="choice: force width w over which the mesh load |F| is smoothed as sqrt(F^2 + w^2) - w, so "
                        "the mesh friction is zero at zero load; 1 N is below 0.1 % of the rack load in steady "
                        "steering (about 3 kN)"),
    )
    uses = ("gear_efficiency.inefficiency", "gear_efficiency.smoothing_force", "steering.friction_smoothing")

    def road_force(self, model):
        """The force the rack needs on its road side: minus the rack's generalized force of every load but the
        column's (the column torque, and column-side loads, act above the mesh) and this effect's."""
        k = model.kinematics
        loads = list(model.core_loads())
        for effect in model.effects:
            if effect.name != self.name:
                loads += effect.loads(model)
        force = 0
        for where, vector in loads:
            if where is k.column_frame:
                continue
            velocity = where.ang_vel_in(model.N) if isinstance(where, me.ReferenceFrame) else where.vel(model.N)
            partial = velocity.diff(model.rack_u, model.N)
            if partial != 0:
                force -= partial.dot(vector)
        return force

    def loads(self, model):
        k = model.kinematics
        road = self.road_force(model)
        width = model.p("gear_efficiency.smoothing_force")
        magnitude = sp.sqrt(road**2 + width**2) - width
        force = model.p("gear_efficiency.inefficiency") * magnitude * sp.tanh(
            model.p("steering.friction_smoothing") * model.rack_u)
        # between rack and housing, as the rack's own friction
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


EFFECT = GearEfficiency()
