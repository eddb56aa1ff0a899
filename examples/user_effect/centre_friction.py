"""A user-defined effect written from the physics: a rack bore worn tight at the centre (example, not part of the
library).

A car steers most straight ahead, so the rack's bushing wears its bore oval there, and a bent or dented rack binds
where it passes its tightest point. Either adds a friction force on the rack that is largest at the centre and
fades within some millimetres either side: here ``-F_c exp(-(x / w)^2) tanh(beta v)``, with x the rack position,
v its speed and beta the model's friction smoothing. The peak force F_c (N) is 0 when the bore is even.

The peak force and the width are declared free (``free=True``, within their bounds): with the effect in the
model, ``parksteer diagnose RUN.csv --effects=+examples/user_effect/centre_friction.py`` fits them together with
the calibrated parameters, from the defaults below, and gives its verdict on the model with the effect
(``parksteer compare`` fits them too). A quantity not declared free keeps the value it is given (its default, or
``--set``); so would either of these, given with ``--set`` to ``compare``.
"""

from __future__ import annotations

import sympy as sp

from parksteer.model.symbolic.components import Effect
from parksteer.model.symbolic.system import action_reaction
from parksteer.parameters import Quantity


class CentreFriction(Effect):
    name = "centre_friction"
    description = "Rack friction peaked at the centre: -F_c exp(-(x / w)^2) tanh(beta v); 0 = absent"
    in_default_set = False
    diagnosis_candidate = False
    quantities = (
        Quantity("centre_friction.peak_force", "N", 0.0, 2000.0, lower_inclusive=True, default=0.0, free=True,
                 source="example: a worn bore adds tens to a few hundred N to the rack friction of 500-1000 N"),
        Quantity("centre_friction.width", "m", 0.002, 0.05, default=0.010, free=True,
                 source="example: the worn zone, some millimetres of rack travel either side of the centre"),
    )
    uses = ("centre_friction.peak_force", "centre_friction.width", "steering.friction_smoothing")

    def loads(self, model):
        k = model.kinematics
        x, v = model.rack_q, model.rack_u
        shape = sp.exp(-((x / model.p("centre_friction.width")) ** 2))
        force = model.p("centre_friction.peak_force") * shape * sp.tanh(model.p("steering.friction_smoothing") * v)
        # Between rack and housing: equal and opposite on the rack and on the body.
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


EFFECT = CentreFriction()
