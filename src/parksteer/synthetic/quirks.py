"""Manual cars the model does not fit: every record carries a quirk of the car's own, outside the library.

A quirk is written apart from the model, as a layer over the manual replay (the prescribed-rack solve,
:func:`parksteer.model.numeric.simulate.simulate`, on the rack a hand drives: :func:`manual_road`), which gives the
column torque ``T`` (N m) the car needs, its column angle, rack speed, mean steer angle, the tyre's share of ``T``
and the linkage's ratios (column angle and steer angle per metre of rack); each quirk changes what the logger sees:
``bore_friction`` (:class:`BoreFriction`, a rack friction growing toward the ends and stronger one way, N),
``joint_phasing`` (:class:`JointPhasing`, a second universal joint out of phase by its angle in rad), ``dahl_tyre``
(:class:`DahlTyre`, a share of the tyre's moment about the king-pins in Dahl's hysteresis of the steer angle,
through the linkage) and ``tie_rod_compliance`` (:class:`TieRodCompliance`, tie-rod bushes stiffening with load: the
wheels lag the logged rack by a travel in m that saturates). Each class holds its form and constants. The quirk's
strength is the car's, one value for every record (:func:`quirk_strength` sizes it on the healthy record); hidden
library effects on later records enter the replay (``effects``, ``overrides``), under the quirk. The benchmark:
docs/diagnosis.md, "Cars the model does not fit".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..measure.converter import quantisation_step
from ..measure.io import Measurement
from ..parameters import Parameters
from .assisted_truth import column_of_pinion
from .logger import LoggerSettings, synthetic_measurement
from .variations import CLEAN_DT_S, HandVariant, variation_rack
from ..names import TORQUE

JOINT_STEP_RAD = 1e-6  # the central difference of the Hooke joint's map that gives its speed ratio
STEER_STEP_M = 1e-6  # the central difference of the model's steer map that gives the steer per metre of rack


@dataclass
class ManualRoad:
    """The manual replay of one hand: time, the wheels' rack, the column torque, the column angle, the rack's
    speed, the mean steer angle, the tyre's share of the torque, the column angle per metre of rack and the mean
    steer angle per metre of rack."""

    time_s: np.ndarray
    rack_m: np.ndarray
    torque_Nm: np.ndarray
    column_rad: np.ndarray
    rack_speed_m_s: np.ndarray
    steer_rad: np.ndarray
    tyre_Nm: np.ndarray
    column_per_rack: np.ndarray
    steer_per_rack: np.ndarray
    replayed_Nm: np.ndarray | None = None  # the replay of this rack as a logged rack is replayed (apparent_change)

    @property
    def steer_per_column(self) -> np.ndarray:
        """d(mean steer)/d(column angle): by virtual work, the handwheel torque of a moment about the king-pins
        (both wheels, N m) is the moment times this."""
        return self.steer_per_rack / self.column_per_rack


def manual_road(params: Parameters, hand: HandVariant, case: str, overrides: dict[str, float] | None = None,
                effects: str | None = None, surface: str = "ground", dt_s: float = CLEAN_DT_S,
                rack_drive=None) -> ManualRoad:
    """The car of `params` (with `overrides`, and `effects` added: a hidden library effect) following `hand`'s
    rack, or `rack_drive` where given (the prescribed-rack solve)."""
    from ..model.numeric.simulate import simulate

    drive = rack_drive if rack_drive is not None else variation_rack(params, hand)
    run = simulate(case, effects=effects, overrides=dict(overrides or {}), surface=surface, rack_drive=drive,
                   params=params, output_dt_s=dt_s)
    c = run.columns
    x = np.asarray(c["rack_m"], dtype=float)
    s = params.sections["steering"]
    ratio, angle, phase = s["handwheel_to_rack_ratio"], s["hooke_joint_angle"], s["hooke_joint_phase"]
    h = JOINT_STEP_RAD
    speed_ratio = (column_of_pinion(ratio * x + h, angle, phase) - column_of_pinion(ratio * x - h, angle, phase)) \
        / (2.0 * h)
    steer = 0.5 * (np.asarray(c["steer_left_rad"], dtype=float) + np.asarray(c["steer_right_rad"], dtype=float))
    return ManualRoad(np.asarray(c["time_s"], dtype=float), x, np.asarray(c[TORQUE], dtype=float),
                      np.asarray(c["column_angle_rad"], dtype=float), np.asarray(c["rack_speed_m_s"], dtype=float),
                      steer, np.asarray(c["contrib_tyre_friction_Nm"], dtype=float), ratio * speed_ratio,
                      _steer_per_rack(run))


def _steer_per_rack(run) -> np.ndarray:
    """d(mean steer)/d(rack), rad/m, at each sample: the model's own steer map (its steer outputs, which depend on
    the rack alone) at the replay's states with the rack moved by +-STEER_STEP_M, a central difference of the
    kinematics; a difference along the series would be 0/0 wherever the rack reverses."""
    rack = run.model.index("rack")

    def mean_steer(shift_m: float) -> np.ndarray:
        states = np.array(run.states, dtype=float)
        states[:, rack] += shift_m
        out = run.model.evaluate_outputs(run.columns["time_s"], states, run.parameter_vector)
        return 0.5 * (np.asarray(out["steer_left_rad"], dtype=float) + np.asarray(out["steer_right_rad"], dtype=float))

    return (mean_steer(STEER_STEP_M) - mean_steer(-STEER_STEP_M)) / (2.0 * STEER_STEP_M)


class Quirk:
    """A quirk's layer over the manual replay: the logged rack and torque for a strength (0: the replay as it is)."""

    name = ""
    what = ""
    unit = ""
    upper = 1.0  # the largest strength searched

    def logged(self, road: ManualRoad, strength: float) -> tuple[np.ndarray, np.ndarray]:
        """(rack the logger reads, torque at the handwheel)."""
        return road.rack_m, road.torque_Nm + self.added_torque(road, strength)

    def added_torque(self, road: ManualRoad, strength: float) -> np.ndarray:
        raise NotImplementedError


