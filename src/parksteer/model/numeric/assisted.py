"""The prescribed-rack solve of an assisted car: the torsion-bar torque and the motor's output from a rack motion.

The plain prescribed-rack solve (:mod:`.prescribed`) cannot take an assist, whose force depends on its own unknown
column torque. Here the model is solved once with the boost switched off (the motor's inertia and friction kept),
which gives the road torque T_road (N m); the torsion-bar torque T_s (N m) is then the one root of
``T_s + A(T_s) = y``, y the road torque referred to the bar, A the boost law of
:mod:`parksteer.model.symbolic.effects.electric_assist` or ``hydraulic_assist`` with the same smoothed corners
(:mod:`parksteer.model.symbolic.effects.assist_common`) and the gear's efficiency in the direction the power flows,
found pointwise by regula falsi in compiled C (:mod:`.torsion_bar`); the motor torque (N m) and current (A), or the
pressure (Pa), follow from the law. A is increasing, so the root is unique, for a back-driven efficiency above
:func:`least_back_efficiency` (0.147 at eta_f 0.85); below it the law is refused. The derivation: docs/assist.md,
"Replaying an assisted car's rack".
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property, lru_cache

import numpy as np

from ... import portable as pm
from ...boost_table import MAX_POINTS, off_keys, table_keys
from ...errors import UsageError
from ...parameters import VEHICLE_SPEED
from ...reduction_efficiency import min_monotone_back_efficiency
from ..symbolic.components import power_assist_of
from ..symbolic.effects.assist_common import speed_gain
from .boost_numeric import clamp, deadband, directional_efficiency, points_at_speed, table_law_numeric
from .prescribed import PRESCRIBED_ATOL_FACTOR, PRESCRIBED_RTOL, PrescribedSolution, RackMotion, solve
from .torsion_bar import LAW_FIELDS, invert

# The inversion stops when the bracket is this narrow (N m of torsion-bar torque), far below a sensor's resolution.
INVERSION_TOLERANCE_NM = 1e-12
# ... or after this many steps (beyond 8192 N m two neighbouring doubles are further apart than that tolerance).
INVERSION_STEPS = 200
HYDRAULIC = "hydraulic_assist"


def boost_keys(name: str) -> list[str]:
    """The quantities that switch the boost off at 0: the gain (electric) or the valve's slope (hydraulic), and the
    boost table's assists and slopes."""
    return [f"{name}.valve_slope" if name == HYDRAULIC else f"{name}.gain", *(f"{name}.{key}" for key in off_keys())]


