"""A zero offset of an assisted car's torsion-bar torque sensor: a candidate of the diagnosis of an assisted car.

Mechanism. The sensor reads S = T_s + o (T_s the torque the bar carries). The control unit's boost curve and the
logger (which records the control unit's signal) both take the reading: the motor gives A(S), and the gear
carries ``T_s + A(S) = y`` (y the road torque at the torsion bar, :mod:`parksteer.model.numeric.assisted`), so the
reading solves ``S + A(S) = y + o``. An offset is thus a constant torque added to the road's at the torsion bar: in
the assist's linear range it moves the reading by o / (1 + G) only, while the current, which follows the reading,
moves by G o / (1 + G) in torque units; unlike a friction it does not flip with the direction of motion.

Law-side: it acts in the boost law of the assisted replay (:meth:`boost_law`), not in the mechanics (the effect adds
no load; its one output carries its value into the compiled model's parameter vector, where the replay reads it). A
handwheel-driven simulation leaves it out. Strength 0 is no offset, exactly; it may be negative.
"""

from __future__ import annotations

from dataclasses import replace

from ....parameters import Quantity
from ..components import Effect
from .assist_motor_friction import electric_assist_of

NAME = "torsion_bar_offset"
KEY = f"{NAME}.strength"


class TorsionBarOffset(Effect):
    name = NAME
    description = "Zero offset of the torsion-bar torque sensor, read by the boost law and the logger alike; 0 = absent"
    in_default_set = False
    diagnosis_candidate = False
    assist_candidate = True
    quantities = (
        Quantity(KEY, "N m", -2.0, 2.0, lower_inclusive=True, default=0.0,
                 source="candidate: a torque sensor's zero drifts by up to a few tenths of a N m before the "
                        "end-of-line zero calibration is repeated (Harrer & Pfeffer, Steering Handbook, ch. 8.5); "
                        "0 = absent"),
    )
    uses = (KEY,)

    def outputs(self, model):
        electric_assist_of(model, NAME)
        return [("torsion_bar_offset_Nm", model.p(KEY))]

    def boost_law(self, law, value):
        """The law's reading offset by o (the replay solves S + A(S) = y + o)."""
        return replace(law, offset=value(KEY))


EFFECT = TorsionBarOffset()
