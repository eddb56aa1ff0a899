"""Records made independently of the benchmark's generator: another hand, another logger, another drive.

The benchmark's records (:mod:`parksteer.synthetic.datasets`) are made by the hand, logger and handwheel-driven
simulation the diagnosis was tuned on; these differ in every one, each as a real test could:

- the hand (:func:`variation_hand`): the Section 4 cycle with a smooth (C2) rate variation of a few per cent,
  optional pauses at rest, and a record that ends mid-stroke or goes on at rest after the hand stops;
- the drive: the rack follows the hand through a rigid column and the Hooke joint
  (:func:`parksteer.synthetic.standin.rack_of_hand`), the torque the model's prescribed-rack solve of that rack (as
  ``parksteer simulate --rack-from`` does), finer than any logger;
- the logger (:class:`VariationLogger`): its own sample rate, rack and torque on converters of different
  resolution; a file states only the torque channel's full scale and bits, so the diagnosis estimates the rack's
  noise from the data.

:data:`VARIATIONS` names one record per way of differing (also uneven strokes, a lock overshoot, 8- to 16-bit racks,
8- to 12-bit torques, 50 Hz to 1 kHz, an anti-alias filter, a channel lag, three files to a case): with nothing
hidden a diagnosis must say ``adequate`` on each; :mod:`parksteer.experiments.variations` hides library effects in
them as well.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..measure.io import Measurement, metadata_text
from ..measure.rack_spline import interpolate_rack
from ..parameters import Parameters
from ..measure.converter import add_noise, quantise
from .logger import resample
from .standin import rack_of_hand
from ..names import TORQUE

# The hand's motion is sampled this finely before the rack is splined through it (s).
HAND_DT_S = 0.002
# The clean torque is solved at this spacing, finer than any logger here, then sampled (s).
CLEAN_DT_S = 0.002


@dataclass(frozen=True)
class HandVariant:
    """A hand through the Section 4 cycle (straight ahead, right lock, left lock, straight ahead).

    ``rate_variation``: the hand's speed in each stroke's cruise is scaled by
    ``1 + rate_variation * s(t)``, s a smooth random signal within [-1, 1] (two sinusoids of
    ``frequency_hz`` scale). ``pause_s``: the hand rests this long in the middle of the first and
    second strokes (0: no pause). ``end``: ``"rest"`` keeps the record going ``rest_after_s`` at rest
    after the hand stops at straight ahead; ``"mid_stroke"`` cuts the record ``cut_before_end_s`` before
    the hand's stop, while it is slowing (the last stroke's ramp to rest lasts ``ramp_s``).
    ``stroke_scale``: each of the three strokes lasts its Section 4 duration times this factor (uneven strokes:
    one hurried, one slow; each still covers its travel). ``overshoot``: the driver turns past each lock by this
    fraction of the lock angle and comes back to it in ``overshoot_return_s`` before the next stroke (0: none).
    """

    rate_variation: float = 0.05
    frequency_hz: float = 0.2
    pause_s: float = 0.0
    end: str = "rest"
    rest_after_s: float = 1.0
    cut_before_end_s: float = 0.15
    ramp_s: float = 0.6
    stroke_scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    overshoot: float = 0.0
    overshoot_return_s: float = 0.8
    seed: int = 0

    def __post_init__(self):
        if not 0.0 <= self.rate_variation < 0.5:
            raise UsageError(f"hand rate variation must be in [0, 0.5), got {self.rate_variation:g}")
        if self.end not in ("rest", "mid_stroke"):
            raise UsageError(f"hand end must be 'rest' or 'mid_stroke', got {self.end!r}")
        if self.end == "mid_stroke" and not 0.0 < self.cut_before_end_s < self.ramp_s:
            raise UsageError("a mid-stroke end must cut the record inside the last ramp to rest")
        if len(self.stroke_scale) != 3 or not all(0.5 <= f <= 2.0 for f in self.stroke_scale):
            raise UsageError(f"hand stroke scale must be three factors in [0.5, 2], got {self.stroke_scale}")
        if not 0.0 <= self.overshoot <= 0.2:
            raise UsageError(f"hand overshoot must be in [0, 0.2] of the lock angle, got {self.overshoot:g}")


def _smoothstep_rate(t: np.ndarray, t0: float, t1: float, ramp: float) -> np.ndarray:
    """A rate shape rising from 0 at t0 to 1 over `ramp`, 1 in the cruise, back to 0 at t1 (C1 cosine ramps)."""
    up = np.clip((t - t0) / ramp, 0.0, 1.0)
    down = np.clip((t1 - t) / ramp, 0.0, 1.0)
    shape = 0.5 - 0.5 * pm.cos(np.pi * np.minimum(up, down))
    return np.where((t > t0) & (t < t1), shape, 0.0)


def variation_hand(params: Parameters, hand: HandVariant) -> tuple[np.ndarray, np.ndarray]:
    """(time s, handwheel angle rad) of `hand`, sampled every HAND_DT_S from 0 to the record's end.

    Each stroke covers exactly its travel (lock, -2 lock, lock; with an overshoot, past each lock and back): its
    rate is scaled so that its integral does, whatever the speed variation.
    """
    p = params.sections["input"]
    lock = p["handwheel_lock_angle"]
    durations = [f * p[k] for f, k in zip(hand.stroke_scale, ("time_to_right_lock", "time_right_to_left_lock",
                                                                "time_left_lock_to_centre"))]
    travels = [lock, -2.0 * lock, lock]
    pauses = [hand.pause_s, hand.pause_s, 0.0]
    if hand.overshoot > 0.0:  # past the right lock and back, past the left lock and back
        over = hand.overshoot * lock
        durations = [durations[0], hand.overshoot_return_s, durations[1], hand.overshoot_return_s, durations[2]]
        travels = [lock + over, -over, -2.0 * lock - over, over, lock]
        pauses = [hand.pause_s, 0.0, hand.pause_s, 0.0, 0.0]
    rng = np.random.default_rng(hand.seed)
    frequencies = hand.frequency_hz * rng.uniform(0.5, 1.5, size=2)
    phases = rng.uniform(0.0, 2.0 * np.pi, size=2)
    end_hand = sum(durations) + sum(pauses)
    end_record = end_hand + hand.rest_after_s if hand.end == "rest" else end_hand - hand.cut_before_end_s
    t = np.arange(0.0, max(end_record, end_hand) + 0.5 * HAND_DT_S, HAND_DT_S)
    wander = 1.0 + hand.rate_variation * 0.5 * np.sum(pm.sin(2 * np.pi * frequencies * t[:, None] + phases), axis=1)
    rate = np.zeros_like(t)
    start = 0.0
    for duration, travel, pause in zip(durations, travels, pauses):
        ramp = min(hand.ramp_s, 0.5 * duration)
        if pause > 0.0:  # the hand slows to rest half way, rests, and goes on
            half = 0.5 * duration
            shape = (_smoothstep_rate(t, start, start + half, ramp)
                     + _smoothstep_rate(t, start + half + pause, start + duration + pause, ramp))
        else:
            shape = _smoothstep_rate(t, start, start + duration, ramp)
        piece = shape * wander
        area = float(np.sum(0.5 * (piece[1:] + piece[:-1]) * np.diff(t)))
        rate += travel / area * piece
        start += duration + pause
    keep = t <= end_record + 1e-9
    t, rate = t[keep], rate[keep]
    angle = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t))])
    return t, angle


@dataclass(frozen=True)
class VariationLogger:
    """A logger with its own sample rate and a converter per channel: rack and torque bits, full scales, noise.

    ``anti_alias_hz`` (0: none) and ``torque_lag_s`` put the out-of-class logger chain's analogue front before the
    sampling (:func:`parksteer.synthetic.outclass.anti_alias_and_lag`: a causal Butterworth of
    ``anti_alias_order`` on both channels, the torque channel delayed behind the rack).
    ``angle_bits`` (0: no angle channel) logs the handwheel angle too, as an encoder would: sampled without the
    analogue filter, with ``angle_noise_rad`` RMS noise on +-``angle_full_scale_rad``.
    """

    sample_rate_hz: float = 100.0
    rack_bits: int = 12
    torque_bits: int = 8
    rack_full_scale_m: float = 0.1
    torque_full_scale_Nm: float = 25.0
    rack_noise_m: float = 2e-5
    torque_noise_Nm: float = 0.1
    anti_alias_hz: float = 0.0
    anti_alias_order: int = 2
    torque_lag_s: float = 0.0
    seed: int = 0
    angle_bits: int = 0
    angle_full_scale_rad: float = 16.0
    angle_noise_rad: float = 2e-4


def variation_record(params: Parameters, hand: HandVariant, logger: VariationLogger, case: str = "unladen",
                     surface: str = "ground", overrides: dict[str, float] | None = None, effects=None) -> Measurement:
    """A record: `hand` drives the rack, the model's prescribed-rack solve gives the torque, `logger` logs both.

    With `effects` (a spec as ``parksteer simulate --effects``) and `overrides`, something is hidden in it;
    by default nothing is (a null).
    """
    from ..model.numeric.simulate import simulate
    from .outclass import anti_alias_and_lag

    drive = variation_rack(params, hand)
    # at least two clean samples per logged one, so that a 1 kHz logger samples a signal finer than itself
    result = simulate(case, effects=effects, overrides=overrides, surface=surface, rack_drive=drive, params=params,
                      output_dt_s=min(CLEAN_DT_S, 0.5 / logger.sample_rate_hz))
    t = np.asarray(result.columns["time_s"], dtype=float)
    clean = anti_alias_and_lag(t, result.columns, logger.anti_alias_hz, logger.anti_alias_order, logger.torque_lag_s)
    if logger.angle_bits:
        clean["handwheel_angle_rad"] = np.asarray(result.columns["handwheel_angle_rad"], dtype=float)
    time_s, sampled = resample(t, clean, logger.sample_rate_hz)
    rng = np.random.default_rng(logger.seed)
    rack = quantise(add_noise(sampled["rack_m"], logger.rack_noise_m, rng), logger.rack_full_scale_m, logger.rack_bits)
    torque = quantise(add_noise(sampled[TORQUE], logger.torque_noise_Nm, rng),
                      logger.torque_full_scale_Nm, logger.torque_bits)
    metadata = {
        "case": case, "surface": surface, "source": "synthetic: parksteer.synthetic.variations",
        "synthetic": True, "bits": logger.torque_bits, "sample_rate_hz": float(logger.sample_rate_hz),
        "full_scale_handwheel_torque_Nm": logger.torque_full_scale_Nm,
        "rack_bits": logger.rack_bits, "hand_rate_variation": hand.rate_variation, "hand_pause_s": hand.pause_s,
        "hand_end": hand.end, "hand_seed": hand.seed, "noise_seed": logger.seed,
    }
    if hand.stroke_scale != (1.0, 1.0, 1.0):
        metadata["hand_stroke_scale"] = " ".join(f"{f:g}" for f in hand.stroke_scale)
    if hand.overshoot:
        metadata["hand_overshoot"] = hand.overshoot
    if logger.anti_alias_hz:
        metadata["anti_alias_hz"] = logger.anti_alias_hz
    if logger.torque_lag_s:
        metadata["torque_lag_s"] = logger.torque_lag_s
    columns = {"time_s": time_s, "rack_m": rack, TORQUE: torque}
    if logger.angle_bits:  # its noise drawn after the others', so that the other channels are those without it
        columns["handwheel_angle_rad"] = quantise(add_noise(sampled["handwheel_angle_rad"], logger.angle_noise_rad, rng),
                                                  logger.angle_full_scale_rad, logger.angle_bits)
        metadata["bits_handwheel_angle_rad"] = logger.angle_bits
        metadata["full_scale_handwheel_angle_rad"] = logger.angle_full_scale_rad
    return Measurement(path=None, columns=columns, metadata={k: metadata_text(v) for k, v in metadata.items()})


def variation_rack(params: Parameters, hand: HandVariant):
    """The rack the hand drives (a spline through its fine samples, the motion itself)."""
    t_hand, angle = variation_hand(params, hand)
    return interpolate_rack(t_hand, rack_of_hand(params, angle))


@dataclass(frozen=True)
class Variation:
    """One way a record can differ from the benchmark's: a hand, a logger (each without its seed), how many
    files a case has (the first ``files`` of the design's file list, each with its own hand and noise seeds) and
    whether the diagnosis fits the handwheel angle its logger logs."""

    name: str
    what: str
    hand: HandVariant
    logger: VariationLogger
    files: int = 1
    uses_angle: bool = False  # diagnosed with the handwheel angle as a second signal (its logger logs one)

    def settings(self, seed: int) -> tuple[HandVariant, VariationLogger]:
        """The hand and logger of this variation with `seed` for the hand's wander and the logger's noise."""
        return replace(self.hand, seed=seed), replace(self.logger, seed=seed)


_H = HandVariant
_L = VariationLogger
# Every variation of the variation benchmark (parksteer.experiments.variations), in a fixed order: a record's seeds
# follow its place here, so that choosing a subset in config/config.yaml does not change any record.
VARIATIONS: tuple[Variation, ...] = (
    Variation("rest_after_stop", "5 % smooth rate variation, 1.5 s at rest after the stop",
              _H(0.05, 0.2, 0.0, "rest", 1.5), _L(100.0, 12, 8)),
    Variation("mid_stroke_end", "record cut 0.2 s before the hand stops, while it slows",
              _H(0.04, 0.25, 0.0, "mid_stroke", cut_before_end_s=0.2), _L(100.0, 12, 8)),
    Variation("pauses", "0.8 s pauses at rest inside the first two strokes",
              _H(0.06, 0.15, 0.8, "rest", 0.5), _L(100.0, 12, 8)),
    Variation("rate_8pc_50Hz", "8 % rate variation, logged at 50 Hz",
              _H(0.08, 0.3, 0.0, "rest", 0.3), _L(50.0, 12, 8)),
    Variation("rate_3pc_200Hz", "3 % rate variation, logged at 200 Hz, cut mid-stroke",
              _H(0.03, 0.1, 0.0, "mid_stroke", cut_before_end_s=0.1), _L(200.0, 12, 8)),
    Variation("rack_8bit_torque_12bit", "8-bit rack beside a 12-bit torque, pauses, cut mid-stroke",
              _H(0.05, 0.2, 0.6, "mid_stroke", cut_before_end_s=0.15), _L(100.0, 8, 12, rack_noise_m=2e-4)),
    Variation("uneven_strokes", "strokes 0.7, 1.3 and 0.85 times their Section 4 durations",
              _H(0.05, 0.2, stroke_scale=(0.7, 1.3, 0.85)), _L(100.0, 12, 8)),
    Variation("lock_overshoot", "past each lock by 5 % of the lock angle and back in 0.8 s",
              _H(0.05, 0.2, overshoot=0.05, overshoot_return_s=0.8), _L(100.0, 12, 8)),
    Variation("rack_16bit_torque_10bit", "16-bit rack beside a 10-bit torque",
              _H(0.05, 0.2), _L(100.0, 16, 10)),
    Variation("anti_alias_1kHz", "logged at 1 kHz behind a second-order 200 Hz anti-alias filter",
              _H(0.05, 0.2), _L(1000.0, 12, 8, anti_alias_hz=200.0)),
    Variation("anti_alias_lag_50Hz", "10 Hz anti-alias filter and a torque channel 10 ms behind the rack, 50 Hz",
              _H(0.05, 0.2), _L(50.0, 12, 8, anti_alias_hz=10.0, torque_lag_s=0.01)),
    Variation("anti_alias_50Hz", "the 10 Hz anti-alias filter alone, 50 Hz",
              _H(0.05, 0.2), _L(50.0, 12, 8, anti_alias_hz=10.0)),
    Variation("lag_10ms_50Hz", "the torque channel 10 ms behind the rack alone, 50 Hz",
              _H(0.05, 0.2), _L(50.0, 12, 8, torque_lag_s=0.01)),
    Variation("three_files", "three files (unladen, part laden, largest spacer), each its own hand",
              _H(0.05, 0.2), _L(100.0, 12, 8), files=3),
    Variation("angle_channel", "a 14-bit handwheel angle beside the 12-bit rack and 8-bit torque, 50 Hz; diagnosed "
              "with the angle as a second signal", _H(0.05, 0.2), _L(50.0, 12, 8, angle_bits=14), uses_angle=True),
)


def variation_by_name(name: str) -> Variation:
    for v in VARIATIONS:
        if v.name == name:
            return v
    raise UsageError(f"unknown variation {name!r} (known: {', '.join(v.name for v in VARIATIONS)})")


def null_variations(seed: int = 0) -> list[tuple[str, HandVariant, VariationLogger]]:
    """The first six variations' settings (name, hand, logger), hand and noise seeded seed + 1 to seed + 6."""
    return [(v.name, *v.settings(seed + i + 1)) for i, v in enumerate(VARIATIONS[:6])]
