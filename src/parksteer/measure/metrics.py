"""How far a model is from a measurement, overall and in each phase, beside the noise floor of the data.

The residual is ``measured - model`` (N m) on the measurement's own time samples (the model interpolated onto them):
positive is torque the model is missing. For each phase of the cycle (:mod:`parksteer.measure.phases`) and overall:
the number of samples, the mean (bias), the RMS and the peak absolute residual. The noise floor is the RMS residual a
perfect model would still show: the quantisation error ``step / sqrt(12)`` and the analog noise, root sum of
squares, the analog noise estimated from the signal's own second differences, clipped of their sharp features; with
less analog noise than about half a step the floor is the quantisation error. The estimator and why it holds:
docs/measurement.md, "The error against the noise floor".
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from .io import Measurement
from .phases import PHASES, CyclePhases, find_phases
from ..names import TORQUE

CLIP_RMS = 4.0


@dataclass(frozen=True)
class ErrorStats:
    """Residual statistics over a set of samples (in the channel's unit)."""

    samples: int
    mean: float
    rms: float
    peak: float  # largest absolute residual
    peak_time_s: float

    def as_dict(self) -> dict:
        return {
            "samples": self.samples,
            "mean": self.mean,
            "rms": self.rms,
            "peak": self.peak,
            "peak_time_s": self.peak_time_s,
        }


def error_stats(time_s: np.ndarray, residual: np.ndarray) -> ErrorStats:
    """Bias, RMS and peak absolute value of `residual`; NaN statistics for no samples."""
    residual = np.asarray(residual, dtype=float)
    if residual.size == 0:
        return ErrorStats(0, math.nan, math.nan, math.nan, math.nan)
    worst = int(np.argmax(np.abs(residual)))
    return ErrorStats(
        samples=int(residual.size),
        mean=float(np.mean(residual)),
        rms=float(np.sqrt(np.mean(residual**2))),
        peak=float(abs(residual[worst])),
        peak_time_s=float(np.asarray(time_s)[worst]),
    )


def quantisation_noise_rms(step: float) -> float:
    """RMS of a rounding error uniform over one step: step / sqrt(12)."""
    return step / math.sqrt(12.0)


def estimate_noise_rms(values: np.ndarray, mask: np.ndarray | None = None) -> float:
    """RMS of the white noise on `values`, from the clipped RMS of its second differences / sqrt(6).

    With `mask`, only second differences whose three samples all lie in the mask are used.
    """
    y = np.asarray(values, dtype=float)
    d2 = y[2:] - 2.0 * y[1:-1] + y[:-2]
    if mask is not None:
        m = np.asarray(mask, dtype=bool)
        d2 = d2[m[2:] & m[1:-1] & m[:-2]]
    if d2.size < 10:
        raise UsageError(f"noise estimate needs at least 10 second differences, got {d2.size}")
    kept = np.ones(d2.size, dtype=bool)
    for _ in range(50):
        rms = math.sqrt(float(np.mean(d2[kept] ** 2)))
        new = np.abs(d2) <= CLIP_RMS * rms
        if np.array_equal(new, kept) or not new.any():
            break
        kept = new
    return rms / math.sqrt(6.0)


@dataclass(frozen=True)
class NoiseFloor:
    """What the data allow: quantisation and analog noise (RMS), and their root sum of squares."""

    quantisation_step: float
    quantisation_rms: float
    analog_rms: float
    total_rms: float

    def as_dict(self) -> dict:
        return {
            "quantisation_step": self.quantisation_step,
            "quantisation_rms": self.quantisation_rms,
            "analog_rms": self.analog_rms,
            "total_rms": self.total_rms,
        }


def noise_floor(values: np.ndarray, quantisation_step: float = 0.0, mask: np.ndarray | None = None) -> NoiseFloor:
    """Split the noise on measured `values` into quantisation (from the known step) and analog parts."""
    if quantisation_step < 0.0:
        raise UsageError(f"quantisation step must not be negative, got {quantisation_step:g}")
    q_rms = quantisation_noise_rms(quantisation_step)
    total = estimate_noise_rms(values, mask)
    analog = math.sqrt(max(total**2 - q_rms**2, 0.0))
    return NoiseFloor(quantisation_step, q_rms, analog, pm.hypot(q_rms, analog))


@dataclass(frozen=True)
class Comparison:
    """A model against a measurement on the measurement's samples; residual = measured - model."""

    channel: str
    time_s: np.ndarray
    measured: np.ndarray
    model: np.ndarray
    residual: np.ndarray
    overall: ErrorStats
    by_phase: dict[str, ErrorStats]
    noise_floor: NoiseFloor
    phases: CyclePhases | None = field(default=None, repr=False)

    def summary(self) -> dict:
        """Key numbers (for JSON): overall and per-phase statistics, the noise floor, and their ratio."""
        return {
            "channel": self.channel,
            "overall": self.overall.as_dict(),
            "by_phase": {name: stats.as_dict() for name, stats in self.by_phase.items()},
            "noise_floor": self.noise_floor.as_dict(),
            "rms_over_noise_floor": self.overall.rms / self.noise_floor.total_rms
            if self.noise_floor.total_rms > 0.0
            else math.inf,
        }


def compare(
    time_s: np.ndarray,
    measured: np.ndarray,
    model: np.ndarray,
    *,
    phases: CyclePhases | None = None,
    quantisation_step: float = 0.0,
    channel: str = TORQUE,
) -> Comparison:
    """Residual statistics of `model` against `measured`, both on `time_s`, overall and per phase of `phases`."""
    t = np.asarray(time_s, dtype=float)
    measured = np.asarray(measured, dtype=float)
    model = np.asarray(model, dtype=float)
    if not (t.shape == measured.shape == model.shape) or t.ndim != 1:
        raise UsageError(
            f"compare: time, measured and model need one shape, got {t.shape}, {measured.shape}, {model.shape}"
        )
    residual = measured - model
    by_phase: dict[str, ErrorStats] = {}
    if phases is not None:
        if len(phases.labels) != len(t):
            raise UsageError(f"compare: phases label {len(phases.labels)} samples, the data have {len(t)}")
        for name in PHASES:
            mask = phases.labels == name
            if mask.any():
                by_phase[name] = error_stats(t[mask], residual[mask])
    return Comparison(
        channel=channel,
        time_s=t,
        measured=measured,
        model=model,
        residual=residual,
        overall=error_stats(t, residual),
        by_phase=by_phase,
        noise_floor=noise_floor(measured, quantisation_step),
        phases=phases,
    )


def interpolate_onto(time_s: np.ndarray, source_time_s: np.ndarray, source_values: np.ndarray) -> np.ndarray:
    """`source_values` linearly interpolated at `time_s`, which must lie within the source's time span."""
    t = np.asarray(time_s, dtype=float)
    src_t = np.asarray(source_time_s, dtype=float)
    tolerance = 1e-9 * max(1.0, float(np.max(np.abs(src_t))))
    if t[0] < src_t[0] - tolerance or t[-1] > src_t[-1] + tolerance:
        raise UsageError(
            f"the model covers {src_t[0]:g} to {src_t[-1]:g} s but the measurement runs from "
            f"{t[0]:g} to {t[-1]:g} s; simulate the whole measured time"
        )
    return np.interp(t, src_t, np.asarray(source_values, dtype=float))


def compare_measurement(
    measurement: Measurement,
    model_columns: Mapping[str, np.ndarray],
    channel: str = TORQUE,
    phases: CyclePhases | None = None,
) -> Comparison:
    """Compare a model output (columns with ``time_s`` and `channel`) with a measurement's `channel`.

    The phases come from the measurement (its rack, its torque, its surface) unless given; the
    quantisation step comes from the file's ``full_scale_<channel>`` and ``bits`` (0 if absent).
    """
    if channel not in measurement.columns:
        raise UsageError(f"{measurement.path}: the measurement has no column {channel!r}")
    for name in ("time_s", channel):
        if name not in model_columns:
            raise UsageError(f"the model output has no column {name!r}")
    model = interpolate_onto(measurement.time_s, model_columns["time_s"], model_columns[channel])
    if phases is None:
        phases = find_phases(
            measurement.time_s, measurement.rack_m, measurement.handwheel_torque_Nm, surface=measurement.surface
        )
    return compare(
        measurement.time_s,
        measurement.columns[channel],
        model,
        phases=phases,
        quantisation_step=measurement.quantisation_step(channel),
        channel=channel,
    )
