"""A user-defined effect: an out-of-balance mass on the steering column (example, not part of the library).

A mass m whose centre sits a distance e off the axis of an inclined column shaft (a heavy
universal-joint yoke, a column-lock collar fitted off centre) is lifted and lowered once per
column turn. Its weight, resolved across the column inclined by lambda from the horizontal,
gives the column a torque -m g e sin(lambda) sin(theta_c - phase) about its axis, with
theta_c the column angle: a ripple once per turn, distinct from the Hooke joint's, which
comes twice per turn and scales with the torque carried. The strength m g e sin(lambda), in
N m, is 0 when the column is balanced.

The file is one module defining ``EFFECT``; nothing in the package refers to it. Join it to
the model with an effects spec, or name it in the environment::

    parksteer compare run.csv --effects=+src/parksteer/examples/column_imbalance.py
    PARKSTEER_EFFECT_MODULES=src/parksteer/examples/column_imbalance.py parksteer diagnose run.csv --json

or, from an installed package, with an entry point in its pyproject.toml::

    [project.entry-points."parksteer.effects"]
    column_imbalance = "my_package.column_imbalance:EFFECT"
"""

from __future__ import annotations

import math

# sympy as the package's own effects take it, imported at its first use: only a derivation builds the torque's
# expression, so a process that replays the compiled model (every diagnosis that has this effect among its
# candidates) never imports sympy. A file of your own may import sympy as it stands.
from parksteer.model.symbolic.lazy_sympy import sp

from parksteer.model.symbolic.components import Effect
from parksteer.model.symbolic.system import torque_between
from parksteer.parameters import Quantity


class ColumnImbalance(Effect):
    name = "column_imbalance"
    description = "Out-of-balance mass on the inclined column: torque -T_u sin(column angle - phase), once per turn"
    in_default_set = False
    # Quantities only this effect has, declared here as every effect declares its own (the parameter file holds the
    # car's): a run that uses the effect knows them from it.
    quantities = (
        Quantity("column_imbalance.strength", "N m", 0.0, 20.0, lower_inclusive=True, default=0.0,
                 source="example: m g e sin(lambda); 0.2 kg at 30 mm on a column inclined 25 deg gives 0.025 N m "
                        "per 100 g, so a few tenths of a N m for a heavy yoke"),
        Quantity("column_imbalance.phase", "rad", -math.pi, math.pi, lower_inclusive=True, default=0.0,
                 source="example: column angle at which the mass passes its highest point"),
    )
    uses = tuple(q.key for q in quantities)

    def _angle(self, model):
        return model.kinematics.column_angle - model.p("column_imbalance.phase")

    def loads(self, model):
        k = model.kinematics
        torque = -model.p("column_imbalance.strength") * sp.sin(self._angle(model))
        # The mass turns with the column; the column bearings in the body take the reaction.
        return torque_between(torque, k.B.y, k.column_frame, k.B)

    def potential_energy(self, model):
        # V = T_u (1 - cos(theta)), so that -dV/dtheta is the torque above.
        return model.p("column_imbalance.strength") * (1 - sp.cos(self._angle(model)))


EFFECT = ColumnImbalance()
