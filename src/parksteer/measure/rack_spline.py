"""A rack motion as a piecewise cubic (:class:`RackSpline`): evaluated, differentiated and added, and the
interpolating spline through a record's samples (:func:`interpolate_rack`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .. import portable as pm
from ..errors import UsageError

if TYPE_CHECKING:
    from scipy.interpolate import PPoly
# scipy.interpolate is imported where a spline is made: the workflow's Snakefile imports this module (through the
# synthetic data designs), and scipy.interpolate is half a second of every Snakemake start.


@dataclass(frozen=True, eq=False)
class RackSpline:
    """A rack motion as a piecewise polynomial: position (m), speed (m/s), acceleration (m/s^2) at any time.

    ``breaks`` (s, increasing) and ``coefficients`` (highest power first, one column per piece,
    as :class:`scipy.interpolate.PPoly`). Outside the record the rack is held at its end position
    (speed and acceleration of the end sample).
    """

    breaks: np.ndarray
    coefficients: np.ndarray

    @classmethod
    def from_ppoly(cls, pp: PPoly) -> RackSpline:
        keep = np.diff(pp.x) > 0.0  # a spline's PPoly repeats its end knots as empty pieces
        return cls(np.concatenate([pp.x[:-1][keep], [pp.x[-1]]]), np.asarray(pp.c[:, keep], dtype=float))

    @property
    def start_s(self) -> float:
        return float(self.breaks[0])

    @property
    def end_s(self) -> float:
        return float(self.breaks[-1])

    def evaluate(self, t_s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position (m), speed (m/s) and acceleration (m/s^2) at `t_s` (held at the ends outside the record)."""
        t = np.clip(np.asarray(t_s, dtype=float), self.start_s, self.end_s)
        x = self.breaks
        k = np.clip(np.searchsorted(x, t, side="right") - 1, 0, len(x) - 2)
        h = t - x[k]
        c = self.coefficients[:, k]
        degree = len(self.coefficients) - 1
        position, speed, accel = np.zeros_like(h), np.zeros_like(h), np.zeros_like(h)
        for i in range(degree + 1):  # Horner, with the derivatives alongside
            accel = accel * h + 2.0 * speed
            speed = speed * h + position
            position = position * h + c[i]
        return position, speed, accel

    def plus(self, other: RackSpline) -> RackSpline:
        """This motion plus `other` (both cubic), on the union of their breaks, over this one's span."""
        if len(self.coefficients) != 4 or len(other.coefficients) != 4:
            raise ValueError("RackSpline.plus adds cubic splines only")
        breaks = np.union1d(self.breaks, other.breaks)
        breaks = breaks[(breaks >= self.start_s) & (breaks <= self.end_s)]
        starts = breaks[:-1]
        cubic = np.zeros(len(starts))
        for spline in (self, other):  # each piece's cubic coefficient, from the piece the start lies in
            k = np.clip(np.searchsorted(spline.breaks, starts, side="right") - 1, 0, len(spline.breaks) - 2)
            inside = (starts >= spline.start_s) & (starts < spline.end_s)
            cubic += np.where(inside, spline.coefficients[0, k], 0.0)
        position, speed, accel = (a + b for a, b in zip(self.evaluate(starts), other.evaluate(starts)))
        return RackSpline(breaks, np.vstack([cubic, 0.5 * accel, speed, position]))


def interpolate_rack(time_s, rack_m) -> RackSpline:
    """The cubic spline through every sample (not-a-knot ends): for samples of a smooth motion, not logged data.

    On logged data it replays every converter step (see the module docstring); :func:`smooth_rack` is the
    replay of a measurement.
    """
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(rack_m, dtype=float)
    if t.ndim != 1 or len(t) < 4 or len(t) != len(x):
        raise UsageError("rack spline: needs at least 4 samples of time_s and rack_m")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x))) or np.any(np.diff(t) <= 0):
        raise UsageError("rack spline: time_s must be finite and strictly increasing, rack_m finite")
    return _not_a_knot_spline(t, x)


def _not_a_knot_spline(t: np.ndarray, x: np.ndarray) -> RackSpline:
    """The interpolating cubic spline with not-a-knot ends (scipy.interpolate.CubicSpline's default), its slopes
    from the tridiagonal system written out and solved by :func:`parksteer.portable.solve_tridiagonal`."""
    dt = np.diff(t)
    slope = np.diff(x) / dt
    n = len(t)
    diagonal, lower, upper, rhs = np.empty(n), np.empty(n - 1), np.empty(n - 1), np.empty(n)
    # interior: continuity of the second derivative at each knot
    diagonal[1:-1] = 2.0 * (dt[:-1] + dt[1:])
    lower[:-1] = dt[1:]
    upper[1:] = dt[:-1]
    rhs[1:-1] = 3.0 * (dt[1:] * slope[:-1] + dt[:-1] * slope[1:])
    # not-a-knot: the third derivative continuous at the second and the last-but-one knots
    span = t[2] - t[0]
    diagonal[0], upper[0] = dt[1], span
    rhs[0] = ((dt[0] + 2.0 * span) * dt[1] * slope[0] + dt[0] * dt[0] * slope[1]) / span
    span = t[-1] - t[-3]
    diagonal[-1], lower[-1] = dt[-2], span
    rhs[-1] = (dt[-1] * dt[-1] * slope[-2] + (2.0 * span + dt[-1]) * dt[-2] * slope[-1]) / span
    s = pm.solve_tridiagonal(lower, diagonal, upper, rhs)
    # Hermite cubic on each piece, highest power first
    excess = (s[:-1] + s[1:] - 2.0 * slope) / dt
    coefficients = np.vstack([excess / dt, (slope - s[:-1]) / dt - excess, s[:-1], x[:-1]])
    return RackSpline(t.copy(), coefficients)
