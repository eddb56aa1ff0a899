"""Turn a clean model output into a realistic measurement, as the paper's logger would record it.

The car tests were logged through the 8-bit converter of a CIC Litecorder (Section 3). A
synthetic measurement reproduces that chain, in this order:

1. the driver's hand does not turn the wheel at constant speed (:func:`irregular_hand_profile`
   gives the handwheel angle to drive the model with);
2. the logger samples every channel at its sample rate (:func:`resample`);
3. analog noise adds to each channel before conversion (:func:`parksteer.measure.converter.add_noise`);
4. the converter rounds to one of 2**bits levels over [-full_scale, +full_scale]
   (:func:`parksteer.measure.converter.quantise`).

The converter's levels and rounding are :mod:`parksteer.measure.converter`'s.

Every setting (full scales, noise RMS, seed, sample rate, bits) is written into the metadata of
the synthetic file, with ``synthetic: true``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import UsageError
from ..measure.converter import LITECORDER_BITS, add_noise, quantise
from ..measure.io import ALLOWED_COLUMNS, Measurement, metadata_text

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
    # a channel with a converter of its own (e.g. a 14-bit handwheel angle sensor beside 8-bit torque): its bits
    column_bits: Mapping[str, int] = field(default_factory=dict)

    def bits_of(self, column: str) -> int:
        return int(self.column_bits.get(column, self.bits))

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
                if name in self.column_bits:
                    meta[f"bits_{name}"] = int(self.column_bits[name])
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
        out[name] = quantise(noisy, full_scale, logger.bits_of(name))
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
