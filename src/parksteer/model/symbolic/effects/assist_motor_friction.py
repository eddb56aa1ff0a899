"""Extra Coulomb friction at an electric assist's motor: a candidate of the diagnosis of an assisted car.

Mechanism. The motor's bearings, seals and worm (or ball nut) drag more than the assist's own
``motor_friction_torque`` says (wear, a tight worm mesh, a dry seal): a torque T_e tanh(beta v) opposing the
rotor, reacted on the body, v the rack speed the rotor's speed corresponds to (the car-wide friction smoothing
beta, the shape of every friction candidate: a drag of unknown cause, not the assist's own band). The
rotor turns at N dx/dt (x the point of action, N the reduction), so at x the friction is N T_e: at a column assist
a torque on the column above the intermediate shaft, the same load as a column friction of N T_e there; at a
pinion or rack assist a force on the rack N T_e G_hr or N T_e, the same as a rack friction. The motor's current
does not see it: the control unit asks for the current its boost curve gives the torsion-bar torque, whatever
the friction; the friction shows as a larger torsion-bar torque (and with it a larger current) where the rack
moves, and it is told from a rack friction only by its lever (a column assist's is constant at the column, a rack
friction's varies with the intermediate shaft's joint, ``column_angle_per_rack``).

Strength 0 is no extra friction, exactly. Requires an electric assist in the set (refused in one line without).
"""

from __future__ import annotations

from ..lazy_sympy import sp

from ....errors import UsageError
from ....parameters import Quantity
from ..components import Effect
from ..system import torque_between

NAME = "assist_motor_friction"


def electric_assist_of(model, who: str):
    """The electric assist of the set being built (refused in one line without one)."""
    found = [e for e in model.effects if e.power_assist == "electric"]
    if not found:
        raise UsageError(f"{who} requires an electric assist in the effects (+electric_assist_column, _pinion or "
                         "_rack; or a vehicle file's [assist] with --with-assist)")
    return found[0]


class AssistMotorFriction(Effect):
    name = NAME
    description = ("Extra Coulomb friction of an electric assist's motor, -T_e tanh(beta v) on the rotor (N T_e at "
                   "the point of action); 0 = absent")
    in_default_set = False
    diagnosis_candidate = False  # not a candidate of a car without assist
    assist_candidate = True
    quantities = (
        Quantity(f"{NAME}.friction_torque", "N m", 0.0, 0.5, lower_inclusive=True, default=0.0,
                 source="candidate: extra breakaway torque at the motor beyond the assist's own; EPS motors and "
                        "worm gears 0.01-0.05 N m new (Harrer & Pfeffer, Steering Handbook, ch. 8.6), up to several "
                        "times that worn; 0 = absent"),
    )
    uses = (f"{NAME}.friction_torque", "steering.friction_smoothing", "steering.handwheel_to_rack_ratio")

    def loads(self, model):
        assist = electric_assist_of(model, NAME)
        k = model.kinematics
        frame = assist._motor_frame(model)  # the rotor's frame, turning at N dx/dt (electric_assist.py)
        ratio = model.p("steering.handwheel_to_rack_ratio")
        if assist.location == "column":
            rack_speed = k.column_rate / ratio
        elif assist.location == "pinion":
            rack_speed = model.rack_u
        else:
            rack_speed = model.rack_u
        friction = model.p(f"{NAME}.friction_torque") * sp.tanh(model.p("steering.friction_smoothing") * rack_speed)
        return torque_between(-friction, k.B.y, frame, k.B)


EFFECT = AssistMotorFriction()
