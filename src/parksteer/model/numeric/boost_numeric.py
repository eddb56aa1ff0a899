"""The boost law's arithmetic on plain numbers, for the assisted replay's motor torque and assist (:mod:`.assisted`;
its inversion is compiled C, :mod:`.torsion_bar`) and the assist's identification of a boost map.

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
