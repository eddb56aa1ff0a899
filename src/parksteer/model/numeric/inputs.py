"""The handwheel drive of the model: the prescribed handwheel angle (paper section 4).

The paper's input is a saw tooth of handwheel angle: straight ahead to full right lock in
4.5 s, to full left lock 9 s later, back to straight ahead at 18 s. Its corners are rounded
here: over half of ``input.reversal_rounding_time`` on each side of a corner the rate
changes linearly (constant angular acceleration), so the handwheel stops exactly at each
lock at the corner time and the start and stop are from and to rest. An ideal saw tooth
changes the rate instantly, and against the 200 N m s/rad column damping that gives a
torque spike of about 1 kN m that no measurement shows. The constant rates are raised a
little so that each lock is still reached at the paper's times. A prescribed rack travel is any rack
motion (:mod:`parksteer.model.numeric.prescribed`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import UsageError


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
