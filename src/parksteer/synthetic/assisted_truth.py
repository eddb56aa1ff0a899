"""An assisted car's records from a truth of their own: a column EPS written apart from the model's assist.

The model's assisted replay (:mod:`parksteer.model.numeric.assisted`) inverts the boost law of the effect it
diagnoses with. Records made by it share that law, its corners and its gear with the diagnosis. Here nothing of
the model's assist is called: the road part is the manual replay (the prescribed-rack solve of the car without
an assist, :func:`parksteer.model.numeric.simulate.simulate`), and over it sits a quasi-static column-EPS layer
written for it alone (:mod:`parksteer.synthetic.column_eps_layer`, which says how it works).

Hidden, in the truth's own terms (:data:`HIDDEN_TRUTH`): the motor's friction above the car's, the sensor's
offset, the map's gain error, a rack friction above the file's (the manual replay's own parameter, affine in the
torque: one extra replay gives its direction). Out of class (:data:`OUT_OF_CLASS_TRUTH`): cogging of the motor
(n periods a revolution), a hysteresis of the control unit's map (a play of half-width h on its reading), backlash
of the worm (after every reversal of the worm's torque the motor crosses the lash unloaded: no assist for
sqrt(2 J_m b / |o|)), a friction of the gear growing with the motor's torque (mu |k_t I| beside the Coulomb part).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .. import portable as pm
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


@dataclass(frozen=True)
class TruthHidden:
    """How the truth shows one hidden candidate: the field of :class:`Hidden` it sets, and the largest size the
    benchmark's size search tries (that field's unit; the search starts at a hundredth of it)."""

    hidden_field: str
    largest: float


# The truth's row of each diagnosis candidate it hides (rack friction: the base's, calibrated), in the benchmarks'
# order. The truth is written apart from the model, so how it shows a candidate is declared here, not read from the
# candidate's effect: each candidate of the assisted benchmarks has this one row besides its effect file.
HIDDEN_TRUTH = {
    "assist_motor_friction": TruthHidden("motor_friction_Nm", 0.3),
    "torsion_bar_offset": TruthHidden("sensor_offset_Nm", 1.0),
    "boost_gain_error": TruthHidden("gain_error", 1.0),
    "rack_friction": TruthHidden("rack_friction_N", 1500.0),
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
    key = HIDDEN_TRUTH[name].hidden_field if name in HIDDEN_TRUTH else OUT_OF_CLASS_TRUTH[name][0]
    return replace(hidden, **{key: size})


__all__ = ["HIDDEN_TRUTH", "OUT_OF_CLASS_TRUTH", "Hidden", "Road", "TruthHidden", "TruthGear", "TruthLogger",
           "TruthMap", "column_of_pinion", "manual_road", "truth_record", "with_hidden"]
