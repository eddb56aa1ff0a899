"""An assisted car's records from a truth of their own: a column EPS written apart from the model's assist.

The model's assisted replay (:mod:`parksteer.model.numeric.assisted`) inverts the boost law of the effect it
diagnoses with. Records made by it share that law, its corners and its gear with the diagnosis. Here nothing of
the model's assist is called: the road part is the manual replay (the prescribed-rack solve of the car without
an assist, :func:`parksteer.model.numeric.simulate.simulate`), and over it sits a quasi-static column-EPS layer
written for this module alone:

- the column: the pinion follows the rack (theta_p = G_hr x), the column angle is the Hooke joint's inverse of
  it (:func:`column_of_pinion`), its rate and acceleration by differences on the fine grid;
- the torsion bar carries T_s; its sensor reads S = T_s + o (o: a zero offset) on the logger's converter (the bus
  carries the sensor's own value: the control unit reads the same steps);
- the control unit: the assist the map asks for at the column, A_map(S) (:class:`TruthMap`: a progressive power
  law c (|S| - d)^p beyond a dead band d, or an exponential family c (exp((|S| - d)/w) - 1), odd in S; neither is
  the model's monotone cubic table), times 1 + e (a gain error), turned into the motor's current through the
  data sheet's numbers, I = A_map / (eta_f N k_t), clipped at the current limit;
- the motor and the worm: the motor's electromagnetic torque k_t I less its loads (the rotor's inertia J_m N
  theta_c'', a Coulomb friction saturated linearly below ``friction_speed_rad_s`` of the rotor) is the torque o the
  worm transmits; the column receives eta_f N o when the motor drives it (o and the column's rate of one sign)
  and N o / eta_b when the column drives the motor (back-driven), the factor passing linearly through 1 as the
  rotor slows to rest (a worm at rest loses no power);
- the balance T_s + D(o(T_s)) = T_road, with T_road the manual replay's column torque. The left side rises with
  T_s (a staircase, the sensor's steps, plus T_s itself): the torsion-bar torque is where it first reaches
  T_road; where T_road falls inside a step's jump, T_s sits at the step's edge and the control unit dithers
  between the two levels, the delivered torque their mean (T_road - T_s) and the current the mean that delivers
  it. The control unit filters its reading's noise (out of the mechanics' band): the logged channel carries the
  noise, the loop does not.

Hidden, in the truth's own terms (:data:`HIDDEN_TRUTH`): the motor's friction above the car's, the sensor's
offset, the map's gain error, a rack friction above the file's (the manual replay's own parameter, affine in the
torque: one extra replay gives its direction). Out of class (:data:`OUT_OF_CLASS_TRUTH`): cogging of the motor
(n periods a revolution), a hysteresis of the control unit's map (a play of half-width h on its reading), backlash
of the worm (after every reversal of the worm's torque the motor crosses the lash unloaded: no assist for
sqrt(2 J_m b / |o|)), a friction of the gear growing with the motor's torque (mu |k_t I| beside the Coulomb part).

The handwheel angle (the angle-only tier: a bus log has no rack) is the column's plus the twist that passes T_s
through the torsion bar in series with the column shaft, with the column's own damping time constant (the file's
column law; :func:`parksteer.geometry.column_twist`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .. import portable as pm
from ..geometry import column_twist
from ..measure.converter import add_noise, quantisation_step, quantise
from ..measure.io import Measurement, metadata_text
from ..parameters import Parameters
from .logger import resample
from .variations import CLEAN_DT_S, HandVariant, variation_rack
from ..names import TORQUE

RACK_FRICTION = "steering.rack_friction_force"
# The rack friction's direction in the column torque is found from a replay with this much more (N).
RACK_FRICTION_PROBE_N = 100.0
BISECTION_STEPS = 60


@dataclass(frozen=True)
class TruthMap:
    """The control unit's boost map: assist at the column (N m) against the sensor's reading S (N m), odd in S.

    ``power``: c (|S| - d)^p beyond the dead band d (p > 1: progressive, its corner at d as smooth as p makes it);
    ``exp``: c (exp((|S| - d) / w) - 1) beyond d (a corner of slope c / w at d)."""

    form: str = "power"
    dead_band_Nm: float = 0.4
    scale: float = 3.9
    exponent: float = 1.6
    width_Nm: float = 1.2

    def __post_init__(self):
        if self.form not in ("power", "exp"):
            raise ValueError(f"boost map form must be 'power' or 'exp', not {self.form!r}")

    def __call__(self, reading) -> np.ndarray:
        s = np.asarray(reading, dtype=float)
        beyond = np.maximum(np.abs(s) - self.dead_band_Nm, 0.0)
        if self.form == "power":
            magnitude = self.scale * pm.power(beyond, np.full_like(beyond, self.exponent))
        else:
            magnitude = self.scale * pm.expm1(beyond / self.width_Nm)
        return np.sign(s) * magnitude


@dataclass(frozen=True)
class TruthGear:
    """The worm gear, the motor and the torsion bar of the truth's column EPS (what its data sheet would give,
    and the motor's friction, which no data sheet gives)."""

    reduction: float = 18.0
    efficiency: float = 0.85  # eta_f, the motor driving the column
    back_efficiency: float = 0.8  # eta_b, the column driving the motor
    torque_constant_Nm_per_A: float = 0.05
    current_limit_A: float = 80.0
    motor_inertia_kg_m2: float = 2.0e-4
    motor_friction_Nm: float = 0.012
    # the rotor speed (rad/s; 1 rad/s: 0.4 mm/s of the rack at a ratio of 125 rad/m and N = 18) below which the
    # Coulomb friction is saturated linearly, and over which the worm passes from driving to back-driven
    friction_speed_rad_s: float = 1.0
    direction_speed_rad_s: float = 1.0
    torsion_bar_stiffness: float = 115.0