@dataclass(frozen=True)
class BoostLaw:
    """The boost law of one assist with its values: torsion-bar torque -> assist, in torsion-bar torque units.

    ``location`` is the point of action (column, pinion, rack; a hydraulic gear acts at the rack through a valve on
    the pinion). ``ratio`` is the handwheel-to-rack ratio G_hr (rad/m). Electric: gain, dead band, reduction N,
    efficiency eta, motor limit, torque constant; hydraulic: valve slope (in ``gain``), relief pressure (in
    ``limit``), piston area (in ``area``)."""

    name: str
    location: str
    gain: float
    dead_band: float
    band_width: float
    limit: float
    limit_width: float
    ratio: float
    reduction: float = 1.0
    efficiency: float = 1.0
    torque_constant: float = 1.0
    area: float = 0.0
    offset: float = 0.0  # the torsion-bar sensor's zero offset (N m), read by the law and the logger alike
    table: tuple = ()  # the boost table's scalars (boost_table.table_keys order); () or all zero: no table
    speed: float = 0.0  # the vehicle speed (m/s) the table is read at
    table_scale: float = 1.0  # the boost gain error's factor on the table (1 + e)
    back_efficiency: float = 1.0  # eta_b of the gear back-driven
    direction_width: float = 0.0  # motor torque (N m) over which the power's sign is smoothed (limit_smoothing)
    friction_speed: float = 1.0  # rad/s: the rotor speed w of tanh(omega / w) over which the direction changes

    @property
    def hydraulic(self) -> bool:
        return self.name == HYDRAULIC

    def motor(self, torsion_bar_Nm):
        """The motor torque (N m; hydraulic: the pressure, Pa) at the torsion-bar torque (module docstring)."""
        opening = deadband(np.asarray(torsion_bar_Nm, dtype=float), self.dead_band, self.band_width)
        scale = self.ratio if self.location == "rack" and not self.hydraulic else 1.0
        demand = self.gain * opening * scale
        if any(self.table):
            demand = demand + self.table_scale * table_law_numeric(np.asarray(torsion_bar_Nm, dtype=float),
                                                                    self._table_points)
        if self.hydraulic:
            return clamp(demand, self.limit, self.limit_width)
        return clamp(demand / (self.efficiency * self.reduction), self.limit, self.limit_width)

    @cached_property
    def _table_points(self):
        """The table's points at this law's speed as arrays, read once per table and speed (:func:`.boost_numeric.points_at_speed`):
        the inversion evaluates the law some 50 times a sample, and every replay of a diagnosis builds its own law."""
        points = points_at_speed(np.asarray(self.table, dtype=float).tobytes(), np.float64(self.speed).tobytes())
        return tuple(np.asarray(v, dtype=float) for v in points)

    def with_wider_dead_band(self, size_Nm: float) -> BoostLaw:
        """This law with its dead band wider by `size_Nm`: the line's band, and every point of a table but the
        origin moved out by it (the curve beyond the band unchanged in shape)."""
        table = list(self.table)
        if any(table):
            for k in range(1, MAX_POINTS):
                table[k] += size_Nm  # boost_torque_<k>: the first MAX_POINTS scalars (table_keys)
        return replace(self, dead_band=self.dead_band + size_Nm, table=tuple(table))

    def delivered(self, motor, rotor_speed):
        """What the gear delivers per motor torque, in the direction the power flows (eta_f driving, 1 / eta_b
        back-driven; :func:`~parksteer.model.symbolic.effects.assist_common.directional_efficiency`), the rotor
        turning at `rotor_speed` (rad/s)."""
        return directional_efficiency(motor, self._direction(rotor_speed), self.efficiency, self.back_efficiency,
                                      self.direction_width)

    def _direction(self, rotor_speed):
        """The gear's direction of power flow tanh(omega / w) at `rotor_speed` (rad/s), with the portable tanh
        (:mod:`parksteer.portable`: the compiled model's own, not the C library's)."""
        return pm.tanh((1.0 / self.friction_speed) * np.asarray(rotor_speed, dtype=float))

    def assist(self, torsion_bar_Nm, rotor_speed=0.0):
        """A(T_s): the assist in torsion-bar torque units (what it adds to the torsion bar's torque in y), with the
        rotor turning at `rotor_speed` (rad/s: the direction of the gear's power flow)."""
        motor = self.motor(torsion_bar_Nm)
        if self.hydraulic:
            return self.area * motor / self.ratio
        scale = self.ratio if self.location == "rack" else 1.0
        return self.delivered(motor, rotor_speed) * self.reduction * motor / scale

    def bound(self) -> float:
        """An upper bound of |A| (the clamp's magnitude is below limit + width; a back-driven gear delivers at most
        1 / eta_b of the motor torque)."""
        if self.hydraulic:
            return self.area * (self.limit + self.limit_width) / self.ratio
        scale = self.ratio if self.location == "rack" else 1.0
        return max(self.efficiency, 1.0 / self.back_efficiency) * self.reduction * (self.limit + self.limit_width) / scale

    def torsion_bar(self, y, factor=1.0, rotor_speed=0.0) -> np.ndarray:
        """The torsion-bar torque T_s with T_s + factor A(T_s) = y, elementwise. The left side rises with T_s (A is
        increasing, and factor >= 0: a motor whose delivered torque departs from the law by `factor`), so the root
        is bracketed and kept bracketed: regula falsi with the Illinois rule (the end that stays has its value
        halved), falling back to the bracket's midpoint where the secant leaves it, until the bracket is
        INVERSION_TOLERANCE_NM wide (at most INVERSION_STEPS steps). Only comparisons, the four operations and
        square roots: the same bits on any machine.

        Each sample is solved on its own in compiled C (:mod:`.torsion_bar`, ``torsion_bar.c``, which writes the
        law once); the gear's direction at each sample's rotor speed is read here, once a call (:meth:`_direction`)."""
        y = np.asarray(y, dtype=float)
        samples = np.ascontiguousarray(y.reshape(-1))
        gains = np.asarray(factor, dtype=float)
        # a factor of 1 everywhere multiplies by 1: the same bits without the product
        gains = (None if gains.ndim == 0 and float(gains) == 1.0
                 else np.ascontiguousarray(np.broadcast_to(gains, y.shape).reshape(-1)))
        direction = None
        if not self.hydraulic:
            if self.back_efficiency == 0.0:
                raise ZeroDivisionError("back_efficiency 0: a back-driven gear delivering 1 / 0 of the motor torque")
            speed = np.array(np.broadcast_to(np.asarray(rotor_speed, dtype=float), y.shape))
            direction = np.ascontiguousarray(self._direction(speed).reshape(-1))
        # A has the sign of its argument, so the root lies between 0 and y; where rounding says otherwise, a
        # bracket as wide as the assist can be
        try:
            width = self.bound() * float(np.max(factor)) + 1.0 if samples.size else 0.0
        except ZeroDivisionError:
            width = None  # a law whose bound is not a number: said below if a sample needs it
        points = self._inversion_points if any(self.table) else None
        root = invert(self._inversion_values, self.hydraulic, points, samples, gains, direction, width,
                      INVERSION_TOLERANCE_NM, INVERSION_STEPS)
        if root is None:
            self.bound()  # raises what it raised
        return root.reshape(y.shape)

    @cached_property
    def _inversion_values(self) -> np.ndarray:
        """The law's values as the compiled inversion reads them (:data:`.torsion_bar.LAW_FIELDS`): a rack motor's
        demand times G_hr (``line_scale``) and its assist over G_hr (``assist_scale``)."""
        rack = self.location == "rack"
        scales = {"line_scale": self.ratio if rack and not self.hydraulic else 1.0,
                  "assist_scale": self.ratio if rack else 1.0}
        return np.array([scales[key] if key in scales else getattr(self, key) for key in LAW_FIELDS], dtype=float)

    @cached_property
    def _inversion_points(self) -> np.ndarray:
        """The table's points at this law's speed (torques, assists, slopes) as one 3 x n array, read once per law.
        The torques past the first must rise (as the table's file has them), for a sample's segment to be one."""
        points = np.ascontiguousarray(np.array(self._table_points, dtype=float))
        if not np.all(points[0, 2:] >= points[0, 1:-1]):
            raise UsageError(f"{self.name}: the boost table's torques do not rise ({points[0].tolist()})")
        return points