def _direction(v: np.ndarray, v0: float) -> np.ndarray:
    return v / np.sqrt(v * v + v0 * v0)


class BoreFriction(Quirk):
    name = "bore_friction"
    what = "rack friction growing toward the ends, stronger one way, with its own smoothing"
    unit = "N"
    upper = 2000.0
    speed_scale_m_s = 0.002

    def added_torque(self, road, strength):
        d = _direction(road.rack_speed_m_s, self.speed_scale_m_s)
        force = strength * (0.55 + 0.45 * (road.rack_m / 0.065) ** 2) * d * (1.0 + 0.3 * d)
        return force / road.column_per_rack


class JointPhasing(Quirk):
    name = "joint_phasing"
    what = "a second universal joint out of phase: the torque times its speed ratio, twice per column turn"
    unit = "rad"
    upper = 0.6
    phase_rad = 0.9

    def added_torque(self, road, strength):
        s2 = pm.sin(strength) ** 2
        ratio = pm.cos(strength) / (1.0 - s2 * pm.sin(road.column_rad - self.phase_rad) ** 2)
        return road.torque_Nm * (ratio - 1.0)


class DahlTyre(Quirk):
    """A tyre moment of another shape: Dahl's hysteresis of the mean steer angle, a moment about the king-pins (both
    wheels, N m), reaching the handwheel through the linkage as the model's own tyre moment does (times
    d(steer)/d(column), :attr:`ManualRoad.steer_per_column`: with the rack's position and twice per column turn),
    and taking the place of the same share of the model's tyre moment."""

    name = "dahl_tyre"
    what = "a share of the tyre's moment about the king-pins in Dahl's hysteresis of the steer angle, via the linkage"
    unit = "1"
    upper = 1.0
    # Both front tyres sliding about the king-pins: the paper's equation (2) at the unladen car's front wheel
    # loads (about 2.8 kN a wheel, 125 N m each), the size at which the model's own tyre moment slides.
    saturation_Nm = 250.0
    # The steer over which the moment builds: a first stiffness M_s / delta_0 of 5 kN m/rad, stiffer than the
    # paper's carcass (728 N m/rad a wheel) and with a rounder knee than its sliding patch: another shape.
    approach_rad = 0.05

    def dahl(self, steer_rad: np.ndarray) -> np.ndarray:
        """Dahl's moment about the king-pins along the steer angle's path, from rest (0) at the start (explicit
        steps, exact arithmetic: the same bits on every machine)."""
        slope = self.saturation_Nm / self.approach_rad
        out = np.empty(len(steer_rad))
        m, previous = 0.0, float(steer_rad[0])
        for k, delta in enumerate(steer_rad.tolist()):
            step = delta - previous
            if step:
                gap = 1.0 - (m / self.saturation_Nm) * (1.0 if step > 0 else -1.0)
                m = min(max(m + slope * gap * gap * step, -self.saturation_Nm), self.saturation_Nm)
            out[k] = m
            previous = delta
        return out

    def added_torque(self, road, strength):
        """At the handwheel: the share `strength` of the model's tyre moment (``tyre_Nm``, already through the
        linkage) replaced by Dahl's moment mapped by the linkage's ratio sample by sample."""
        return strength * (self.dahl(road.steer_rad) * road.steer_per_column - road.tyre_Nm)


class TieRodCompliance(Quirk):
    name = "tie_rod_compliance"
    what = "tie-rod bushes stiffening with load: the wheels lag the logged rack by a travel that saturates"
    unit = "m"
    upper = 0.003
    knee_N = 1500.0

    def logged(self, road, strength):
        force = road.torque_Nm * road.column_per_rack
        return road.rack_m + strength * force / np.sqrt(force * force + self.knee_N ** 2), road.torque_Nm

    def added_torque(self, road, strength):
        return np.zeros_like(road.torque_Nm)


