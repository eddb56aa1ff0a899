"""The core multibody system of the front end (paper section 4), built symbolically.

Effects fill slots of this system (``Effect.replaces``, :data:`SLOTS`): the linkage's steer function,
the column-to-pinion map, the column spring's deflection law, the tread ring's twist, the points where
vertical loads act. They read the built kinematics through :class:`Kinematics` (``model.kinematics``),
the declared fields effects may use, and keep per-build state in ``model.state(effect)``.

Every position, axis direction and inertia is a parameter symbol valued at run time. The derivation, its reasoning
and its sources: docs/model.md, "The core multibody system (`model.symbolic.system`)".
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

from .lazy_sympy import me, sp

from ...names import SIDES

DERIVED = "derived"

# The slots of the core an effect may fill (``Effect.replaces``), each with the method the effect defines to
# fill it. At most one effect fills a slot (refused when the effect set is resolved); an empty slot keeps the
# paper's law.
SLOTS: dict[str, str] = {
    "steer_function": "steer_angle",  # (model, side) -> road-wheel steer angle, an expression in model.rack_q
    "column_map": "column_angle",  # (model, pinion angle) -> column angle theta_c
    "column_deflection": "deflection",  # (model, twist) -> the deflection g(twist) the column spring acts on
    "ring_twist": "ring_twist",  # (model, side) -> angle of the tread ring about the steer axis from its wheel
    "load_points": "",  # filled: vertical loads act where the steer geometry puts them (the effect moves them)
}

# Quantities of the parameter file that enter the core's equations.
CORE_PARAMETERS: tuple[str, ...] = (
    "vehicle.gravity",
    "vehicle.chassis_roll_inertia",
    "vehicle.chassis_roll_stiffness",
    "vehicle.chassis_roll_damping",
    "steering.rack_mass",
    "steering.rack_roll_inertia",
    "steering.handwheel_to_rack_ratio",
    "steering.roadwheel_to_rack_ratio",
    "steering.column_torsional_stiffness",
    "steering.column_torsional_damping",
    "steering.steering_assembly_mass",
    "tyre.radial_stiffness",
    "tyre.radial_damping",
    "tyre.tread_ring_mass",
    "tyre.tread_ring_yaw_inertia",
)

# Values computed at run time from the case and the geometry (see values.derived_values).
DERIVED_SCALARS = (
    "chassis_mass",
    "chassis_cg_y",
    "chassis_cg_z_below_roll_axis",
    "rack_z_below_roll_axis",
    "roll_axis_z",
    "ground_z",
    "wheel_radius",
    "roll_spring_neutral",
    "surface_grip",
)
DERIVED_PER_SIDE = (
    ["foot_" + c for c in "xyz"]  # A, body axes
    + [f"axis_frame_{i}{j}" for i in range(3) for j in range(3)]  # columns X2 Y2 Z2 in body axes
    + ["centre_in_axis_" + c for c in "xyz"]  # AC in the steered axis frame
    + ["assembly_cg_in_axis_" + c for c in "xyz"]  # A to the assembly mass centre, steered axis frame
    + ["assembly_inertia_" + c for c in ("xx", "yy", "zz", "xy", "yz", "zx")]  # steered axis frame
    + ["static_tyre_deflection"]
)

INPUT_NAMES = ("handwheel_angle", "handwheel_rate")


@dataclass
class Coordinate:
    name: str
    unit: str
    q: Any
    u: Any
    owner: str


Weight = "tuple[me.Point, Any, me.Point | None]"  # (true point, mass, chassis-fixed twin at zero steer or None)


@dataclass
class Kinematics:
    """The built system: the fields an effect's ``bodies``, ``loads`` and ``potential_energy`` may use.

    Per-side fields are dicts keyed by ``"left"``/``"right"``. Frames: ``B`` the chassis, ``column_frame``
    turned by the column angle about B.y, per side ``axis_frame`` (fixed in B, z along the king-pin axis),
    ``steer_frame`` (the steering assembly, turned about it by the steer angle) and ``ring_frame`` (the tread
    ring; the steer frame unless the ring_twist slot is filled). Points: ``rack_point`` (rack mass centre)
    and ``rack_housing_point`` (the body point under it), per side ``axis_foot`` (A), ``wheel_centre`` (C),
    ``contact_point`` (P) and ``assembly_cg`` (G), each with its chassis-fixed ``*_unsteered`` twin.
    """

    B: me.ReferenceFrame
    roll_centre: me.Point
    rack_point: me.Point
    rack_housing_point: me.Point
    pinion_angle: Any
    column_angle: Any
    column_angle_per_rack: Any
    column_rate: Any
    column_frame: me.ReferenceFrame
    column_torque: Any
    column_spring_deflection: Any
    weights: list[Weight]
    qd_to_u: dict
    steer_angle: dict[str, Any] = field(default_factory=dict)
    ring_twist: dict[str, Any] = field(default_factory=dict)
    axis_frame: dict[str, me.ReferenceFrame] = field(default_factory=dict)
    steer_frame: dict[str, me.ReferenceFrame] = field(default_factory=dict)
    ring_frame: dict[str, me.ReferenceFrame] = field(default_factory=dict)
    axis_foot: dict[str, me.Point] = field(default_factory=dict)
    wheel_centre: dict[str, me.Point] = field(default_factory=dict)
    wheel_centre_unsteered: dict[str, me.Point] = field(default_factory=dict)
    contact_point: dict[str, me.Point] = field(default_factory=dict)
    contact_point_unsteered: dict[str, me.Point] = field(default_factory=dict)
    assembly_cg: dict[str, me.Point] = field(default_factory=dict)
    assembly_cg_unsteered: dict[str, me.Point] = field(default_factory=dict)
    wheel_load: dict[str, Any] = field(default_factory=dict)
    tyre_deflection: dict[str, Any] = field(default_factory=dict)


def action_reaction(point: me.Point, force, reaction_point: me.Point) -> list[me.Force]:
    """A force on `point` and its reaction on `reaction_point` (sympy's apply_force(..., reaction_point))."""
    return [me.Force(point, force), me.Force(reaction_point, -force)]


def torque_between(torque, axis, target_frame: me.ReferenceFrame, reaction_frame: me.ReferenceFrame
                   ) -> list[me.Torque]:
    """`torque` about `axis` on `target_frame`, reacted on `reaction_frame` (a sympy TorqueActuator)."""
    return me.TorqueActuator(torque, axis, target_frame, reaction_frame).to_loads()


class ModelSpace:
    """The symbolic system under construction, handed to each effect's hooks.

    Before the build (``Effect.configure``): the rack coordinate ``rack_q``/``rack_u``, the time ``t``, the
    ground frame ``N`` and ``origin``, ``add_coordinate``, and the parameter symbols ``p(key)`` (a key the
    model's effects use) and ``d(name)`` (a value derived from the case and geometry). After it:
    ``kinematics`` (:class:`Kinematics`).
    """

    def __init__(self, effects=(), speeds_as_qdot: bool = False):
        self.effects = tuple(effects)
        self.speeds_as_qdot = speeds_as_qdot  # write every speed as dq/dt (for an independent Lagrange derivation)
        self.parameter_symbols: dict[str, sp.Symbol] = {}
        self.coordinates: list[Coordinate] = []
        self.bodies: list[Any] = []
        self._states: dict[str, SimpleNamespace] = {}
        self._kinematics: Kinematics | None = None
        self.slots: dict[str, Any] = {}
        for effect in self.effects:
            if effect.replaces is not None:
                if effect.replaces in self.slots:  # resolve_effects refuses this first, with the user's spec
                    raise ValueError(f"{self.slots[effect.replaces].name} and {effect.name} both fill "
                                     f"{effect.replaces}")
                self.slots[effect.replaces] = effect
        self.t = me.dynamicsymbols._t
        self.N = me.ReferenceFrame("N")
        self.origin = me.Point("O")
        self.origin.set_vel(self.N, 0)
        for key in CORE_PARAMETERS:
            self._symbol(key)
        for name in DERIVED_SCALARS:
            self._symbol(f"{DERIVED}.{name}")
        for side in SIDES:
            for name in DERIVED_PER_SIDE:
                self._symbol(f"{DERIVED}.{side}.{name}")
        for effect in self.effects:
            for key in effect.uses:
                self._symbol(key)
        self.handwheel_angle, self.handwheel_rate = sp.symbols("handwheel_angle handwheel_rate", real=True)
        self.rack_q, self.rack_u = self.add_coordinate("rack", "m", owner="core")
        self.bounce_q, self.bounce_u = self.add_coordinate("bounce", "m", owner="core")
        self.roll_q, self.roll_u = self.add_coordinate("roll", "rad", owner="core")

    @property
    def effect_names(self) -> tuple[str, ...]:
        return tuple(e.name for e in self.effects)

    @property
    def built(self) -> bool:
        return self._kinematics is not None

    @property
    def kinematics(self) -> Kinematics:
        if self._kinematics is None:
            raise RuntimeError("the kinematics exist after the build (use them in bodies, loads, potential_energy)")
        return self._kinematics

    def state(self, effect) -> SimpleNamespace:
        """The per-build state of `effect` (coordinates it added, frames it made): one namespace per effect."""
        return self._states.setdefault(effect.name, SimpleNamespace())

    # -- parameters and coordinates ------------------------------------------------------
    def _symbol(self, key: str) -> sp.Symbol:
        if key not in self.parameter_symbols:
            self.parameter_symbols[key] = sp.Symbol(key.replace(".", "__"), real=True)
        return self.parameter_symbols[key]

    def p(self, key: str) -> sp.Symbol:
        """The symbol of quantity `key`: a core quantity or one an effect of this model uses."""
        try:
            return self.parameter_symbols[key]
        except KeyError:
            raise KeyError(f"{key}: not a quantity of this model (list it in the effect's uses)") from None

    def d(self, key: str) -> sp.Symbol:
        """The symbol of a value derived from the case and the geometry (``derived.<key>``)."""
        return self.parameter_symbols[f"{DERIVED}.{key}"]

    def add_coordinate(self, name: str, unit: str, owner: str) -> tuple[Any, Any]:
        """A new generalized coordinate and its speed (Kane: u = dq/dt); only before the build."""
        if self.built:
            raise RuntimeError("coordinates must be added in Effect.configure")
        if any(c.name == name for c in self.coordinates):
            raise ValueError(f"coordinate {name!r} already exists")
        q, u = me.dynamicsymbols(f"q_{name} u_{name}", real=True)  # real: sympy answers is_real at once
        if self.speeds_as_qdot:
            u = q.diff(self.t)
        self.coordinates.append(Coordinate(name, unit, q, u, owner))
        return q, u

    def _slot(self, slot: str):
        """The method of the effect filling `slot`, or None for the paper's law."""
        effect = self.slots.get(slot)
        return None if effect is None else getattr(effect, SLOTS[slot])

    @property
    def lifts(self) -> bool:
        """Whether the vertical loads act where the steer geometry puts them (the load_points slot is filled)."""
        return "load_points" in self.slots

    @property
    def q(self) -> list:
        return [c.q for c in self.coordinates]

    @property
    def u(self) -> list:
        return [c.u for c in self.coordinates]

    # -- kinematics ------------------------------------------------------------------------
    def build(self) -> None:
        """Frames, points and bodies, after every effect has configured the space."""
        N, O = self.N, self.origin
        qd_to_u = {c.q.diff(self.t): c.u for c in self.coordinates}

        B = me.ReferenceFrame("B")
        B.orient_axis(N, N.x, self.roll_q)
        B.set_ang_vel(N, self.roll_u * N.x)
        roll_centre = O.locatenew("roll_centre", (self.d("roll_axis_z") + self.bounce_q) * N.z)
        roll_centre.set_vel(N, self.bounce_u * N.z)

        def body_point(name: str, x, y, z_below_roll_axis) -> me.Point:
            point = roll_centre.locatenew(name, x * B.x + y * B.y + z_below_roll_axis * B.z)
            point.v2pt_theory(roll_centre, N, B)
            return point

        self._body_point = body_point
        chassis_cg = body_point("chassis_cg", 0, self.d("chassis_cg_y"), self.d("chassis_cg_z_below_roll_axis"))
        chassis = me.RigidBody(
            "chassis", chassis_cg, B, self.d("chassis_mass"),
            (self.p("vehicle.chassis_roll_inertia") * me.outer(B.x, B.x), chassis_cg),
        )
        rack_point = body_point("rack", 0, self.rack_q, self.d("rack_z_below_roll_axis"))
        rack_point.set_vel(N, (rack_point.pos_from(O).dt(N)).xreplace(qd_to_u))
        # The point of the rack housing (chassis) under the rack's mass centre: internal forces between
        # rack and housing act on both, so they roll the body only through their moment, never net.
        rack_housing_point = body_point("rack_housing", 0, self.rack_q, self.d("rack_z_below_roll_axis"))
        rack = me.RigidBody(
            "rack", rack_point, B, self.p("steering.rack_mass"),
            (self.p("steering.rack_roll_inertia") * me.outer(B.y, B.y), rack_point),
        )
        self.bodies = [chassis, rack]
        weights: list[Weight] = [
            (chassis_cg, self.d("chassis_mass"), None),
            (rack_point, self.p("steering.rack_mass"), None),
        ]

        steer = self._slot("steer_function") or _linear_linkage
        pinion = self.p("steering.handwheel_to_rack_ratio") * self.rack_q
        column_angle = (self._slot("column_map") or (lambda model, p: p))(self, pinion)
        column_angle_per_rack = sp.diff(column_angle, self.rack_q)
        # the total rate, so that a map may also depend on a coordinate an effect adds (e.g. lash)
        column_rate = column_angle.diff(self.t).xreplace(qd_to_u)
        column_frame = me.ReferenceFrame("column")
        column_frame.orient_axis(B, B.y, column_angle)
        column_frame.set_ang_vel(B, column_rate * B.y)
        k_col = self.p("steering.column_torsional_stiffness")
        c_col = self.p("steering.column_torsional_damping")
        column_deflection = self._slot("column_deflection")
        if column_deflection is None:
            column_torque = k_col * (self.handwheel_angle - column_angle) + c_col * (
                self.handwheel_rate - column_rate
            )
            spring_deflection = self.handwheel_angle - column_angle
        else:
            # The column's spring and damper act on a deflection g(twist) of the twist (handwheel minus column
            # angle): the column torque is the generalized force of the spring energy k g^2 / 2 and the damper
            # dissipation c (dg/dt)^2 / 2 on the twist, (k g + c g' dtwist/dt) g'.
            twist = sp.Dummy("twist")
            law = sp.sympify(column_deflection(self, twist))
            at_twist = {twist: self.handwheel_angle - column_angle}
            deflection, slope = law.xreplace(at_twist), sp.diff(law, twist).xreplace(at_twist)
            column_torque = (k_col * deflection + c_col * slope * (self.handwheel_rate - column_rate)) * slope
            spring_deflection = deflection

        self._kinematics = Kinematics(
            B=B, roll_centre=roll_centre, rack_point=rack_point, rack_housing_point=rack_housing_point,
            pinion_angle=pinion, column_angle=column_angle, column_angle_per_rack=column_angle_per_rack,
            column_rate=column_rate, column_frame=column_frame, column_torque=column_torque,
            column_spring_deflection=spring_deflection, weights=weights, qd_to_u=qd_to_u,
        )
        ring_twist = self._slot("ring_twist")
        for side in SIDES:
            twist = None if ring_twist is None else ring_twist(self, side)
            self._build_side(side, steer(self, side), twist)

    def _build_side(self, side: str, delta, twist) -> None:
        N, O = self.N, self.origin
        k = self._kinematics
        B, body_point = k.B, self._body_point
        ds = lambda name: self.d(f"{side}.{name}")  # noqa: E731
        roll_axis_z = self.d("roll_axis_z")
        K = me.ReferenceFrame(f"K_{side}")
        K.orient_explicit(B, sp.Matrix(3, 3, lambda i, j: ds(f"axis_frame_{i}{j}")))
        K.set_ang_vel(B, 0)
        S = me.ReferenceFrame(f"S_{side}")
        S.orient_axis(K, K.z, delta)
        delta_rate = sp.diff(delta, self.rack_q) * self.rack_u
        S.set_ang_vel(K, delta_rate * K.z)
        if twist is None:
            R = S
        else:
            R = me.ReferenceFrame(f"R_{side}")
            R.orient_axis(S, S.z, twist)
            R.set_ang_vel(S, twist.diff(self.t).xreplace(k.qd_to_u) * S.z)
            k.ring_twist[side] = twist
        foot = body_point(f"A_{side}", ds("foot_x"), ds("foot_y"), ds("foot_z") - roll_axis_z)

        def steered(name: str, prefix: str) -> tuple[me.Point, me.Point]:
            """A point fixed in S given in axis-frame components, and its chassis-fixed twin at zero steer."""
            comps = [ds(f"{prefix}_{c}") for c in "xyz"]
            point = foot.locatenew(name, comps[0] * S.x + comps[1] * S.y + comps[2] * S.z)
            point.v2pt_theory(foot, N, S)
            twin = foot.locatenew(name + "_unsteered", comps[0] * K.x + comps[1] * K.y + comps[2] * K.z)
            twin.v2pt_theory(foot, N, K)
            return point, twin

        centre, centre0 = steered(f"C_{side}", "centre_in_axis")
        cg, cg0 = steered(f"G_{side}", "assembly_cg_in_axis")
        radius = self.d("wheel_radius")
        contact = centre.locatenew(f"P_{side}", radius * N.z)
        contact.set_vel(N, centre.vel(N))
        contact0 = centre0.locatenew(f"P_{side}_unsteered", radius * N.z)
        contact0.set_vel(N, centre0.vel(N))

        inertia = sp.zeros(3, 3)
        for (i, j), key in zip(((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)), ("xx", "yy", "zz", "xy", "yz", "zx")):
            inertia[i, j] = inertia[j, i] = ds(f"assembly_inertia_{key}")
        assembly = me.RigidBody(
            f"steering_assembly_{side}", cg, S, self.p("steering.steering_assembly_mass"),
            (me.inertia(S, inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[1, 2], inertia[2, 0]), cg),
        )
        ring = me.RigidBody(
            f"tread_ring_{side}", centre, R, self.p("tyre.tread_ring_mass"),
            (self.p("tyre.tread_ring_yaw_inertia") * me.outer(R.z, R.z), centre),
        )
        self.bodies += [assembly, ring]
        k.weights += [
            (cg, self.p("steering.steering_assembly_mass"), cg0),
            (centre, self.p("tyre.tread_ring_mass"), centre0),
        ]

        where = contact if self.lifts else contact0  # the tyre deflection follows the steered contact height
        deflection = where.pos_from(O).dot(N.z) - self.d("ground_z") + ds("static_tyre_deflection")
        deflection_rate = where.vel(N).dot(N.z)
        k.tyre_deflection[side] = deflection
        load = self.p("tyre.radial_stiffness") * deflection + self.p("tyre.radial_damping") * deflection_rate
        k.steer_angle[side] = delta
        k.axis_frame[side], k.steer_frame[side], k.ring_frame[side] = K, S, R
        k.axis_foot[side] = foot
        k.wheel_centre[side], k.wheel_centre_unsteered[side] = centre, centre0
        k.contact_point[side], k.contact_point_unsteered[side] = contact, contact0
        k.assembly_cg[side], k.assembly_cg_unsteered[side] = cg, cg0
        k.wheel_load[side] = load

    # -- core loads and energy ------------------------------------------------------------
    def core_loads(self) -> list[Any]:
        """Gravity, tyre vertical springs and dampers, chassis roll spring and damper."""
        N, k = self.N, self.kinematics
        g = self.p("vehicle.gravity")
        loads = []
        for point, mass, unsteered in k.weights:
            loads.append(me.Force(unsteered or point, mass * g * N.z))
        for side in SIDES:
            loads.append(me.Force(k.contact_point_unsteered[side], -k.wheel_load[side] * N.z))
        stiffness, damping = self.p("vehicle.chassis_roll_stiffness"), self.p("vehicle.chassis_roll_damping")
        roll_torque = -(stiffness * (self.roll_q - self.d("roll_spring_neutral")) + damping * self.roll_u)
        loads.append(me.Torque(k.B, roll_torque * N.x))
        return loads

    def column_loads(self) -> list[Any]:
        """The column torque on the pinion (through the massless frame turned by theta_c); the driver who
        applies it sits in the body, which takes the reaction."""
        k = self.kinematics
        return torque_between(k.column_torque, k.B.y, k.column_frame, k.B)

    def core_potential_energy(self):
        """Gravity (at the points where the core applies the weights), tyre and roll springs."""
        k = self.kinematics
        g = self.p("vehicle.gravity")
        energy = sum(mass * g * (unsteered or point).pos_from(self.origin).dot(self.N.z) * -1
                     for point, mass, unsteered in k.weights)
        for side in SIDES:
            energy += self.p("tyre.radial_stiffness") * k.tyre_deflection[side] ** 2 / 2
        energy += self.p("vehicle.chassis_roll_stiffness") * (self.roll_q - self.d("roll_spring_neutral")) ** 2 / 2
        return energy

    def column_potential_energy(self):
        return self.p("steering.column_torsional_stiffness") * self.kinematics.column_spring_deflection ** 2 / 2

    def kinetic_energy(self):
        return sum(b.kinetic_energy(self.N) for b in self.bodies).xreplace(self.kinematics.qd_to_u)


def _linear_linkage(model: ModelSpace, side: str):
    """The paper's linkage: both road wheels steer by roadwheel_to_rack_ratio * rack (positive: to the right)."""
    return model.p("steering.roadwheel_to_rack_ratio") * model.rack_q
