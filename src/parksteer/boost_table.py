"""A boost table: the assist against torsion-bar torque as points, one row per vehicle speed, and its slopes.

A vehicle file's ``[assist.boost]`` gives torsion-bar torques T_0 = 0 < T_1 < ... (N m) and, for each vehicle speed
(one row without ``vehicle_speed``), the assist at the point of action A_r,0 = 0 <= A_r,1 <= ... (N m at the column
or pinion, N at the rack). The law is the monotone cubic Hermite interpolant of Fritsch and Carlson (SIAM J. Numer.
Anal. 17, 238, 1980) with SciPy's PchipInterpolator's slopes, odd in the torque, exactly zero in a dead band of two
zero points, a straight line with the last slope beyond the last point; a two-point table is a straight line.

The effect reads the table as scalar quantities of fixed count (the generated code's parameter vector has a fixed
layout): :data:`MAX_POINTS` torques, :data:`MAX_SPEEDS` speeds, an assist and a slope per speed and point, 552
scalars, consecutive in :func:`table_keys` order. A shorter table is padded: torques beyond the last in steps of
:data:`PAD_STEP_NM` on the straight continuation, speeds beyond the last in steps of :data:`PAD_STEP_MPS` with the
last row again. The law itself is in :mod:`parksteer.model.symbolic.effects.assist_common`, one definition for the
generated C and the replay (docs/assist.md, "Boost tables").
"""

from __future__ import annotations

import math

MAX_POINTS = 32  # torque points of a map
MAX_SPEEDS = 8  # vehicle-speed rows
PAD_STEP_NM = 1.0  # spacing of the padded torques beyond a table's last point (the law is a line there)
PAD_STEP_MPS = 10.0  # spacing of the padded speeds beyond a table's last row (the same row again)
KMH = 1.0 / 3.6  # m/s per km/h


class BoostTableError(ValueError):
    """A table that is not a boost curve (one line, what is wrong)."""


def _check_row(torques: list[float], row: list[float], what: str) -> None:
    if len(row) != len(torques):
        raise BoostTableError(f"{what}: {len(row)} values for {len(torques)} torques")
    if row[0] != 0.0:
        raise BoostTableError(f"{what}: the assist at zero torsion-bar torque must be 0, not {row[0]:g}")
    started = False
    for k in range(1, len(row)):
        if started and not row[k] > row[k - 1]:
            raise BoostTableError(f"{what}: the assist must rise strictly beyond the dead band ({row[k - 1]:g} "
                                  f"then {row[k]:g} at {torques[k]:g} N m)")
        if row[k] < row[k - 1]:
            raise BoostTableError(f"{what}: the assist must not fall ({row[k - 1]:g} then {row[k]:g})")
        started = started or row[k] > 0.0
    if not started:
        raise BoostTableError(f"{what}: every assist is 0")


def check_table(torques: list[float], speeds: list[float] | None, rows: list[list[float]]) -> None:
    """Refuse a table that is not a boost curve (:class:`BoostTableError`)."""
    if not 2 <= len(torques) <= MAX_POINTS:
        raise BoostTableError(f"torsion_bar_torque: 2-{MAX_POINTS} points, not {len(torques)}")
    if any(not math.isfinite(t) for t in torques) or torques[0] != 0.0:
        raise BoostTableError("torsion_bar_torque: finite values from 0")
    if any(not b > a for a, b in zip(torques, torques[1:])):
        raise BoostTableError("torsion_bar_torque: the torques must rise strictly")
    count = 1 if speeds is None else len(speeds)
    if speeds is not None:
        if not 1 <= count <= MAX_SPEEDS:
            raise BoostTableError(f"vehicle_speed: 1-{MAX_SPEEDS} speeds, not {count}")
        if speeds[0] < 0.0 or any(not b > a for a, b in zip(speeds, speeds[1:])):
            raise BoostTableError("vehicle_speed: speeds from 0 up, rising strictly")
    if len(rows) != count:
        raise BoostTableError(f"assist: {len(rows)} rows for {count} vehicle speeds")
    for r, row in enumerate(rows):
        if any(not math.isfinite(a) for a in row):
            raise BoostTableError("assist: finite values")
        _check_row(torques, row, "assist" if count == 1 else f"assist row {r + 1}")


def _sign(x: float) -> float:
    return (x > 0) - (x < 0)