@lru_cache(maxsize=64)
def least_back_efficiency(forward: float) -> float:
    """The least eta_b at which the gear's delivered torque rises with the motor torque at every rotor speed, at
    eta_f = `forward` (:func:`parksteer.reduction_efficiency.min_monotone_back_efficiency`: 0.147 at 0.85)."""
    return min_monotone_back_efficiency(forward)


def check_back_efficiency(name: str, forward: float, back: float, where: str = "") -> None:
    """Refuse a back-driven efficiency below :func:`least_back_efficiency` (one line): the delivered torque would
    fall as the motor torque rises somewhere, and T + A(T) = y would have more than one root."""
    least = least_back_efficiency(forward)
    if back < least:
        raise UsageError(f"{where}{name}.back_efficiency {back:g}: below {least:.3f}, the least at which the gear's "
                         f"delivered torque rises with the motor torque at every speed (efficiency {forward:g}); the "
                         "law would not be increasing and the replay could not invert it")


def _table_values(run, p: np.ndarray, name: str) -> tuple[float, ...]:
    """The boost table's scalars of the assist `name` in `p` (table_keys order), their positions found once per
    compiled model (:meth:`parksteer.model.numeric.compiled.CompiledModel.positions`): a replay's law reads all 552
    at every replay."""
    positions = run.model.positions(tuple(f"{name}.{k}" for k in table_keys()))
    return tuple(np.asarray(p, dtype=float)[positions].tolist())


def boost_law(run, p: np.ndarray) -> BoostLaw | None:
    """The boost law of `run`'s assist with the values of the parameter vector `p` (None without an assist)."""
    effect = power_assist_of(run.effects)
    if effect is None:
        return None
    name = effect.name
    v = lambda key: float(p[run.parameter_index(f"{name}.{key}")])  # noqa: E731
    ratio = float(p[run.parameter_index("steering.handwheel_to_rack_ratio")])
    if name == HYDRAULIC:
        law = BoostLaw(name, "rack", v("valve_slope"), v("dead_band"), v("dead_band_smoothing"),
                       v("relief_pressure"), v("pressure_smoothing"), ratio, area=v("piston_area"),
                       table=_table_values(run, p, name),
                       speed=float(p[run.parameter_index(VEHICLE_SPEED.key)]))
    else:
        gain = speed_gain(v("gain"), v("speed_dependence"), float(p[run.parameter_index(VEHICLE_SPEED.key)]),
                          v("gain_half_speed"))
        law = BoostLaw(name, effect.location, gain, v("dead_band"), v("dead_band_smoothing"),
                       v("motor_torque_limit"), v("limit_smoothing"), ratio, v("reduction_ratio"), v("efficiency"),
                       v("torque_constant"), table=_table_values(run, p, name),
                       speed=float(p[run.parameter_index(VEHICLE_SPEED.key)]),
                       back_efficiency=v("back_efficiency"), direction_width=v("limit_smoothing"),
                       friction_speed=v("friction_speed"))
        check_back_efficiency(name, law.efficiency, law.back_efficiency)
    # the law-side effects of the model (a diagnosis's candidates acting in the control unit: Effect.boost_law)
    value = lambda key: float(p[run.parameter_index(key)])  # noqa: E731
    for other in run.effects:
        law = other.boost_law(law, value)
    return law


