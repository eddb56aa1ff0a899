"""Turn a clean model output into a realistic measurement, as the paper's logger would record it.

The car tests were logged through the 8-bit converter of a CIC Litecorder (Section 3). A
synthetic measurement reproduces that chain, in this order:

1. the driver's hand does not turn the wheel at constant speed (:func:`irregular_hand_profile`
   gives the handwheel angle to drive the model with);
2. the logger samples every channel at its sample rate (:func:`resample`);
3. analog noise adds to each channel before conversion (:func:`add_noise`);
4. the converter rounds to one of 2**bits levels over [-full_scale, +full_scale]
   (:func:`quantise`).

Quantisation convention: the 2**bits levels (256 for 8 bits) run from -full_scale to
+full_scale inclusive, so the step is ``2 full_scale / (2**bits - 1)`` (2 full_scale / 255 for
8 bits). The levels are symmetric about zero and zero itself is not a level (it lies half a step
from the two middle levels). A value rounds to the nearest level; a value beyond full scale reads
as the end level, as a saturated converter does. For a signal that is busy on the scale of a
step, the rounding error is uniform over one step, with RMS ``step / sqrt(12)``.

Every setting (full scales, noise RMS, seed, sample rate, bits) is written into the metadata of
the synthetic file, with ``synthetic: true``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import UsageError
from ..parameters import Parameters
from .io import ALLOWED_COLUMNS, Measurement, metadata_text

LITECORDER_BITS = 8  # Section 3: "digitized via an 8-bit ... converter"


def quantisation_step(full_scale: float, bits: int = LITECORDER_BITS) -> float:
    """Converter step: 2 full_scale / (2**bits - 1) (the levels include both ends of the range)."""
    if full_scale <= 0.0:
        raise UsageError(f"full scale must be positive, got {full_scale:g}")
    return 2.0 * full_scale / (2**bits - 1)


def quantise(values: np.ndarray, full_scale: float, bits: int = LITECORDER_BITS) -> np.ndarray:
    """Round `values` to the nearest of 2**bits levels spanning [-full_scale, +full_scale]; saturate beyond."""
    step = quantisation_step(full_scale, bits)
    level = np.clip(np.rint((np.asarray(values, dtype=float) + full_scale) / step), 0, 2**bits - 1)
    return -full_scale + level * step


def add_noise(values: np.ndarray, rms: float, rng: np.random.Generator) -> np.ndarray:
    """`values` plus white Gaussian noise of the given RMS."""
    if rms < 0.0:
        raise UsageError(f"noise RMS must not be negative, got {rms:g}")
    values = np.asarray(values, dtype=float)
    return values + rng.normal(0.0, rms, size=values.shape) if rms > 0.0 else values.copy()


def resample(
    time_s: np.ndarray, columns: Mapping[str, np.ndarray], sample_rate_hz: float
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Sample every column at ``time_s[0] + k / sample_rate_hz`` within the record (linear interpolation).

    Linear interpolation stands for the logger's sample-and-hold at the instant of conversion;
    it is faithful when the clean input is sampled finer than the logger (the model writes
    100 Hz) and the motion is slow beside that (the Hooke joint ripple is about 1 Hz).
    """
    time_s = np.asarray(time_s, dtype=float)
    if sample_rate_hz <= 0.0:
        raise UsageError(f"sample rate must be positive, got {sample_rate_hz:g} Hz")
    if len(time_s) < 2 or (np.diff(time_s) <= 0.0).any():
        raise UsageError("resample: time must be strictly increasing with at least two samples")
    n = int(np.floor((time_s[-1] - time_s[0]) * sample_rate_hz + 1e-9)) + 1
    new_time = time_s[0] + np.arange(n) / sample_rate_hz
    return new_time, {name: np.interp(new_time, time_s, np.asarray(v, dtype=float)) for name, v in columns.items()}