@dataclass(frozen=True)
class Hidden:
    """What the car has beyond its owner's file: motor friction (N m, added), sensor offset (N m), map gain error
    (relative), rack friction (N, added to the replay's); out of class: cogging (N m at the rotor, ``cogging_periods``
    a revolution), map hysteresis (N m, the play's half-width), worm backlash (rad at the rotor), a friction
    growing with the motor torque (its factor mu)."""

    motor_friction_Nm: float = 0.0
    sensor_offset_Nm: float = 0.0
    gain_error: float = 0.0
    rack_friction_N: float = 0.0
    cogging_Nm: float = 0.0
    cogging_periods: int = 6
    hysteresis_Nm: float = 0.0
    backlash_rad: float = 0.0
    current_friction: float = 0.0


# The hidden quantities of the truth by the diagnosis candidate each stands for (rack friction: calibrated).
HIDDEN_TRUTH = {
    "assist_motor_friction": "motor_friction_Nm",
    "torsion_bar_offset": "sensor_offset_Nm",
    "boost_gain_error": "gain_error",
    "rack_friction": "rack_friction_N",
}
# Out-of-class forms: name -> (the Hidden field, what it is, candidates a diagnosis may honestly name for it). A
# friction that grows with the motor's torque acts as a loss of the forward gain and as a friction of the gear:
# naming the gain error or the motor friction is near the truth. Cogging, map hysteresis and backlash are no
# candidate's form.
OUT_OF_CLASS_TRUTH = {
    "cogging": ("cogging_Nm", "cogging of the motor, periodic in the rotor's angle", ()),
    "boost_hysteresis": ("hysteresis_Nm", "a play of the control unit's map on its reading", ()),
    "gear_backlash": ("backlash_rad", "backlash of the worm, crossed unloaded at each reversal of its torque", ()),
    "current_friction": ("current_friction", "a gear friction growing with the motor's torque",
                         ("boost_gain_error", "assist_motor_friction")),
}


