"""The control unit's thermal derating of an electric assist's motor: an assisted candidate written as one user file
(example, not part of the library).

Physics. Parking is a column EPS's hardest duty: near the ends of a stroke the motor gives its largest torque at
almost no speed, so its windings and power stage heat while little cools them. The control unit models or measures
those temperatures and, after repeated parking manoeuvres, lowers the current it allows; full assist returns only
after minutes of rest. Within one record (a minute or so) the limit is constant: the motor's torque limit is
(1 - d) T_max instead of the vehicle file's T_max (``electric_assist_<location>.motor_torque_limit``), d the derated
fraction. Below the derated limit nothing changes (the same curve, the same current per torsion-bar torque); beyond
it the boost curve saturates earlier, the current flattens at (1 - d) T_max / k_t, and the driver's torsion-bar
torque takes the shortfall, so it rises near the ends of a stroke, where the rack needs most. Which car has it, and
how far, the owner does not know: the control unit does not report it (no lamp above some 40 % of the assist).

Sources of the range: service manuals describe the behaviour and its size. Honda's EPS ("Restriction on power
assist operation"): repeated turning back and forth at standstill heats the motor, the control unit reduces its
current gradually and restores it within about 8 minutes. Hyundai/Kia MDPS: more than about ten full turns at
standstill restrict the motor's current while the control module is above 85 degC. BMW F10 EPS: the assist is
reduced linearly from a temperature threshold, the warning shown only below 40 % of it; a powerpack's
over-temperature code cuts the motor torque to 30 %. So d from 0 (absent) to 0.7.

Law-side: it acts in the boost law of the assisted replay (:meth:`boost_law`: the law's limit times 1 - d), not in
the mechanics; it adds no load, and its one output carries d into the compiled model's parameter vector, where the
replay reads it. A handwheel-driven simulation leaves it out. d = 0 is the file's limit, exactly.

Registered as a candidate of every diagnosis of an electrically assisted car, it is tested with the package's own::

    PARKSTEER_EFFECT_MODULES=examples/assisted_candidate/current_derating.py \\
        parksteer diagnose RUN.csv --vehicle car.toml --with-assist
"""

from __future__ import annotations

from dataclasses import replace

from parksteer.model.symbolic.components import Effect
from parksteer.model.symbolic.effects.assist_motor_friction import electric_assist_of
from parksteer.parameters import Quantity

NAME = "current_derating"
KEY = f"{NAME}.fraction"


class CurrentDerating(Effect):
    name = NAME
    description = "Thermal derating of the motor's torque limit: (1 - d) T_max instead of the file's T_max; 0 = absent"
    in_default_set = False
    diagnosis_candidate = False
    assist_candidate = True
    quantities = (
        Quantity(KEY, "1", 0.0, 0.7, lower_inclusive=True, default=0.0,
                 source="candidate: EPS control units derate the motor's current after repeated parking at "
                        "standstill, down to 40 % (BMW F10) or 30 % (powerpack over-temperature) of the assist; "
                        "Honda and Hyundai/Kia service manuals; 0 = absent"),
    )
    uses = (KEY,)

    def outputs(self, model):
        electric_assist_of(model, NAME)
        return [("current_derating_fraction", model.p(KEY))]

    def boost_law(self, law, value):
        """The motor's limit (1 - d) T_max: the boost curve saturates earlier."""
        return replace(law, limit=law.limit * (1.0 - value(KEY)))


EFFECT = CurrentDerating()