def rack_speed_mps(rack: RackMotion, t) -> np.ndarray:
    """The speed of `rack` at the times `t` (m/s; 0 where it is held, before its first and after its last break).

    The cubic pieces' derivative evaluated as scipy's PPoly(...).derivative() evaluates it, operation for operation
    (the derivative's coefficients c_i times their powers, then summed from the constant term up), so with its bits
    and without importing scipy.interpolate (a second of every assisted diagnosis)."""
    breaks = np.asarray(rack.breaks, dtype=float)
    c = np.asarray(rack.coefficients, dtype=float)
    times = np.asarray(t, dtype=float)
    piece = np.clip(np.searchsorted(breaks, times, side="right") - 1, 0, len(breaks) - 2)
    s = times - breaks[piece]
    degree = len(c) - 1
    speed = np.zeros_like(s)
    power = np.ones_like(s)
    for i in range(degree):  # the term of s**i: the coefficient of s**(i + 1) times i + 1
        speed = speed + (c[degree - 1 - i, piece] * float(i + 1)) * power
        power = power * s
    inside = (np.asarray(t) >= breaks[0]) & (np.asarray(t) <= breaks[-1])
    return np.where(inside, speed, 0.0)


@dataclass
class AssistedSolution(PrescribedSolution):
    """The prescribed-rack solve of an assisted car. ``torque_Nm`` is the torsion-bar torque (what the car's torque
    sensor measures), ``road_torque_Nm`` the column torque the boost-free model needs (T_road), ``motor_torque_Nm``
    and ``motor_current_A`` the motor's (hydraulic: ``motor_torque_Nm`` holds the pressure in Pa, the current is
    None)."""

    road_torque_Nm: np.ndarray | None = None
    motor_torque_Nm: np.ndarray | None = None
    motor_current_A: np.ndarray | None = None


def solve_assisted(run, p: np.ndarray, rack: RackMotion, t_out, rtol: float = PRESCRIBED_RTOL,
                   atol_factor: float = PRESCRIBED_ATOL_FACTOR, law: BoostLaw | None = None,
                   delivered=None) -> AssistedSolution:
    """The torsion-bar torque and the motor's torque and current of `run`'s assisted car with its rack following
    `rack`, at the output times `t_out` (module docstring: the boost-free solve, then the law inverted). The
    law-side effects of the model act here, each through its ``Effect.boost_law`` (:func:`boost_law`): a sensor
    offset o (the reading S solves S + A(S) = y + o, the log and the law take S), a gain error (the law's gain
    G (1 + e)), a user's own (a derated motor limit). `law` replaces the run's own law (a record
    made with another curve than the file's); `delivered` (a factor per output time, >= 0) scales what the motor
    delivers against what the law commands (a torque ripple), the current unchanged."""
    law = law if law is not None else boost_law(run, p)
    if law is None:
        raise UsageError("an assisted replay needs an assist effect in the model (electric_assist_* or "
                         "hydraulic_assist)")
    p_off = np.array(p, dtype=float)
    for key in boost_keys(law.name):
        p_off[run.parameter_index(key)] = 0.0
    electric = not law.hydraulic
    # a column assist's law needs only the column angle per rack (the speed below), not the handwheel's twist
    road = solve(run, p_off, rack, t_out, rtol=rtol, atol_factor=atol_factor,
                 outputs=law.location != "column" or electric, assist_off=True, handwheel=law.location != "column")
    y = road.torque_Nm
    if law.location != "column":
        y = y * road.outputs["column_angle_per_rack_rad_per_m"] / law.ratio
    # the speed the gear's direction of power flow is read from: the rotor's, N times the point of action's rate (the
    # column's through the joint), as the effect reads it
    speed = rack_speed_mps(rack, road.time_s) * law.reduction if electric else 0.0
    if electric and law.location != "rack":
        speed = speed * (road.outputs["column_angle_per_rack_rad_per_m"] if law.location == "column" else law.ratio)
    # A sensor reading S = T_s + o, taken by the law: S - o + A(S) = y (effect torsion_bar_offset).
    factor = 1.0 if delivered is None else np.asarray(delivered, dtype=float)
    torsion_bar = law.torsion_bar(y + law.offset, factor, speed)
    motor = law.motor(torsion_bar)
    current = None if law.hydraulic else motor / law.torque_constant
    return AssistedSolution(road.time_s, torsion_bar, road.states, road.accelerations, None, None, road.torque_Nm,
                            motor, current)
