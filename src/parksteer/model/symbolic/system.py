"""The core multibody system of the front end (paper section 4), built symbolically.

Bodies (a parent/child tree, as in AutoSim; axes x forward, y right, z down):

- chassis B: bounce ``bounce_m`` (down) and roll ``roll_rad`` about a fore-aft axis on the
  centreline at height ``vehicle.roll_axis_z``; roll spring and damper to the ground;
- rack: translates along B.y (``rack_m``, positive to the right) and rolls with the chassis;
- per side, a steering assembly S turning about its king-pin axis by the steer angle
  delta(rack) (supplied by the linkage: linear unless an effect replaces it);
- per side, a tread ring R, child of S; rigid to S unless an effect adds a twist coordinate.

The handwheel angle is prescribed; the massless column is a torsion spring and damper from
the handwheel to the column angle theta_c, a function of the rack through the pinion
(theta_p = handwheel_to_rack_ratio * rack) and the column-to-pinion map (theta_c = theta_p
unless an effect such as the Hooke joint replaces it). The column torque acts on a massless
frame turned by theta_c, so its generalized force on the rack is T * d(theta_c)/d(rack).

Vertical loads on the steered parts (tyre contact forces and the weights of the steering
assemblies and rings) are applied by the core at points fixed in the chassis that coincide
with their true points at zero steer: so the core alone does no work against them when
steering. The ``lifting`` effect moves them to where the steer geometry puts them.

Inertia: the chassis roll inertia is about its own mass centre (AutoSim's convention); the
rack's given inertia is about its own axis (B.y); each steering assembly's diag(x, y, z) is
about axes parallel to the body axes at zero steer, turning with the wheel; each tread
ring has its yaw inertia about the steer axis only (the paper gives no other component, and
the others would only add a little to the roll inertia).

Geometry is numeric: every position, axis direction and inertia is a parameter symbol whose
value is computed at run time from data/parameters.toml (see :mod:`parksteer.model.numeric.values`),
so the expressions stay small and changing a value never re-derives.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import sympy as sp
import sympy.physics.mechanics as me

SIDES = ("left", "right")
DERIVED = "derived"

# Core parameters: (section, name) of data/parameters.toml that enter the equations.
CORE_PARAMETERS: tuple[tuple[str, str], ...] = (
    ("vehicle", "gravity"),
    ("vehicle", "chassis_roll_inertia"),
    ("vehicle", "chassis_roll_stiffness"),
    ("vehicle", "chassis_roll_damping"),
    ("steering", "rack_mass"),
    ("steering", "rack_roll_inertia"),
    ("steering", "handwheel_to_rack_ratio"),
    ("steering", "roadwheel_to_rack_ratio"),
    ("steering", "column_torsional_stiffness"),
    ("steering", "column_torsional_damping"),
    ("steering", "steering_assembly_mass"),
    ("tyre", "radial_stiffness"),
    ("tyre", "radial_damping"),
    ("tyre", "tread_ring_mass"),
    ("tyre", "tread_ring_yaw_inertia"),
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


@dataclass
class ModelSpace:
    """The symbolic system under construction, handed to each effect's hooks."""

    effect_names: tuple[str, ...]
    parameter_symbols: dict[str, sp.Symbol] = field(default_factory=dict)
    coordinates: list[Coordinate] = field(default_factory=list)
    steer_function: Callable[[ModelSpace, str], Any] | None = None
    column_map: Callable[[ModelSpace, Any], Any] | None = None
    column_deflection: Callable[[ModelSpace, Any], Any] | None = None
    contact_follows_steer: bool = False
    ring_twist: dict[str, Any] = field(default_factory=dict)
    speeds_as_qdot: bool = False  # write every speed as dq/dt (for an independent Lagrange derivation)
    built: bool = False

    def __post_init__(self):
        self.t = me.dynamicsymbols._t
        self.N = me.ReferenceFrame("N")
        self.origin = me.Point("O")
        self.origin.set_vel(self.N, 0)
        for section, name in CORE_PARAMETERS:
            self.symbol(f"{section}.{name}")
        for name in DERIVED_SCALARS:
            self.symbol(f"{DERIVED}.{name}")
        for side in SIDES:
            for name in DERIVED_PER_SIDE:
                self.symbol(f"{DERIVED}.{side}.{name}")
        self.handwheel_angle, self.handwheel_rate = sp.symbols("handwheel_angle handwheel_rate")
        self.rack_q, self.rack_u = self.add_coordinate("rack", "m", owner="core")
        self.bounce_q, self.bounce_u = self.add_coordinate("bounce", "m", owner="core")
        self.roll_q, self.roll_u = self.add_coordinate("roll", "rad", owner="core")

    # -- parameters and coordinates ------------------------------------------------------
    def symbol(self, key: str) -> sp.Symbol:
        """The symbol of parameter `key` ("section.name", "effect.name" or "derived..."), created once."""
        if key not in self.parameter_symbols:
            self.parameter_symbols[key] = sp.Symbol(key.replace(".", "__"), real=True)
        return self.parameter_symbols[key]

    def p(self, effect, name: str) -> sp.Symbol:
        """Symbol of parameter `name` of `effect` (an Effect or its name); checks it is declared."""
        from .components import Effect

        if isinstance(effect, Effect):
            effect.parameter(name)
            effect = effect.name
        return self.symbol(f"{effect}.{name}")

    def add_coordinate(self, name: str, unit: str, owner: str) -> tuple[Any, Any]:
        """A new generalized coordinate and its speed (Kane: u = dq/dt); only before the build."""
        if self.built:
            raise RuntimeError("coordinates must be added in Effect.configure")
        if any(c.name == name for c in self.coordinates):
            raise ValueError(f"coordinate {name!r} already exists")
        q, u = me.dynamicsymbols(f"q_{name} u_{name}")
        if self.speeds_as_qdot:
            u = q.diff(self.t)
        self.coordinates.append(Coordinate(name, unit, q, u, owner))
        return q, u

    def set_steer_function(self, function: Callable[[ModelSpace, str], Any]) -> None:
        """Replace the linkage: function(model, side) -> road-wheel steer angle as an expression in model.rack_q."""
        self.steer_function = function

    def set_column_map(self, function: Callable[[ModelSpace, Any], Any]) -> None:
        """Replace the column-to-pinion map: function(model, pinion_angle) -> column angle theta_c."""
        self.column_map = function

    def set_column_deflection(self, function: Callable[[ModelSpace, Any], Any]) -> None:
        """Make the column's spring and damper act on a deflection g(twist) instead of the twist itself.

        function(model, twist) -> g, an expression in the symbol `twist` (handwheel minus column
        angle). The column torque is then the generalized force of the spring energy k g^2 / 2 and
        the damper dissipation c (dg/dt)^2 / 2 on the twist: (k g + c g' dtwist/dt) g'. A dead
        band g (lash) makes the column carry no torque until the band is taken up.
        """
        self.column_deflection = function

    def set_ring_twist(self, side: str, angle) -> None:
        """Let the tread ring of `side` turn by `angle` about the steer axis relative to its wheel."""
        self.ring_twist[side] = angle

    @property
    def q(self) -> list:
        return [c.q for c in self.coordinates]

    @property
    def u(self) -> list:
        return [c.u for c in self.coordinates]

    def d(self, key: str) -> sp.Symbol:
        return self.symbol(f"{DERIVED}.{key}")

    def core(self, key: str) -> sp.Symbol:
        return self.symbol(key)

    # -- kinematics ------------------------------------------------------------------------
    def build(self) -> None:
        """Frames, points and bodies, after every effect has configured the space."""
        N, O = self.N, self.origin
        qd_to_u = {c.q.diff(self.t): c.u for c in self.coordinates}
        self.qd_to_u = qd_to_u

        B = me.ReferenceFrame("B")
        B.orient_axis(N, N.x, self.roll_q)
        B.set_ang_vel(N, self.roll_u * N.x)
        self.B = B
        roll_centre = O.locatenew("roll_centre", (self.d("roll_axis_z") + self.bounce_q) * N.z)
        roll_centre.set_vel(N, self.bounce_u * N.z)
        self.roll_centre = roll_centre

        def body_point(name: str, x, y, z_below_roll_axis) -> me.Point:
            point = roll_centre.locatenew(name, x * B.x + y * B.y + z_below_roll_axis * B.z)
            point.v2pt_theory(roll_centre, N, B)
            return point

        self.body_point = body_point
        chassis_cg = body_point("chassis_cg", 0, self.d("chassis_cg_y"), self.d("chassis_cg_z_below_roll_axis"))
        chassis = me.RigidBody(
            "chassis", chassis_cg, B, self.d("chassis_mass"),
            (self.core("vehicle.chassis_roll_inertia") * me.outer(B.x, B.x), chassis_cg),
        )
        rack_point = body_point("rack", 0, self.rack_q, self.d("rack_z_below_roll_axis"))
        rack_point.set_vel(N, (rack_point.pos_from(O).dt(N)).xreplace(qd_to_u))
        self.rack_point = rack_point
        # The point of the rack housing (chassis) under the rack's mass centre: internal forces between
        # rack and housing act on both, so they roll the body only through their moment, never net.
        self.rack_housing_point = body_point("rack_housing", 0, self.rack_q, self.d("rack_z_below_roll_axis"))
        rack = me.RigidBody(
            "rack", rack_point, B, self.core("steering.rack_mass"),
            (self.core("steering.rack_roll_inertia") * me.outer(B.y, B.y), rack_point),
        )
        self.bodies = [chassis, rack]
        self.weights: list[tuple[me.Point, Any, me.Point | None]] = [
            (chassis_cg, self.d("chassis_mass"), None),
            (rack_point, self.core("steering.rack_mass"), None),
        ]

        steer = self.steer_function or _linear_linkage
        pinion = self.core("steering.handwheel_to_rack_ratio") * self.rack_q
        self.pinion_angle = pinion
        self.column_angle = (self.column_map or (lambda model, p: p))(self, pinion)
        self.column_angle_per_rack = sp.diff(self.column_angle, self.rack_q)
        # the total rate, so that a map may also depend on a coordinate an effect adds (e.g. lash)
        self.column_rate = self.column_angle.diff(self.t).xreplace(qd_to_u)
        column_frame = me.ReferenceFrame("column")
        column_frame.orient_axis(B, B.y, self.column_angle)
        column_frame.set_ang_vel(B, self.column_rate * B.y)
        self.column_frame = column_frame
        k_col = self.core("steering.column_torsional_stiffness")
        c_col = self.core("steering.column_torsional_damping")
        if self.column_deflection is None:
            self.column_torque = k_col * (self.handwheel_angle - self.column_angle) + c_col * (
                self.handwheel_rate - self.column_rate
            )
            self.column_spring_deflection = self.handwheel_angle - self.column_angle
        else:
            twist = sp.Dummy("twist")
            law = sp.sympify(self.column_deflection(self, twist))
            at_twist = {twist: self.handwheel_angle - self.column_angle}
            deflection, slope = law.xreplace(at_twist), sp.diff(law, twist).xreplace(at_twist)
            self.column_torque = (k_col * deflection + c_col * slope * (self.handwheel_rate - self.column_rate)) * slope
            self.column_spring_deflection = deflection

        self.steer_angle, self.axis_frame, self.steer_frame, self.ring_frame = {}, {}, {}, {}
        self.axis_foot, self.wheel_centre, self.wheel_centre_unsteered = {}, {}, {}
        self.contact_point, self.contact_point_unsteered, self.wheel_load = {}, {}, {}
        self.tyre_deflection = {}
        self.assembly_cg, self.assembly_cg_unsteered = {}, {}
        for side in SIDES:
            self._build_side(side, steer(self, side))
        self.built = True

    def _build_side(self, side: str, delta) -> None:
        N, B, O = self.N, self.B, self.origin
        ds = lambda name: self.d(f"{side}.{name}")  # noqa: E731
        roll_axis_z = self.d("roll_axis_z")
        K = me.ReferenceFrame(f"K_{side}")
        K.orient_explicit(B, sp.Matrix(3, 3, lambda i, j: ds(f"axis_frame_{i}{j}")))
        K.set_ang_vel(B, 0)
        S = me.ReferenceFrame(f"S_{side}")
        S.orient_axis(K, K.z, delta)
        delta_rate = sp.diff(delta, self.rack_q) * self.rack_u
        S.set_ang_vel(K, delta_rate * K.z)
        twist = self.ring_twist.get(side)
        if twist is None:
            R = S
        else:
            R = me.ReferenceFrame(f"R_{side}")
            R.orient_axis(S, S.z, twist)
            R.set_ang_vel(S, twist.diff(self.t).xreplace(self.qd_to_u) * S.z)
        foot = self.body_point(f"A_{side}", ds("foot_x"), ds("foot_y"), ds("foot_z") - roll_axis_z)

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
            f"steering_assembly_{side}", cg, S, self.core("steering.steering_assembly_mass"),
            (me.inertia(S, inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[1, 2], inertia[2, 0]), cg),
        )
        ring = me.RigidBody(
            f"tread_ring_{side}", centre, R, self.core("tyre.tread_ring_mass"),
            (self.core("tyre.tread_ring_yaw_inertia") * me.outer(R.z, R.z), centre),
        )
        self.bodies += [assembly, ring]
        self.weights += [
            (cg, self.core("steering.steering_assembly_mass"), cg0),
            (centre, self.core("tyre.tread_ring_mass"), centre0),
        ]

        where = contact if self.contact_follows_steer else contact0
        deflection = where.pos_from(O).dot(N.z) - self.d("ground_z") + ds("static_tyre_deflection")
        deflection_rate = where.vel(N).dot(N.z)
        self.tyre_deflection[side] = deflection
        load = self.core("tyre.radial_stiffness") * deflection + self.core("tyre.radial_damping") * deflection_rate
        self.steer_angle[side] = delta
        self.axis_frame[side], self.steer_frame[side], self.ring_frame[side] = K, S, R
        self.axis_foot[side] = foot
        self.wheel_centre[side], self.wheel_centre_unsteered[side] = centre, centre0
        self.contact_point[side], self.contact_point_unsteered[side] = contact, contact0
        self.assembly_cg[side], self.assembly_cg_unsteered[side] = cg, cg0
        self.wheel_load[side] = load

    # -- core loads and energy ------------------------------------------------------------
    def core_loads(self) -> list[tuple[Any, Any]]:
        """Gravity, tyre vertical springs and dampers, chassis roll spring and damper."""
        N, B = self.N, self.B
        g = self.core("vehicle.gravity")
        loads = []
        for point, mass, unsteered in self.weights:
            loads.append((unsteered or point, mass * g * N.z))
        for side in SIDES:
            loads.append((self.contact_point_unsteered[side], -self.wheel_load[side] * N.z))
        k, c = self.core("vehicle.chassis_roll_stiffness"), self.core("vehicle.chassis_roll_damping")
        loads.append((B, -(k * (self.roll_q - self.d("roll_spring_neutral")) + c * self.roll_u) * N.x))
        return loads

    def column_loads(self) -> list[tuple[Any, Any]]:
        """The column torque on the pinion (through the massless frame turned by theta_c); the driver who
        applies it sits in the body, which takes the reaction."""
        return [(self.column_frame, self.column_torque * self.B.y), (self.B, -self.column_torque * self.B.y)]

    def core_potential_energy(self):
        """Gravity (at the points where the core applies the weights), tyre and roll springs."""
        g = self.core("vehicle.gravity")
        energy = sum(mass * g * (unsteered or point).pos_from(self.origin).dot(self.N.z) * -1
                     for point, mass, unsteered in self.weights)
        for side in SIDES:
            energy += self.core("tyre.radial_stiffness") * self.tyre_deflection[side] ** 2 / 2
        energy += self.core("vehicle.chassis_roll_stiffness") * (self.roll_q - self.d("roll_spring_neutral")) ** 2 / 2
        return energy

    def column_potential_energy(self):
        return self.core("steering.column_torsional_stiffness") * self.column_spring_deflection ** 2 / 2

    def kinetic_energy(self):
        return sum(b.kinetic_energy(self.N) for b in self.bodies).xreplace(self.qd_to_u)


def _linear_linkage(model: ModelSpace, side: str):
    """The paper's linkage: both road wheels steer by roadwheel_to_rack_ratio * rack (positive: to the right)."""
    return model.core("steering.roadwheel_to_rack_ratio") * model.rack_q
