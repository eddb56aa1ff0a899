"""A boost-curve gain that differs from the vehicle file's: a candidate of the diagnosis of an assisted car.

Mechanism. The control unit's gain is G (1 + e) instead of the file's G (another software calibration, a
parking map the file does not know): the motor torque is clamp(G (1 + e) deadband(S) s / (eta N), T_max). The
torsion-bar torque falls as 1 / (1 + G (1 + e)) in the linear range and the current per torsion-bar torque rises
as (1 + e): the current channel fixes e directly, the torque alone only through the ratio of the two slopes.

Law-side: it acts in the boost law of the assisted replay (:meth:`boost_law`, :mod:`parksteer.model.numeric.assisted`),
not in the mechanics (no load; its one output carries its value into the compiled model's parameter vector). A
handwheel-driven simulation leaves it out. Strength 0 is the file's gain, exactly; it may be negative (a weaker
curve).
"""

from __future__ import annotations

from dataclasses import replace

from ....parameters import Quantity
from ..components import Effect
from .assist_motor_friction import electric_assist_of

NAME = "boost_gain_error"
KEY = f"{NAME}.strength"


class BoostGainError(Effect):
    name = NAME
    description = "Relative error e of the boost curve's gain: G (1 + e) instead of the file's G; 0 = absent"
    in_default_set = False
    diagnosis_candidate = False
    assist_candidate = True
    quantities = (
        Quantity(KEY, "1", -0.9, 2.0, lower_inclusive=True, default=0.0,
                 source="candidate: parking gains of EPS boost curves span 4-10 (Harrer & Pfeffer, Steering "
                        "Handbook, ch. 8.2), so a file's assumed gain may be off by -0.5 to +1 of itself; 0 = absent"),
    )
    uses = (KEY,)

    def outputs(self, model):
        electric_assist_of(model, NAME)
        return [("boost_gain_error", model.p(KEY))]

    def boost_law(self, law, value):
        """The law's gain and its table scaled by 1 + e."""
        factor = 1.0 + value(KEY)
        return replace(law, gain=law.gain * factor, table_scale=factor)


EFFECT = BoostGainError()
