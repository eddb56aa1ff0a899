"""The boost law's arithmetic on plain numbers, for the assisted replay's inversion (:mod:`.assisted`).

Each function is its namesake of :mod:`parksteer.model.symbolic.effects.assist_common` with the same operations
in the same order, so every bit is the same (tests/model/test_assisted_replay.py checks it), but without the
check of each argument for a sympy expression, whose first call imports sympy: a replay never needs sympy.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ...boost_table import MAX_POINTS, MAX_SPEEDS, table_keys
from ..symbolic.effects.assist_common import _half_numeric


@lru_cache(maxsize=64)
def points_at_speed(table: bytes, speed: bytes) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
    """:func:`~parksteer.model.symbolic.effects.assist_common.table_points` of the table's scalars (table_keys
    order) at the vehicle speed: (torques, assists, slopes); both given by their bytes (so that a -0.0 is not
    taken for a 0.0)."""
    values = dict(zip(table_keys(), (float(v) for v in np.frombuffer(table))))
    knots, assist, slope = table_points_numeric(values.__getitem__, float(np.frombuffer(speed)[0]))
    return tuple(float(v) for v in knots), tuple(float(v) for v in assist), tuple(float(v) for v in slope)


def table_points_numeric(value, speed: float):
    """:func:`~parksteer.model.symbolic.effects.assist_common.table_points` on numbers (its selection of the first
    branch whose condition holds, without the check for a sympy expression, whose first call imports sympy): the
    same operations."""

    def at_speed(speeds, row_values):
        branches = [(speed < speeds[0], row_values[0])]
        for r in range(len(speeds) - 1):
            fraction = (speed - speeds[r]) / (speeds[r + 1] - speeds[r])
            branches.append((speed < speeds[r + 1], row_values[r] + fraction * (row_values[r + 1] - row_values[r])))
        return next((v for condition, v in branches if condition), row_values[-1])

    knots = [value(f"boost_torque_{k}") for k in range(MAX_POINTS)]
    speeds = [value(f"boost_speed_{r}") for r in range(MAX_SPEEDS)]
    assist = [at_speed(speeds, [value(f"boost_assist_{r}_{k}") for r in range(MAX_SPEEDS)]) for k in range(MAX_POINTS)]
    slope = [at_speed(speeds, [value(f"boost_slope_{r}_{k}") for r in range(MAX_SPEEDS)]) for k in range(MAX_POINTS)]
    return knots, assist, slope


def table_law_numeric(torque: np.ndarray, points) -> np.ndarray:
    """:func:`~parksteer.model.symbolic.effects.assist_common.table_law` at `torque` on a table read at one speed
    (`points`: :func:`points_at_speed`, all numbers): its numeric branch, the same operations, without the check
    of every point for a symbol at each of the inversion's calls."""
    knots, assist, slope = points
    magnitude = _half_numeric(np.abs(torque), knots, assist, slope)
    return np.where(torque >= 0, magnitude, -magnitude)


def ramp(z, width):
    """:func:`~parksteer.model.symbolic.effects.assist_common.ramp` on numbers (np.sqrt, not the sympy-aware
    square root, whose first call imports sympy): the same operations."""
    return (z + np.sqrt(z * z + width * width)) / 2


def deadband(x, band, width):
    """:func:`~parksteer.model.symbolic.effects.assist_common.deadband` on numbers: the same operations."""
    return ramp(x - band, width) - ramp(-x - band, width)


def clamp(y, limit, width):
    """:func:`~parksteer.model.symbolic.effects.assist_common.clamp` on numbers: the same operations."""
    return y - ramp(y - limit, width) + ramp(-y - limit, width)


def directional_efficiency(motor, direction, forward, back, width):
    """:func:`~parksteer.model.symbolic.effects.assist_common.directional_efficiency` on numbers, its
    tanh(sharpness speed) given (`direction`): the same operations."""
    s = direction * motor / np.sqrt(motor * motor + width * width)
    return 1 + s * ((forward - 1) * (1 + s) / 2 + (1 - 1 / back) * (1 - s) / 2)


def table_segments(points):
    """The table's Hermite segments read once (`points`: :func:`points_at_speed`): the inner knots (the first k
    with x < knots[k + 1] is the segment), each segment's start t0, width h = t1 - t0, end values a0, a1 and h m0,
    h m1 (the products :func:`hermite_at` takes, as _hermite forms them), and the line beyond the last point."""
    knots, assist, slope = (np.asarray(v, dtype=float) for v in points)
    width = knots[1:] - knots[:-1]
    return (knots[1:], knots[:-1], width, assist[:-1], assist[1:], width * slope[:-1], width * slope[1:],
            knots[-1], assist[-1], slope[-1])


def hermite_at(x, t0, h, a0, a1, h_m0, h_m1):
    """:func:`~parksteer.model.symbolic.effects.assist_common._hermite` with h = t1 - t0, h m0 and h m1 formed
    beforehand: the same operations in the same order (2 s and s s each formed once, as the same products)."""
    s = (x - t0) / h
    r = 1 - s
    two_s = 2 * s
    ss = s * s
    return a0 * ((1 + two_s) * r * r) + h_m0 * (s * r * r) + a1 * (ss * (3 - two_s)) + h_m1 * (ss * (s - 1))


def table_law_segments(torque: np.ndarray, segments) -> np.ndarray:
    """:func:`table_law_numeric` on the table's segments read once (:func:`table_segments`): the same
    operations (:func:`~parksteer.model.symbolic.effects.assist_common._half_numeric`'s)."""
    upper, t0, h, a0, a1, h_m0, h_m1, last_knot, last_assist, last_slope = segments
    x = np.abs(torque)
    k = np.searchsorted(upper, x, side="right")  # len(upper) beyond the last point
    beyond = k == len(upper)
    inner = np.minimum(k, len(upper) - 1)
    magnitude = hermite_at(x, t0[inner], h[inner], a0[inner], a1[inner], h_m0[inner], h_m1[inner])
    if beyond.any():
        magnitude = np.where(beyond, last_assist + last_slope * (x - last_knot), magnitude)
    return np.where(torque >= 0, magnitude, -magnitude)
