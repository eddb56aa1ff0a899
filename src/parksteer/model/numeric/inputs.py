"""Drives of the model: the prescribed handwheel angle (paper section 4) or a prescribed rack travel.

The paper's input is a saw tooth of handwheel angle: straight ahead to full right lock in
4.5 s, to full left lock 9 s later, back to straight ahead at 18 s. Its corners are rounded
here: over half of ``input.reversal_rounding_time`` on each side of a corner the rate
changes linearly (constant angular acceleration), so the handwheel stops exactly at each
lock at the corner time and the start and stop are from and to rest. An ideal saw tooth
changes the rate instantly, and against the 200 N m s/rad column damping that gives a
torque spike of about 1 kN m that no measurement shows. The constant rates are raised a
little so that each lock is still reached at the paper's times.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from ...errors import UsageError
from ...tables import read_csv


@dataclass(frozen=True)
class HandwheelProfile:
    """A piecewise-quadratic handwheel angle: pieces of (start time s, angle rad, rate rad/s, accel rad/s^2)."""

    pieces: tuple[tuple[float, float, float, float], ...]

    @property
    def end_time_s(self) -> float:
        return self.pieces[-1][0]

    def angle_rate(self, t_s) -> tuple[np.ndarray, np.ndarray]:
        """Angle (rad) and rate (rad/s) at times `t_s`; constant before the first and after the last piece."""
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        starts = np.array([p[0] for p in self.pieces])
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(starts) - 1)
        table = np.array(self.pieces)
        dt = t - table[k, 0]
        before = dt < 0
        dt = np.where(before, 0.0, dt)
        angle = table[k, 1] + table[k, 2] * dt + 0.5 * table[k, 3] * dt**2
        rate = np.where(before, 0.0, table[k, 2] + table[k, 3] * dt)
        return angle, rate

    def table(self, max_pieces: int) -> np.ndarray:
        """The flat table the generated C code reads: count, then four numbers per piece."""
        if len(self.pieces) > max_pieces:
            raise ValueError(f"input has {len(self.pieces)} pieces, the compiled model takes at most {max_pieces}")
        out = np.zeros(1 + 4 * max_pieces)
        out[0] = len(self.pieces)
        out[1 : 1 + 4 * len(self.pieces)] = np.ravel(self.pieces)
        return out


def profile_from_rates(segments: list[tuple[float, float]]) -> HandwheelProfile:
    """Integrate (duration s, constant acceleration rad/s^2) segments from rest at angle 0, t = 0."""
    pieces, t, angle, rate = [], 0.0, 0.0, 0.0
    for duration, accel in segments:
        if duration <= 0.0:
            continue
        pieces.append((t, angle, rate, accel))
        angle += rate * duration + 0.5 * accel * duration**2
        rate += accel * duration
        t += duration
    pieces.append((t, angle, rate, 0.0))
    return HandwheelProfile(tuple(pieces))


def sawtooth_profile(params) -> HandwheelProfile:
    """The paper's lock-to-lock cycle with rounded corners (see the module docstring)."""
    lock = params["input.handwheel_lock_angle"]
    durations = [params["input.time_to_right_lock"], params["input.time_right_to_left_lock"],
                 params["input.time_left_lock_to_centre"]]
    half = params["input.reversal_rounding_time"] / 2.0
    travel = [lock, -2.0 * lock, lock]
    segments: list[tuple[float, float]] = []
    for duration, angle in zip(durations, travel):
        if duration <= 2.0 * half:
            raise UsageError(f"input: a segment of {duration:g} s is shorter than the rounding time {2 * half:g} s")
        # Ramp over `half`, cruise, ramp back to rest over `half`: travel = rate * (duration - half).
        rate = angle / (duration - half)
        if half > 0.0:
            segments += [(half, rate / half), (duration - 2.0 * half, 0.0), (half, -rate / half)]
        else:
            segments += [(duration, 0.0)]
    if half > 0.0:
        return profile_from_rates(segments)
    # Ideal saw tooth: the rate jumps at the corners.
    pieces, t, angle = [], 0.0, 0.0
    for duration, travel_rad in zip(durations, travel):
        pieces.append((t, angle, travel_rad / duration, 0.0))
        t += duration
        angle += travel_rad
    pieces.append((t, angle, 0.0, 0.0))
    return HandwheelProfile(tuple(pieces))


@dataclass(frozen=True)
class RackDrive:
    """A prescribed rack displacement: a cubic spline through measured (time, rack) samples."""

    spline: CubicSpline
    start_s: float
    end_s: float

    def position_speed_accel(self, t_s):
        t = np.clip(np.asarray(t_s, dtype=float), self.start_s, self.end_s)
        return self.spline(t), self.spline(t, 1), self.spline(t, 2)


def rack_drive_from_arrays(time_s, rack_m) -> RackDrive:
    time_s = np.asarray(time_s, dtype=float)
    rack_m = np.asarray(rack_m, dtype=float)
    if time_s.ndim != 1 or len(time_s) < 4 or len(time_s) != len(rack_m):
        raise UsageError("rack drive: needs at least 4 samples of time_s and rack_m")
    if not (np.all(np.isfinite(time_s)) and np.all(np.isfinite(rack_m))) or np.any(np.diff(time_s) <= 0):
        raise UsageError("rack drive: time_s must be finite and strictly increasing, rack_m finite")
    # Clamped ends: the rack starts and ends at rest.
    return RackDrive(CubicSpline(time_s, rack_m), float(time_s[0]), float(time_s[-1]))


def rack_drive_from_csv(path: str | Path) -> RackDrive:
    """Read a measurement's time_s and rack_m columns (a CSV as written by parksteer.tables.write_csv)."""
    try:
        columns, _ = read_csv(path)
    except (OSError, ValueError, UnicodeDecodeError, IndexError) as exc:
        raise UsageError(f"{path}: cannot read rack drive ({exc})") from None
    for name in ("time_s", "rack_m"):
        if name not in columns or columns[name].dtype == object:
            raise UsageError(f"{path}: needs a numeric column {name!r}")
    return rack_drive_from_arrays(columns["time_s"], columns["rack_m"])