QUIRKS: dict[str, Quirk] = {q.name: q for q in (BoreFriction(), JointPhasing(), DahlTyre(), TieRodCompliance())}


def quirk_by_name(name: str) -> Quirk:
    if name not in QUIRKS:
        raise UsageError(f"no quirk {name!r} (known: {', '.join(QUIRKS)})")
    return QUIRKS[name]


def apparent_change(params: Parameters, road: ManualRoad, quirk: Quirk, strength: float, case: str,
                    surface: str = "ground", overrides: dict[str, float] | None = None) -> np.ndarray:
    """What the quirk changes in the torque against the model's replay of the rack the logger reads: the added
    torque, and where the logged rack moves (a compliance), the replay of the wheels' rack less that of the moved
    rack, both replayed alike (a spline through the samples), so that the spline's own error cancels."""
    from ..measure.rack_spline import interpolate_rack

    rack, torque = quirk.logged(road, strength)
    if rack is road.rack_m:
        return torque - road.torque_Nm

    def replayed(x: np.ndarray) -> np.ndarray:
        run = manual_road(params, HandVariant(), case, overrides, surface=surface,
                          rack_drive=interpolate_rack(road.time_s, x), dt_s=float(road.time_s[1] - road.time_s[0]))
        return np.interp(road.time_s, run.time_s, run.torque_Nm)

    if road.replayed_Nm is None:
        road.replayed_Nm = replayed(road.rack_m)
    return road.replayed_Nm - replayed(rack)


def quirk_strength(params: Parameters, road: ManualRoad, quirk: Quirk, target_Nm: float, case: str,
                   surface: str = "ground", overrides: dict[str, float] | None = None) -> tuple[float, float]:
    """(strength, RMS apparent change) of `quirk` whose apparent change (:func:`apparent_change`) on `road` (made
    with `overrides`) is `target_Nm` RMS: bisection in the log of the strength (the change grows with it)."""
    def rms(strength: float) -> float:
        change = apparent_change(params, road, quirk, strength, case, surface, overrides)
        return math.sqrt(float(np.mean(change * change)))

    low, high = quirk.upper * 1e-4, quirk.upper
    if rms(high) < target_Nm:
        raise UsageError(f"quirk {quirk.name}: {target_Nm:g} N m RMS is beyond its largest strength {high:g}")
    for _ in range(14 if isinstance(quirk, TieRodCompliance) else 40):
        mid = math.sqrt(low * high)
        low, high = (mid, high) if rms(mid) < target_Nm else (low, mid)
    strength = math.sqrt(low * high)
    return strength, rms(strength)


@dataclass(frozen=True)
class ManualLogger:
    """A manual car's logger: its rate, the rack's converter, the torque's (bits, full scale), both noises."""

    sample_rate_hz: float = 100.0
    rack_bits: int = 12
    rack_full_scale_m: float = 0.1
    rack_noise_m: float = 2e-5
    torque_bits: int = 12
    torque_full_scale_Nm: float = 20.48
    torque_noise_Nm: float = 0.02
    seed: int = 0

    @property
    def torque_step(self) -> float:
        return quantisation_step(self.torque_full_scale_Nm, self.torque_bits)

    @property
    def floor_Nm(self) -> float:
        """The torque channel's noise floor: its noise and its rounding (step / sqrt 12), root sum of squares."""
        return math.hypot(self.torque_noise_Nm, self.torque_step / math.sqrt(12.0))


def quirk_record(road: ManualRoad, quirk: Quirk, strength: float, logger: ManualLogger, case: str,
                 surface: str = "ground", extra_metadata: dict | None = None) -> Measurement:
    """The car's record: the quirk's layer over `road`, logged on `logger` (sampled, noise, each channel on its
    converter: :func:`parksteer.synthetic.logger.synthetic_measurement`)."""
    rack, torque = quirk.logged(road, strength)
    settings = LoggerSettings(logger.sample_rate_hz,
                              {"rack_m": logger.rack_full_scale_m, TORQUE: logger.torque_full_scale_Nm},
                              {"rack_m": logger.rack_noise_m, TORQUE: logger.torque_noise_Nm},
                              logger.seed, bits=logger.torque_bits, column_bits={"rack_m": logger.rack_bits})
    meta = {"quirk": quirk.name, "quirk_strength": strength, **(extra_metadata or {})}
    return synthetic_measurement(road.time_s, {"rack_m": rack, TORQUE: torque}, settings, case=case,
                                 surface=surface, source="synthetic: parksteer.synthetic.quirks",
                                 extra_metadata=meta)


__all__ = ["QUIRKS", "BoreFriction", "DahlTyre", "JointPhasing", "ManualLogger", "ManualRoad", "Quirk",
           "TieRodCompliance", "apparent_change", "manual_road", "quirk_by_name", "quirk_record", "quirk_strength"]