@dataclass(frozen=True)
class LoggerSettings:
    """How the logger records: sample rate, and per column (by name) its full scale and analog noise RMS.

    Full scales and noise RMS are in each column's own unit. Every recorded column except
    ``time_s`` needs both.
    """

    sample_rate_hz: float
    full_scale: Mapping[str, float]
    noise_rms: Mapping[str, float]
    seed: int
    bits: int = LITECORDER_BITS

    def metadata(self) -> dict[str, Any]:
        """The settings as measurement-file metadata (see parksteer.measure.io)."""
        meta: dict[str, Any] = {
            "synthetic": True,
            "bits": self.bits,
            "sample_rate_hz": float(self.sample_rate_hz),
            "noise_seed": int(self.seed),
        }
        for name in ALLOWED_COLUMNS:
            if name in self.full_scale:
                meta[f"full_scale_{name}"] = float(self.full_scale[name])
                meta[f"noise_rms_{name}"] = float(self.noise_rms[name])
        return meta


def degrade(
    time_s: np.ndarray, columns: Mapping[str, np.ndarray], logger: LoggerSettings
) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """Resample, add noise and quantise clean `columns` (sampled at `time_s`) as `logger` would.

    Returns the degraded columns (``time_s`` first) and the metadata recording every setting,
    including ``clipped_samples_<column>`` where noise pushed a sample past full scale. A clean
    signal that itself exceeds full scale is refused: the full scale is then wrongly chosen.
    """
    channels = [name for name in ALLOWED_COLUMNS if name in columns and name != "time_s"]
    unknown = sorted(set(columns) - set(ALLOWED_COLUMNS))
    if unknown:
        raise UsageError(f"degrade: unknown column {unknown[0]!r} (allowed: {', '.join(ALLOWED_COLUMNS)})")
    for name in channels:
        if name not in logger.full_scale or name not in logger.noise_rms:
            raise UsageError(f"degrade: column {name!r} needs a full scale and a noise RMS in the logger settings")
        peak = float(np.max(np.abs(columns[name])))
        if peak > logger.full_scale[name]:
            raise UsageError(
                f"degrade: column {name!r} reaches {peak:g}, beyond the full scale {logger.full_scale[name]:g}"
            )
    new_time, sampled = resample(time_s, {name: columns[name] for name in channels}, logger.sample_rate_hz)
    rng = np.random.default_rng(logger.seed)
    out: dict[str, np.ndarray] = {"time_s": new_time}
    meta = logger.metadata()
    for name in channels:  # canonical column order, so one seed gives one file
        full_scale = logger.full_scale[name]
        noisy = add_noise(sampled[name], logger.noise_rms[name], rng)
        out[name] = quantise(noisy, full_scale, logger.bits)
        clipped = int(np.count_nonzero(np.abs(noisy) > full_scale))
        if clipped:
            meta[f"clipped_samples_{name}"] = clipped
    return out, meta


def synthetic_measurement(
    time_s: np.ndarray,
    columns: Mapping[str, np.ndarray],
    logger: LoggerSettings,
    *,
    case: str,
    surface: str,
    source: str,
    extra_metadata: Mapping[str, Any] | None = None,
) -> Measurement:
    """A :class:`Measurement` made from clean columns by :func:`degrade`, with its provenance in the metadata."""
    degraded, meta = degrade(time_s, columns, logger)
    metadata: dict[str, Any] = {"case": case, "surface": surface, "source": source}
    metadata.update(meta)
    metadata.update(extra_metadata or {})
    return Measurement(path=None, columns=degraded, metadata={k: metadata_text(v) for k, v in metadata.items()})


# --- the driver's hand -------------------------------------------------------------------
#
# A hand profile is a list of pieces (start time s, angle rad, rate rad/s, acceleration rad/s^2):
# a piecewise-quadratic angle, which is what the compiled model takes as its handwheel input
# (parksteer.model.inputs.HandwheelProfile, at most 24 pieces).