@dataclass(frozen=True)
class TruthLogger:
    """A bus logger of the truth's car: its rate, the rack (``rack_bits`` 0: no rack, the angle-only tier), the
    torsion-bar sensor (its bits and full scale: the control unit reads the same steps), the current and the
    handwheel angle, each with its noise; ``seed`` for the noise."""

    sample_rate_hz: float = 100.0
    rack_bits: int = 12
    rack_full_scale_m: float = 0.1
    rack_noise_m: float = 2e-5
    torque_bits: int = 12
    torque_full_scale_Nm: float = 10.24
    torque_noise_Nm: float = 0.01
    current_bits: int = 12
    current_full_scale_A: float = 100.0
    current_noise_A: float = 0.1
    angle_bits: int = 14
    angle_full_scale_rad: float = 16.0
    angle_noise_rad: float = 2e-4
    seed: int = 0

    @property
    def torque_step(self) -> float:
        return quantisation_step(self.torque_full_scale_Nm, self.torque_bits)


def column_of_pinion(pinion_rad, joint_angle_rad: float, phase_rad: float) -> np.ndarray:
    """theta_c from theta_p through the Hooke joint: tan(theta_c - phase) = cos(alpha) tan(theta_p - phase), in the
    branch-free form theta_c - theta_p = atan((cos a - 1) sin psi cos psi / (cos^2 psi + cos a sin^2 psi)),
    psi = theta_p - phase (its denominator is at least cos a > 0)."""
    theta_p = np.asarray(pinion_rad, dtype=float)
    cos_a = pm.cos(joint_angle_rad)
    psi = theta_p - phase_rad
    s, c = pm.sin(psi), pm.cos(psi)
    return theta_p + pm.atan((cos_a - 1.0) * s * c / (c**2 + cos_a * s**2))


@dataclass
class Road:
    """The manual replay of one hand: time, rack, the column's angle, rate and acceleration, the column torque
    T_road and its change per newton of rack friction."""

    time_s: np.ndarray
    rack_m: np.ndarray
    column_rad: np.ndarray
    column_rate: np.ndarray
    column_accel: np.ndarray
    torque_Nm: np.ndarray
    per_rack_friction: np.ndarray = field(default_factory=lambda: np.zeros(0))


def manual_road(params: Parameters, hand: HandVariant, case: str, overrides: dict[str, float] | None = None,
                surface: str = "ground", dt_s: float = CLEAN_DT_S, rack_friction: bool = False) -> Road:
    """The column torque the car without its assist needs to follow `hand`'s rack (the manual replay), with the
    column's kinematics; with `rack_friction`, also its change per newton of rack friction (a second replay)."""
    from ..model.numeric.simulate import simulate

    rack = variation_rack(params, hand)
    overrides = dict(overrides or {})

    def replay(extra: dict) -> dict:
        return simulate(case, effects=None, overrides={**overrides, **extra}, surface=surface, rack_drive=rack,
                        params=params, output_dt_s=dt_s).columns

    columns = replay({})
    t = np.asarray(columns["time_s"], dtype=float)
    x = np.asarray(columns["rack_m"], dtype=float)
    s = params.sections["steering"]
    theta_c = column_of_pinion(s["handwheel_to_rack_ratio"] * x, s["hooke_joint_angle"], s["hooke_joint_phase"])
    rate = np.gradient(theta_c, t)
    accel = np.gradient(rate, t)
    torque = np.asarray(columns[TORQUE], dtype=float)
    road = Road(t, x, theta_c, rate, accel, torque)
    if rack_friction:
        base = overrides.get(RACK_FRICTION, float(params[RACK_FRICTION]))
        more = np.asarray(replay({RACK_FRICTION: base + RACK_FRICTION_PROBE_N})[TORQUE], dtype=float)
        road.per_rack_friction = (more - torque) / RACK_FRICTION_PROBE_N
    return road