def slopes(torques: list[float], row: list[float]) -> list[float]:
    """The Fritsch-Carlson slopes of one row at its points (module docstring), in assist per N m."""
    h = [b - a for a, b in zip(torques, torques[1:])]
    d = [(row[k + 1] - row[k]) / h[k] for k in range(len(h))]
    n = len(row)
    # the point at 0 sees its first segment mirrored: the harmonic mean of d_0 with itself is d_0
    out = [d[0]]
    for k in range(1, n - 1):
        if d[k - 1] * d[k] <= 0.0:
            out.append(0.0)
        else:
            w1, w2 = 2.0 * h[k] + h[k - 1], h[k] + 2.0 * h[k - 1]
            out.append((w1 + w2) / (w1 / d[k - 1] + w2 / d[k]))
    if n == 2:
        out.append(d[0])
    else:  # one-sided three-point formula at the end, kept monotone
        m = ((2.0 * h[-1] + h[-2]) * d[-1] - h[-1] * d[-2]) / (h[-1] + h[-2])
        if _sign(m) != _sign(d[-1]):
            m = 0.0
        elif _sign(d[-1]) != _sign(d[-2]) and abs(m) > 3.0 * abs(d[-1]):
            m = 3.0 * d[-1]
        out.append(m)
    return out


def entries(torques: list[float], speeds_mps: list[float] | None, rows: list[list[float]]) -> dict[str, float]:
    """The effect's scalar quantities of a checked table (module docstring): ``boost_torque_<k>``,
    ``boost_speed_<r>``, ``boost_assist_<r>_<k>``, ``boost_slope_<r>_<k>``."""
    check_table(torques, speeds_mps, rows)
    speeds = list(speeds_mps) if speeds_mps is not None else [0.0]
    n = len(torques)
    all_slopes = [slopes(torques, row) for row in rows]
    padded_t = list(torques) + [torques[-1] + PAD_STEP_NM * j for j in range(1, MAX_POINTS - n + 1)]
    out: dict[str, float] = {f"boost_torque_{k}": float(t) for k, t in enumerate(padded_t)}
    for r in range(MAX_SPEEDS):
        src = min(r, len(rows) - 1)
        row, slope = rows[src], all_slopes[src]
        speed = speeds[r] if r < len(speeds) else speeds[-1] + PAD_STEP_MPS * (r - len(speeds) + 1)
        out[f"boost_speed_{r}"] = float(speed)
        for k in range(MAX_POINTS):
            if k < n:
                value, m = row[k], slope[k]
            else:
                value, m = row[-1] + slope[-1] * (padded_t[k] - torques[-1]), slope[-1]
            out[f"boost_assist_{r}_{k}"] = float(value)
            out[f"boost_slope_{r}_{k}"] = float(m)
    return out


def table_size(values) -> tuple[int, int]:
    """(points, rows) of the table as given, from its padded scalars (`values(key)` gives one, as :func:`entries`
    wrote it): the points before the padding that continues the last point's straight line in steps of
    :data:`PAD_STEP_NM`, and the rows before the last row's repeats. A table whose own last points lie on that line
    at those steps reads as the shorter table: the same law."""
    torques = [values(f"boost_torque_{k}") for k in range(MAX_POINTS)]
    rows = [[values(f"boost_assist_{r}_{k}") for k in range(MAX_POINTS)] for r in range(MAX_SPEEDS)]
    slopes_ = [[values(f"boost_slope_{r}_{k}") for k in range(MAX_POINTS)] for r in range(MAX_SPEEDS)]

    def padded_from(n: int) -> bool:
        last = torques[n - 1]
        return all(torques[j] == last + PAD_STEP_NM * (j - n + 1) and all(
            row[j] == row[n - 1] + slope[n - 1] * (torques[j] - last) and slope[j] == slope[n - 1]
            for row, slope in zip(rows, slopes_)) for j in range(n, MAX_POINTS))

    points = next(n for n in range(2, MAX_POINTS + 1) if padded_from(n))
    count = MAX_SPEEDS
    while count > 1 and rows[count - 1] == rows[count - 2] and slopes_[count - 1] == slopes_[count - 2]:
        count -= 1
    return points, count


def table_keys() -> list[str]:
    """Every scalar key of a table (what :func:`entries` gives), in a fixed order."""
    keys = [f"boost_torque_{k}" for k in range(MAX_POINTS)] + [f"boost_speed_{r}" for r in range(MAX_SPEEDS)]
    for r in range(MAX_SPEEDS):
        keys += [f"boost_assist_{r}_{k}" for k in range(MAX_POINTS)]
        keys += [f"boost_slope_{r}_{k}" for k in range(MAX_POINTS)]
    return keys


def off_keys() -> list[str]:
    """The keys whose zero switches a table off (every assist and slope: the law is then 0 exactly)."""
    return [k for k in table_keys() if k.startswith(("boost_assist_", "boost_slope_"))]
