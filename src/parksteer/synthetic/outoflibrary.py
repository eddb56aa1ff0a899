"""Out-of-library truth effects: everyday mechanisms in forms no diagnosis candidate has, for the signature benchmark.

Each form is an :class:`~parksteer.model.symbolic.components.Effect` with one strength (0 = absent) and its
shape fixed by constants here; none is a library candidate's form (rack friction, damping, stiction, lash,
column friction, gear efficiency, king-pin friction, ...: :mod:`parksteer.model.symbolic.effects`). They come
in the signature's classes (:data:`parksteer.diagnose.signature.CLASSES`), several per class; each form, its
formula and the mechanism it stands for: docs/signature.md, "The out-of-library forms
(`parksteer.synthetic.outoflibrary`)".

Forces act between rack and housing, torques on the column shaft against the body, as the library's do.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..model.symbolic.lazy_sympy import sp  # sympy on first use: the workflow reads the forms' names

from ..model.symbolic.components import Effect
from ..model.symbolic.system import action_reaction, torque_between
from ..parameters import Quantity

FORCE_UPPER_N = 1e6  # any unit of the forms below: a bound for the search, not a physical range
TORQUE_UPPER_NM = 10.0


def _strength(name: str, unit: str, upper: float, why: str) -> Quantity:
    return Quantity(f"{name}.strength", unit, 0.0, upper, lower_inclusive=True, default=0.0,
                    source=f"out-of-library benchmark truth: {why}; 0 = absent")


class _RackForce(Effect):
    """A force on the rack, -strength * shape(x, v), between rack and housing."""

    in_default_set = False
    diagnosis_candidate = False
    why = ""
    unit = "N"  # of the strength: the force per unit shape

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        cls.quantities = (_strength(cls.name, cls.unit, FORCE_UPPER_N, cls.why),)
        cls.uses = (f"{cls.name}.strength", "steering.friction_smoothing")

    def shape(self, x, v, beta):
        raise NotImplementedError

    def loads(self, model):
        k = model.kinematics
        beta = model.p("steering.friction_smoothing")
        force = model.p(f"{self.name}.strength") * self.shape(model.rack_q, model.rack_u, beta)
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


class _ColumnTorque(Effect):
    in_default_set = False
    diagnosis_candidate = False
    why = ""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        cls.quantities = (_strength(cls.name, "N m", TORQUE_UPPER_NM, cls.why),)
        cls.uses = (f"{cls.name}.strength",)

    def shape(self, theta):
        raise NotImplementedError

    def loads(self, model):
        k = model.kinematics
        torque = -model.p(f"{self.name}.strength") * self.shape(k.column_angle)
        return torque_between(torque, k.B.y, k.column_frame, k.B)


class FrictionBump(_RackForce):
    name = "oolib_friction_bump"
    description = "Rack friction bump at +20 mm, 12 mm wide"
    why = "a dent in the rack bore"

    def shape(self, x, v, beta):
        return sp.exp(-(((x - 0.020) / 0.012) ** 2)) * sp.tanh(beta * v)


class LockFriction(_RackForce):
    name = "oolib_lock_friction"
    description = "Rack friction growing toward lock as (x / 70 mm)^2"
    why = "a bent rack binding toward the ends"

    def shape(self, x, v, beta):
        return (x / 0.070) ** 2 * sp.tanh(beta * v)


class DeadZoneSpring(_RackForce):
    name = "oolib_deadzone_spring"
    description = "Centring spring with a +-15 mm dead zone, k (x - d tanh(x / d)), per m"
    why = "a centring spring with preload"

    def shape(self, x, v, beta):
        return (x - 0.015 * sp.tanh(x / 0.015)) / 0.015


class CentreDetent(_RackForce):
    name = "oolib_centre_detent"
    description = "Centre detent, (x / w) exp(-(x / w)^2), w = 8 mm"
    why = "a detent notch straight ahead"

    def shape(self, x, v, beta):
        return (x / 0.008) * sp.exp(-((x / 0.008) ** 2))


class OneWayDrag(_RackForce):
    name = "oolib_one_way_drag"
    description = "Drag only while the rack moves right, (1 + tanh(beta v)) / 2 tanh(beta v)"
    why = "a seal lip dragging one way"

    def shape(self, x, v, beta):
        s = sp.tanh(beta * v)
        return (1 + s) / 2 * s


class MovingOffset(_RackForce):
    name = "oolib_moving_offset"
    description = "A force toward the left while the rack moves either way, tanh(beta v)^2"
    why = "a boot pushing the rack aside while it moves"

    def shape(self, x, v, beta):
        return sp.tanh(beta * v) ** 2


class CubicDamping(_RackForce):
    name = "oolib_cubic_damping"
    description = "Rack damping v (1 + (v / 20 mm/s)^2), per m/s"
    why = "grease shearing thicker than Newtonian"
    unit = "N s/m"

    def shape(self, x, v, beta):
        return v * (1 + (v / 0.020) ** 2)


class QuadraticDrag(_RackForce):
    name = "oolib_quadratic_drag"
    description = "Quadratic drag v |v| (|v| as v tanh(beta v)), per (m/s)^2"
    why = "a fluid forced through the boot's vents"
    unit = "N s^2/m^2"

    def shape(self, x, v, beta):
        return v * v * sp.tanh(beta * v)


class ColumnOnce(_ColumnTorque):
    name = "oolib_column_once"
    description = "Once-per-turn column torque sin(theta_c - 0.7)"
    why = "an eccentric column bearing"

    def shape(self, theta):
        return sp.sin(theta - 0.7)


class ColumnSecond(_ColumnTorque):
    name = "oolib_column_second"
    description = "Second-order column ripple sin(2 theta_c + 0.4)"
    why = "a worn intermediate joint"

    def shape(self, theta):
        return sp.sin(2 * theta + 0.4)


COLUMN_RATE_SCALE_RAD_S = 0.5  # the truth column frictions' breakaway: tanh(omega_c / 0.5 rad/s)


class _ColumnFriction(Effect):
    """A friction torque on the column shaft, -strength * shape(theta_c) * tanh(omega_c / 0.5 rad/s), between
    the column and the body."""

    in_default_set = False
    diagnosis_candidate = False
    why = ""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        cls.quantities = (_strength(cls.name, "N m", TORQUE_UPPER_NM, cls.why),)
        cls.uses = (f"{cls.name}.strength",)

    def shape(self, theta):
        raise NotImplementedError

    def loads(self, model):
        k = model.kinematics
        torque = -model.p(f"{self.name}.strength") * self.shape(k.column_angle) * sp.tanh(
            k.column_rate / COLUMN_RATE_SCALE_RAD_S)
        return torque_between(torque, k.B.y, k.column_frame, k.B)


class PinchedBearing(_ColumnFriction):
    name = "oolib_pinched_bearing"
    description = "Column friction pinched once per turn, exp((cos(theta_c - 0.9) - 1) / 0.25), per N m"
    why = "a column bearing pinched at one place of its turn"

    def shape(self, theta):
        return sp.exp((sp.cos(theta - 0.9) - 1) / 0.25)


class JointFriction(_ColumnFriction):
    name = "oolib_joint_friction"
    description = "Column friction growing twice per turn with the joint's angle, sin(theta_c + 0.3)^4, per N m"
    why = "an intermediate joint whose friction grows with its articulation"

    def shape(self, theta):
        return sp.sin(theta + 0.3) ** 4


@dataclass(frozen=True)
class TruthForm:
    effect: Effect
    signature_class: str  # the class the signature should name (parksteer.diagnose.signature.CLASSES)


FORMS: tuple[TruthForm, ...] = (
    TruthForm(FrictionBump(), "dissipative"), TruthForm(LockFriction(), "dissipative"),
    TruthForm(DeadZoneSpring(), "elastic"), TruthForm(CentreDetent(), "elastic"),
    TruthForm(OneWayDrag(), "direction"), TruthForm(MovingOffset(), "direction"),
    TruthForm(CubicDamping(), "speed"), TruthForm(QuadraticDrag(), "speed"),
    TruthForm(ColumnOnce(), "column"), TruthForm(ColumnSecond(), "column"),
)
# the products of two classes, after the single classes (their records follow the nulls in a grid, so that adding
# them left every other record of the grid as it was)
COMBINED_FORMS: tuple[TruthForm, ...] = (
    TruthForm(PinchedBearing(), "dissipative_column"), TruthForm(JointFriction(), "dissipative_column"),
)
ALL_FORMS = FORMS + COMBINED_FORMS


def form_by_name(name: str) -> TruthForm:
    for form in ALL_FORMS:
        if form.effect.name == name:
            return form
    raise KeyError(name)