def _factor(o, rate, gear: TruthGear):
    """What the worm delivers to the column per rotor-side torque, over N: eta_f when the motor drives (o with the
    column's rate), 1 / eta_b back-driven (o against it), moving linearly from 1 at rest to these as the rotor's
    speed reaches ``direction_speed_rad_s`` (the worm's friction passing through its static band at a reversal).
    Driving it is at most 1 and back-driven at least 1: the gear never gives more power than it takes."""
    along = np.where(o * rate > 0.0, gear.efficiency, 1.0 / gear.back_efficiency)
    if gear.direction_speed_rad_s <= 0.0:
        reached = np.where(rate != 0.0, 1.0, 0.0)
    else:
        reached = np.minimum(np.abs(gear.reduction * rate) / gear.direction_speed_rad_s, 1.0)
    return 1.0 + (along - 1.0) * reached


def _delivered(o, rate, gear: TruthGear):
    """The torque the worm gives the column for the rotor-side torque o (:func:`_factor`); it rises with o."""
    return gear.reduction * o * _factor(o, rate, gear)


def _undelivered(delivered, rate, gear: TruthGear):
    """The rotor-side torque o that delivers `delivered` (the inverse of :func:`_delivered`: o has the sign of
    what it delivers, so the factor is read from that sign)."""
    return delivered / (gear.reduction * _factor(delivered, rate, gear))


@dataclass
class TruthSolution:
    torsion_bar_Nm: np.ndarray
    current_A: np.ndarray
    delivered_Nm: np.ndarray


def eps_layer(road: Road, boost: TruthMap, gear: TruthGear, step_Nm: float, full_scale_Nm: float,
              hidden: Hidden = Hidden()) -> TruthSolution:
    """The torsion-bar torque, the motor current and the delivered assist over `road` (module docstring), the
    control unit reading its sensor in steps of `step_Nm` (the converter of ``full_scale_Nm`` with that step)."""
    y = road.torque_Nm + hidden.rack_friction_N * (road.per_rack_friction if hidden.rack_friction_N else 0.0)
    n = gear.reduction
    rotor_rate = n * road.column_rate
    speed = np.clip(rotor_rate / gear.friction_speed_rad_s, -1.0, 1.0)
    coulomb = (gear.motor_friction_Nm + hidden.motor_friction_Nm) * speed
    load = gear.motor_inertia_kg_m2 * n * road.column_accel + coulomb
    if hidden.cogging_Nm:
        load = load + hidden.cogging_Nm * pm.sin(hidden.cogging_periods * n * road.column_rad)
    bits = max(1, round(math.log2(2.0 * full_scale_Nm / step_Nm + 1.0)))
    gain = (1.0 + hidden.gain_error) / (gear.efficiency * n * gear.torque_constant_Nm_per_A)

    # the control unit's current at each level of its reading (it reads nothing between the levels)
    step = quantisation_step(full_scale_Nm, bits)
    levels = -full_scale_Nm + step * np.arange(2**bits)
    table = np.clip(gain * boost(levels), -gear.current_limit_A, gear.current_limit_A)

    def current(reading):
        level = np.clip(np.rint((np.asarray(reading, dtype=float) + full_scale_Nm) / step), 0, 2**bits - 1)
        return table[level.astype(int)]

    def rotor(i):
        em = gear.torque_constant_Nm_per_A * i
        return em - hidden.current_friction * np.abs(em) * speed - load

    def solve(readings_of, y_, rate_):
        """T_s with T_s + D(o) first reaching y_ (bisection; readings_of(T_s) the control unit's input)."""
        width = n * gear.torque_constant_Nm_per_A * gear.current_limit_A / gear.back_efficiency + 10.0
        low, high = y_ - width, y_ + width
        for _ in range(BISECTION_STEPS):
            mid = 0.5 * (low + high)
            above = mid + _delivered(rotor_current(readings_of(mid)), rate_, gear) >= y_
            high, low = np.where(above, mid, high), np.where(above, low, mid)
        return high

    def rotor_current(reading):
        return rotor(current(reading))

    if hidden.hysteresis_Nm:
        ts = _solve_play(y, road.column_rate, hidden.sensor_offset_Nm, hidden.hysteresis_Nm,
                         lambda readings_of: solve(readings_of, y, road.column_rate), current, gear, load, speed,
                         hidden.current_friction)
    else:
        ts = solve(lambda t_s: t_s + hidden.sensor_offset_Nm, y, road.column_rate)
    delivered = y - ts
    o = _undelivered(delivered, road.column_rate, gear)
    # the mean current that delivers it (o = k_t I - mu |k_t I| sign - load, I of the sign of o + load)
    em = o + load
    em = em / (1.0 - hidden.current_friction * np.sign(em) * speed) if hidden.current_friction else em
    amps = em / gear.torque_constant_Nm_per_A
    if hidden.backlash_rad:
        ts, amps, delivered = _backlash(road, y, ts, amps, o, hidden, gear, current, rotor)
    return TruthSolution(ts, amps, delivered)