def _evaluate_pieces(pieces: tuple[tuple[float, float, float, float], ...], t_s: np.ndarray):
    """Angle and rate of piecewise-quadratic `pieces` at `t_s` (held at the first angle before the start)."""
    t = np.asarray(t_s, dtype=float)
    table = np.array(pieces)
    k = np.clip(np.searchsorted(table[:, 0], t, side="right") - 1, 0, len(table) - 1)
    dt = np.maximum(t - table[k, 0], 0.0)
    angle = table[k, 1] + table[k, 2] * dt + 0.5 * table[k, 3] * dt**2
    rate = np.where(t < table[0, 0], 0.0, table[k, 2] + table[k, 3] * dt)
    return angle, rate


@dataclass(frozen=True)
class HandProfile:
    """Handwheel angle (rad, positive to the right) and its rate (rad/s), sampled against time (s).

    `pieces` holds the same profile exactly, in the model's input form; `anchor_times_s` the
    start, each reversal and the end.
    """

    time_s: np.ndarray
    angle_rad: np.ndarray
    rate_rad_s: np.ndarray
    anchor_times_s: np.ndarray
    pieces: tuple[tuple[float, float, float, float], ...]
    metadata: Mapping[str, Any]

    def angle_rate(self, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Angle and rate at any times (exact, from the pieces)."""
        return _evaluate_pieces(self.pieces, t_s)

    def handwheel_profile(self):
        """The profile as the model's input (parksteer.model.inputs.HandwheelProfile)."""
        from ..model.inputs import HandwheelProfile

        return HandwheelProfile(tuple(self.pieces))


def _anchor_times(params: Parameters) -> np.ndarray:
    p = params.sections["input"]
    return np.cumsum([0.0, p["time_to_right_lock"], p["time_right_to_left_lock"], p["time_left_lock_to_centre"]])


def _sampled(pieces, anchors: np.ndarray, output_dt_s: float, metadata: dict[str, Any]) -> HandProfile:
    if output_dt_s <= 0.0:
        raise UsageError(f"output_dt_s must be positive, got {output_dt_s:g}")
    n = int(round(anchors[-1] / output_dt_s)) + 1
    time_s = np.linspace(anchors[0], anchors[-1], n)
    angle, rate = _evaluate_pieces(pieces, time_s)
    return HandProfile(time_s, angle, rate, anchors, tuple(tuple(float(v) for v in p) for p in pieces), metadata)


def sawtooth_hand_profile(params: Parameters, output_dt_s: float = 0.01) -> HandProfile:
    """The model's own input (parksteer.model.inputs.sawtooth_profile): the Section 4 saw tooth.

    Straight ahead to right lock in 4.5 s, to left lock 9 s later, back to straight ahead at
    18 s, each corner rounded so that the hand stops exactly at each lock at the corner time.
    """
    from ..model.inputs import sawtooth_profile

    meta = {"hand_profile": "saw tooth of Section 4 (parksteer.model.inputs.sawtooth_profile)"}
    return _sampled(sawtooth_profile(params).pieces, _anchor_times(params), output_dt_s, meta)


@dataclass(frozen=True)
class HandVariation:
    """Smooth random variation of the hand speed: a speed factor ``1 + sum_k a_k sin(2 pi f_k t + phi_k)``.

    The `components` frequencies are drawn uniformly from `frequency_range_hz`, the phases
    uniformly, and the amplitudes as random positive shares of `speed_variation`, so the factor
    stays within ``1 +- speed_variation`` (below 1, so that the hand never stops or backs up
    between reversals). The factor is applied at `knots_per_stroke` evenly spaced instants of
    each stroke's cruise (the rate is linear between them), which keeps the profile a short list
    of quadratic pieces the compiled model can take.
    """

    speed_variation: float
    components: int
    frequency_range_hz: tuple[float, float]
    knots_per_stroke: int
    seed: int

    def __post_init__(self) -> None:
        if not 0.0 <= self.speed_variation < 1.0:
            raise UsageError(f"hand speed variation must be in [0, 1), got {self.speed_variation:g}")
        low, high = self.frequency_range_hz
        if not 0.0 < low <= high:
            raise UsageError(f"hand frequency range must be positive and ordered, got {self.frequency_range_hz}")
        if self.components < 1:
            raise UsageError(f"hand variation needs at least one component, got {self.components}")
        if self.knots_per_stroke < 0:
            raise UsageError(f"knots per stroke must not be negative, got {self.knots_per_stroke}")

    def speed_factor(self, t_s: np.ndarray) -> np.ndarray:
        """1 + sum_k a_k sin(2 pi f_k t + phi_k), with the seeded draw."""
        rng = np.random.default_rng(self.seed)
        frequencies = rng.uniform(*self.frequency_range_hz, size=self.components)
        phases = rng.uniform(0.0, 2.0 * np.pi, size=self.components)
        shares = rng.uniform(0.5, 1.0, size=self.components)
        amplitudes = self.speed_variation * shares / shares.sum()
        t = np.asarray(t_s, dtype=float)[..., None]
        return 1.0 + np.sum(amplitudes * np.sin(2.0 * np.pi * frequencies * t + phases), axis=-1)

    def metadata(self) -> dict[str, Any]:
        low, high = self.frequency_range_hz
        return {
            "hand_speed_variation": float(self.speed_variation),
            "hand_components": int(self.components),
            "hand_frequency_range_hz": f"{low:g} to {high:g}",
            "hand_knots_per_stroke": int(self.knots_per_stroke),
            "hand_seed": int(self.seed),
        }


def irregular_hand_profile(params: Parameters, variation: HandVariation, output_dt_s: float = 0.01) -> HandProfile:
    """The Section 4 cycle turned by a hand whose speed wanders, with the same reversal times and lock angles.

    Each stroke (straight ahead to right lock, right to left lock, left lock to straight ahead)
    keeps the saw tooth's structure: from rest, the rate ramps linearly over half the rounding
    time, cruises, and ramps back to rest at the lock at the corner time. In the cruise the rate
    is linear between knots at the ramp ends and `knots_per_stroke` evenly spaced instants
    between them, where it equals c * speed_factor(t); c is set so that the stroke covers exactly
    its travel (the integral is linear in c). So the angle reaches each lock at its corner time and
    is monotone between reversals. With no variation this is the model's saw tooth exactly.
    """
    p = params.sections["input"]
    lock = p["handwheel_lock_angle"]
    anchors = _anchor_times(params)
    travels = (lock, -2.0 * lock, lock)
    half = p["reversal_rounding_time"] / 2.0
    pieces: list[tuple[float, float, float, float]] = []
    angle = 0.0
    for (t0, t1), travel in zip(zip(anchors[:-1], anchors[1:]), travels):
        if t1 - t0 <= 2.0 * half:
            raise UsageError(f"input: a segment of {t1 - t0:g} s is shorter than the rounding time {2 * half:g} s")
        cruise = np.linspace(t0 + half, t1 - half, variation.knots_per_stroke + 2)
        factor = variation.speed_factor(cruise)
        if half > 0.0:  # from rest and back to rest at the lock
            knots = np.concatenate(([t0], cruise, [t1]))
            shape = np.concatenate(([0.0], factor, [0.0]))
        else:  # ideal saw tooth: the rate jumps at the corners
            knots, shape = cruise, factor
        area = float(np.sum(0.5 * (shape[1:] + shape[:-1]) * np.diff(knots)))
        rates = travel / area * shape
        for j in range(len(knots) - 1):
            accel = (rates[j + 1] - rates[j]) / (knots[j + 1] - knots[j])
            pieces.append((float(knots[j]), angle, float(rates[j]), float(accel)))
            angle += 0.5 * (rates[j] + rates[j + 1]) * (knots[j + 1] - knots[j])
    pieces.append((float(anchors[-1]), angle, 0.0, 0.0))
    meta: dict[str, Any] = {"hand_profile": "Section 4 saw tooth with an irregular hand speed"}
    meta.update(variation.metadata())
    return _sampled(tuple(pieces), anchors, output_dt_s, meta)