def _solve_play(y, rate, offset, half_width, solve, current, gear, load, speed, current_friction):
    """The torsion-bar torque when the control unit reads its sensor through a play of `half_width` (the map's
    hysteresis): the play's output r = clip(r_prev, S - h, S + h) feeds the map. At each sample either r holds
    (the map's input fixed: T_s = T_road less what r's current delivers, if its reading stays within r +- h), or
    r is pushed by the reading (r = S -+ h, the balance monotone in T_s: solved for every sample at once by
    `solve` beforehand)."""
    rising = solve(lambda t_s: t_s + offset - half_width)
    falling = solve(lambda t_s: t_s + offset + half_width)
    ts = np.empty(len(y))
    r = 0.0
    k_t = gear.torque_constant_Nm_per_A
    for k in range(len(y)):
        em = k_t * float(current(r))
        o = em - current_friction * abs(em) * speed[k] - load[k]
        delivered = gear.reduction * (o / gear.back_efficiency if o * rate[k] < 0.0 else gear.efficiency * o)
        held = y[k] - delivered
        s = held + offset
        if s > r + half_width:
            ts[k] = rising[k]
            r = rising[k] + offset - half_width
        elif s < r - half_width:
            ts[k] = falling[k]
            r = falling[k] + offset + half_width
        else:
            ts[k] = held
    return ts


def _backlash(road, y, ts, amps, o, hidden, gear, current, rotor):
    """Gaps of the assist where the worm's torque o reverses: the rotor crosses the lash b unloaded, for
    sqrt(2 J_m b / |o_free|) with o_free its torque with the column carrying all (T_s = T_road), during which
    the column gets no assist."""
    ts, amps = ts.copy(), amps.copy()
    t = road.time_s
    flips = np.nonzero(np.sign(o[1:]) * np.sign(o[:-1]) < 0)[0] + 1
    free = gear.torque_constant_Nm_per_A * current(y + hidden.sensor_offset_Nm)
    for k in flips:
        o_free = max(abs(float(free[k])), 1e-6)
        gap = math.sqrt(2.0 * gear.motor_inertia_kg_m2 * hidden.backlash_rad / o_free)
        inside = (t >= t[k]) & (t < t[k] + gap)
        ts[inside] = y[inside]
        amps[inside] = current(y[inside] + hidden.sensor_offset_Nm)
    return ts, amps, y - ts


def truth_clean(road: Road, boost: TruthMap, gear: TruthGear, logger: TruthLogger, hidden: Hidden = Hidden(),
                params: Parameters | None = None) -> dict[str, np.ndarray]:
    """The clean channels of the truth over `road`: time, rack, the sensor's reading (T_s + offset), current and,
    with `params` (its column), the handwheel angle."""
    solution = eps_layer(road, boost, gear, logger.torque_step, logger.torque_full_scale_Nm, hidden)
    out = {"time_s": road.time_s, "rack_m": road.rack_m,
           TORQUE: solution.torsion_bar_Nm + hidden.sensor_offset_Nm,
           "motor_current_A": solution.current_A}
    if params is not None:
        out["handwheel_angle_rad"] = handwheel_angle(road, solution.torsion_bar_Nm, gear, params)
    return out


def handwheel_angle(road: Road, torsion_bar_Nm: np.ndarray, gear: TruthGear, params: Parameters) -> np.ndarray:
    """The handwheel's angle over `road`: the column's plus the twist of the torsion bar and the column in series
    (the car's column stiffness and damping from `params`) under the torsion-bar torque."""
    s = params.sections["steering"]
    k, c = s["column_torsional_stiffness"], s["column_torsional_damping"]
    series = k * gear.torsion_bar_stiffness / (k + gear.torsion_bar_stiffness)
    twist, _ = column_twist(road.time_s, torsion_bar_Nm, series, c * series / k)
    return road.column_rad + twist


def truth_record(clean: dict[str, np.ndarray], logger: TruthLogger, case: str, surface: str = "ground",
                 source: str = "synthetic: parksteer.synthetic.assisted_truth") -> Measurement:
    """`clean` logged on `logger`: sampled, noise added, each channel on its converter; no rack when
    ``logger.rack_bits`` is 0 (the angle-only tier: handwheel angle, torsion-bar torque, current)."""
    wanted = {k: v for k, v in clean.items() if k != "time_s"}
    time_s, sampled = resample(clean["time_s"], wanted, logger.sample_rate_hz)
    rng = np.random.default_rng(logger.seed)
    columns = {"time_s": time_s}
    metadata = {"case": case, "surface": surface, "source": source, "synthetic": True,
                "torque_sensor": "torsion_bar", "bits": logger.torque_bits,
                "full_scale_handwheel_torque_Nm": logger.torque_full_scale_Nm,
                "sample_rate_hz": float(logger.sample_rate_hz), "noise_seed": logger.seed}
    if logger.rack_bits:
        columns["rack_m"] = quantise(add_noise(sampled["rack_m"], logger.rack_noise_m, rng),
                                     logger.rack_full_scale_m, logger.rack_bits)
        metadata["bits_rack_m"] = logger.rack_bits
        metadata["full_scale_rack_m"] = logger.rack_full_scale_m
    columns[TORQUE] = quantise(add_noise(sampled[TORQUE], logger.torque_noise_Nm, rng),
                                              logger.torque_full_scale_Nm, logger.torque_bits)
    columns["motor_current_A"] = quantise(add_noise(sampled["motor_current_A"], logger.current_noise_A, rng),
                                          logger.current_full_scale_A, logger.current_bits)
    metadata["bits_motor_current_A"] = logger.current_bits
    metadata["full_scale_motor_current_A"] = logger.current_full_scale_A
    if not logger.rack_bits:
        columns["handwheel_angle_rad"] = quantise(add_noise(sampled["handwheel_angle_rad"], logger.angle_noise_rad,
                                                            rng), logger.angle_full_scale_rad, logger.angle_bits)
        metadata["bits_handwheel_angle_rad"] = logger.angle_bits
        metadata["full_scale_handwheel_angle_rad"] = logger.angle_full_scale_rad
    return Measurement(path=None, columns=columns, metadata={k: metadata_text(v) for k, v in metadata.items()})


def with_hidden(hidden: Hidden, name: str, size: float) -> Hidden:
    """`hidden` with the truth's quantity of candidate or out-of-class form `name` set to `size`."""
    key = HIDDEN_TRUTH.get(name) or OUT_OF_CLASS_TRUTH[name][0]
    return replace(hidden, **{key: size})


__all__ = ["HIDDEN_TRUTH", "OUT_OF_CLASS_TRUTH", "Hidden", "Road", "TruthGear", "TruthLogger", "TruthMap",
           "column_of_pinion", "eps_layer", "handwheel_angle", "manual_road", "truth_clean", "truth_record",
           "with_hidden"]
