"""A measured rack as a motion the model can follow: position, speed and acceleration at any time.

Why smooth: the rack of an 8-bit logger moves in steps of 2 full_scale / 255 (0.8 mm for a
+-0.1 m range). Replayed as it stands (through an interpolating spline, :func:`interpolate_rack`),
every step is a jump in position, so the rack's speed and acceleration (which a prescribed-rack
model differentiates) are spikes, and the rack friction's tanh flips at every step: the replayed
torque is then wrong by several N m. The rack is therefore replaced by a least-squares cubic
spline (:func:`smooth_rack`) with evenly spaced knots and one knot at each reversal. The spacing
is the largest that still fits the rack to within its own noise (estimated, as for the torque,
from second differences; the discrepancy principle), inside a range the cycle sets: closer knots
follow the noise, and the spline's speed then crosses zero where the rack never reverses, which
flips the rack friction; wider ones cannot follow the hand through a reversal. Each end of the
record is held at rest unless the data contradict it, so that a record starting from rest gets
no spurious starting speed.

What smoothing cannot fix: near a reversal the rack speed passes through zero, and the rack
friction force, F tanh(beta v), turns over within about 1 mm/s of it (a few hundredths of a
second). The rack data fix the turning time only to a few hundredths of a second, so a replay is
least certain there. :meth:`SmoothedRack.perturbed` and :meth:`SmoothedRack.resmoothed` give
other racks the data allow as well; :mod:`parksteer.diagnose.problem` replays them to measure
that uncertainty at every sample. Nor do the data fix how the rack eases into and out of a turn: within a tenth
of a second of it the rack moves by less than a converter step or its noise, so there the spline's speed follows
its knots, and every spacing that passes the discrepancy test (``SmoothedRack.passing_spacings_s``) is as
consistent with the data as the one kept; the replay's uncertainty smooths at each of them
(:func:`parksteer.diagnose.ensemble.ensemble_sources`). A rack rounded more coarsely than its noise (one derived
from a bus's handwheel angle) hides a motion of up to a step wherever it is slow; :func:`rounding_draw` adds one.

Every rack here is a :class:`RackSpline` (a piecewise polynomial: ``breaks``, ``coefficients``, ``start_s`` and
``end_s``), the rack motion :func:`parksteer.model.numeric.prescribed.solve` takes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from typing import TYPE_CHECKING

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from .metrics import estimate_noise_rms
from .phases import local_linear_fit

if TYPE_CHECKING:
    from scipy.interpolate import PPoly
# scipy.interpolate is imported where a spline is made: the workflow's Snakefile imports this module (through the
# synthetic data designs), and scipy.interpolate is half a second of every Snakemake start.

# --- smoothing settings (settings of the method, not properties of the car; each with its reason) ---------------
# The spacing of the knots is the largest whose fit residual (per degree of freedom) is within this factor of the
# rack's own noise (estimated from its second differences): the discrepancy principle, so the spline follows the
# motion but not the noise or the converter's steps.
RACK_DISCREPANCY_FACTOR = 1.05  # 1
# Knot spacings tried, s: never closer than this many samples (a spline needs data in every interval) ...
RACK_MIN_SAMPLES_PER_KNOT = 4  # 1
# ... and within this range. Below 0.15 s the spline starts to follow the noise, and its speed then crosses zero
# where the rack does not move backwards, which flips the rack friction; above 0.4 s it cannot follow a reversal
# of the hand (the paper's cycle turns within about 0.4 s). The rack noise estimate from second differences of
# 8-bit data is itself uncertain by a few per cent, too little to choose reliably between neighbouring spacings,
# so the range does most of the work.
RACK_KNOT_SPACING_RANGE_S = (0.15, 0.4)
RACK_KNOT_SPACING_STEP = 1.15  # 1, ratio between spacings tried
# Reversals (where the spline gets a knot) are found from the speed of a local straight-line fit over this
# window, as parksteer.measure.phases finds strokes.
RACK_TURN_WINDOW_S = 0.5
# Each end of the record is held at rest unless that raises the fit's sum of squares by more than this many
# noise variances (see _lsq_fit).
RACK_REST_TEST_CHI2 = 25.0  # 1
# A record cut while the hand is still slowing (about 1 mm/s, where the rack friction's tanh is already near its
# full value) can pass that test, and holding the end at rest then drops the rack friction from the last samples
# (3 to 5 N m): the data cannot tell. The replay's uncertainty (parksteer.diagnose.problem) therefore replays
# racks smoothed with the ends free as well as held (smooth_rack(hold_rest=False)).
# The same holds at the edges of a pause (RACK_REST_MIN_S below): where the hand comes to rest the rack speed
# passes through the friction's tanh over a few hundredths of a second that the data do not fix, so the free
# alternative there is replayed too.
RACK_REST_SLOPE_SE = 3.0  # 1
# A pause of the hand: a stretch of at least RACK_REST_MIN_S where a quadratic fitted to the rack over a window of
# that length, centred on each sample, has speed and acceleration both within RACK_REST_SLOPE_SE standard errors
# of zero. There the spline is held constant (its B-spline coefficients over the stretch equal, with a knot at
# each end of it): left free, a spline with knots a fifth of a second apart rings after the stop (a few tenths
# of a mm/s either way), and the rack friction flips sign with it, which the data at rest never do. The window
# is the cycle's reversal time (about 0.4 s), so that a reversal without a pause (a parabola, not a line) fails.
RACK_REST_MIN_S = 0.4


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


@dataclass(frozen=True, eq=False)
class SmoothedRack(RackSpline):
    """A measured rack as a least-squares cubic spline, with its fit.

    ``knots`` and ``bspline`` are the least-squares B-spline; ``coefficient_covariance`` is the
    covariance of its coefficients for white rack noise of RMS ``noise_rms_m`` (for
    :meth:`perturbed`).
    """

    knots: np.ndarray = None
    bspline: np.ndarray = None
    coefficient_covariance: np.ndarray = None
    knot_spacing_s: float = 0.0
    fit_rms_m: float = 0.0
    noise_rms_m: float = 0.0
    held_at_rest: tuple[bool, bool] = (False, False)  # (start, end) of the record
    turning_times_s: tuple[float, ...] = ()  # where the rack reverses (each has a knot)
    rest_intervals_s: tuple[tuple[float, float], ...] = ()  # pauses of the hand, where the spline is constant
    # every spacing tried that passed the discrepancy test, coarsest (the chosen one) first; only the chosen one
    # when the spacing was given (smooth_rack)
    passing_spacings_s: tuple[float, ...] = ()
    rest_resolution_m: float = 0.0  # the rounding the rests were tested with (smooth_rack's rest_resolution_m)

    @classmethod
    def from_bspline(cls, knots, bspline, covariance, knot_spacing_s, fit_rms_m, noise_rms_m,
                     held_at_rest=(False, False), turning_times_s=(), rest_intervals_s=(),
                     passing_spacings_s=(), rest_resolution_m=0.0) -> SmoothedRack:
        from scipy.interpolate import BSpline, PPoly

        piecewise = RackSpline.from_ppoly(PPoly.from_spline(BSpline(knots, bspline, 3, extrapolate=False)))
        return cls(piecewise.breaks, piecewise.coefficients, knots, bspline, covariance, float(knot_spacing_s),
                   float(fit_rms_m), float(noise_rms_m), tuple(held_at_rest), tuple(turning_times_s),
                   tuple(rest_intervals_s), tuple(float(x) for x in passing_spacings_s) or (float(knot_spacing_s),),
                   float(rest_resolution_m))

    def perturbed(self, rng: np.random.Generator) -> SmoothedRack:
        """A rack the data allow as well: coefficients drawn from their least-squares distribution."""
        factor = pm.psd_factor(self.coefficient_covariance)
        draw = self.bspline + pm.matmul(factor, rng.standard_normal(factor.shape[1]))
        return SmoothedRack.from_bspline(self.knots, draw, self.coefficient_covariance, self.knot_spacing_s,
                                         self.fit_rms_m, self.noise_rms_m, self.held_at_rest, self.turning_times_s,
                                         self.rest_intervals_s, self.passing_spacings_s, self.rest_resolution_m)

    def resmoothed(self, time_s: np.ndarray, log: Callable[[np.ndarray], np.ndarray],
                   hold_rest: bool = True) -> SmoothedRack:
        """A rack the logger could equally have recorded: this spline at `time_s`, logged by `log`, smoothed again.

        `log` maps a clean rack (m) to a logged one (noise and rounding to the logger's levels;
        see :func:`parksteer.diagnose.ensemble.relogged_rack`); the smoothing keeps this knot
        spacing (and the same tests for rest at the ends). Unlike :meth:`perturbed`, this keeps
        what makes an 8-bit rack hard near a turning point: there the rack stays within one
        converter step for a tenth of a second or more, its rounding errors are the same from
        sample to sample rather than independent, and the turning time the data fix is
        correspondingly less certain.
        """
        return smooth_rack(time_s, log(self.evaluate(time_s)[0]), self.knot_spacing_s, hold_rest)

    def summary(self) -> dict:
        """The smoothing's settings and fit (for JSON)."""
        return {
            "knot_spacing_s": self.knot_spacing_s,
            "fit_rms_m": self.fit_rms_m,
            "rack_noise_rms_m": self.noise_rms_m,
            "held_at_rest_at_start": bool(self.held_at_rest[0]),
            "held_at_rest_at_end": bool(self.held_at_rest[1]),
            "turning_times_s": list(self.turning_times_s),
            "rest_intervals_s": [list(r) for r in self.rest_intervals_s],
        }


def rounding_draw(rack: RackSpline, time_s: np.ndarray, step_m: float, rng: np.random.Generator,
                  held: tuple[tuple[float, float], ...] = ()) -> RackSpline:
    """`rack` plus a motion its data cannot see: the rack moving within the rounding of a logger whose rounding
    is coarser than its noise and not dithered by it (`step_m`; a rack derived from a bus's handwheel angle).

    Such a rounding's error is the same from sample to sample while the rack stays within one level: through a
    reversal, at the edges of a pause, in any slow creep, the rack can move by up to a step in ways the samples do
    not show, and the spline's speed there follows its knots, not the data. Redrawing the logger's noise does not
    reach this (the noise is too small to move the rack across a level), so the draw adds a cubic B-spline on knots
    RACK_MIN_SAMPLES_PER_KNOT samples apart (the finest spline the smoothing admits), its coefficients independent
    and normal with the rounding's RMS, step / sqrt(12), divided by the square root of the number of levels the
    rack crosses over a knot interval at `rack`'s speed there (the rounding's errors average out only across the
    levels crossed): the draw moves where the rack is slow and is left as it is where the rack moves. Over a
    stretch in `held` (a pause the draw holds at rest) it fades out within four knot intervals of the stretch's ends
    (the B-splines wholly inside get nothing), so the pause's edges keep their doubt and its middle stays at rest."""
    from scipy.interpolate import BSpline, PPoly

    t = np.asarray(time_s, dtype=float)
    interval = RACK_MIN_SAMPLES_PER_KNOT * float(np.median(np.diff(t)))
    pieces = max(1, int(round((t[-1] - t[0]) / interval)))
    inner = t[0] + (t[-1] - t[0]) * np.arange(pieces + 1) / pieces
    knots = np.concatenate([[t[0]] * 3, inner, [t[-1]] * 3])
    count = len(knots) - 4
    first, last = knots[:count], knots[4 : count + 4]  # the span of each B-spline
    centres = 0.5 * (first + last)
    crossed = np.abs(rack.evaluate(centres)[1]) * interval / step_m
    sigma = step_m / math.sqrt(12.0) / np.sqrt(np.maximum(crossed, 1.0))
    for a, b in held:
        sigma[(first >= a) & (last <= b)] = 0.0
    draw = sigma * rng.standard_normal(count)
    return rack.plus(RackSpline.from_ppoly(PPoly.from_spline(BSpline(knots, draw, 3, extrapolate=False))))


def _knot_vector(t: np.ndarray, spacing_s: float, turns: tuple[float, ...] = (),
                 rests: tuple[tuple[float, float], ...] = ()) -> np.ndarray:
    """Clamped cubic knots: evenly spaced interior knots about `spacing_s` apart, and one at each turning time.

    A reversal is the one place where the rack's motion changes within a few tenths of a
    second; with a knot at the turning time the spline can decelerate into it and accelerate
    out of it on either side, whatever the reversal's phase against the even knots. Even knots
    closer than half a spacing to a turning time give way to it.
    """
    span = t[-1] - t[0]
    pieces = max(1, int(round(span / spacing_s)))
    interior = list(t[0] + span * np.arange(1, pieces) / pieces)
    closest = RACK_MIN_SAMPLES_PER_KNOT * float(np.median(np.diff(t)))
    turns = [x for x in turns if not any(a <= x <= b for a, b in rests)]  # a turn inside a pause: the pause's ends
    turns += [x for a, b in rests for x in (a, b)]
    turns = [x for x in turns if t[0] + closest < x < t[-1] - closest]
    knots = sorted([k for k in interior if all(abs(k - x) >= 0.5 * spacing_s for x in turns)] + turns)
    return np.concatenate([[t[0]] * 4, knots, [t[-1]] * 4])


def _window_fits(time_s: np.ndarray, rack_m: np.ndarray, half: int, noise: float, degree: int
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares polynomials of `degree` over every window of 2 `half` + 1 samples, each about its mid time:
    (coefficients, their standard errors), one row per window (all windows solved at once, by normal equations:
    in a window's own time the powers are well scaled)."""
    windows_t = np.lib.stride_tricks.sliding_window_view(time_s, 2 * half + 1)
    windows_x = np.lib.stride_tricks.sliding_window_view(rack_m, 2 * half + 1)
    tau = windows_t - 0.5 * (windows_t[:, :1] + windows_t[:, -1:])
    powers = [np.ones_like(tau)]
    for _ in range(degree):
        powers.append(powers[-1] * tau)
    n = degree + 1
    gram = np.empty((len(tau), n, n))
    for i in range(n):
        for j in range(i, n):
            gram[:, i, j] = gram[:, j, i] = np.sum(powers[i] * powers[j], axis=1)
    rhs = np.stack([np.sum(power * windows_x, axis=1) for power in powers], axis=1)
    inverse = pm.inv_spd_batched(gram)
    coefficients = np.sum(inverse * rhs[:, None, :], axis=2)
    errors = noise * np.sqrt(np.diagonal(inverse, axis1=1, axis2=2))
    return coefficients, errors


def rest_intervals(time_s: np.ndarray, rack_m: np.ndarray, noise: float) -> tuple[tuple[float, float], ...]:
    """Stretches (start s, end s) of at least RACK_REST_MIN_S where the rack data show it at rest (see the setting).

    A window passes when the quadratic's speed and acceleration are both within the bound; a
    stretch is a run of samples whose centred windows pass (so it starts half a window after the
    hand has stopped, where the window no longer reaches back into the slowing hand).
    """
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(rack_m, dtype=float)
    dt = float(np.median(np.diff(t)))
    half = int(round(0.5 * RACK_REST_MIN_S / dt))
    if noise <= 0.0 or len(t) < 2 * half + 1 or half < 2:
        return ()
    covered = np.zeros(len(t), dtype=bool)
    c, se = _window_fits(t, x, half, noise, 2)
    covered[half : len(t) - half] = np.all(np.abs(c[:, 1:]) <= RACK_REST_SLOPE_SE * se[:, 1:], axis=1)
    edges = np.diff(np.concatenate([[0], covered.astype(int), [0]]))
    out = []
    for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1):
        if t[b] - t[a] >= RACK_REST_MIN_S:
            out.append((float(t[a]), float(t[b])))
    return tuple(out)


def turning_times(time_s: np.ndarray, rack_m: np.ndarray) -> tuple[float, ...]:
    """Times where the rack reverses: zero crossings of its speed between steady motions of opposite sign.

    The speed is a local straight-line fit over RACK_TURN_WINDOW_S (as parksteer.measure.phases
    finds strokes); steady motion is a speed beyond a fifth of the 90th percentile of |speed|.
    """
    _, speed = local_linear_fit(time_s, rack_m, RACK_TURN_WINDOW_S)
    level = 0.2 * float(np.percentile(np.abs(speed), 90))
    moving = np.flatnonzero(np.abs(speed) > level)
    turns = []
    for a, b in zip(moving[:-1], moving[1:]):
        if level > 0 and np.sign(speed[a]) != np.sign(speed[b]):
            segment = speed[a : b + 1]
            k = a + int(np.flatnonzero(np.sign(segment[:-1]) != np.sign(segment[1:]))[0])
            v0, v1 = speed[k], speed[k + 1]
            turns.append(float(time_s[k] + (time_s[k + 1] - time_s[k]) * v0 / (v0 - v1)))
    return tuple(turns)


def _constrained_solve(inverse: np.ndarray, rhs: np.ndarray, constraints: np.ndarray):
    """Least squares with linear equality constraints C c = 0, from the inverse of the normal equations' matrix:
    (coefficients, their covariance per unit variance)."""
    coefficients = pm.matmul(inverse, rhs)
    covariance = inverse
    if len(constraints):
        gc = pm.matmul(inverse, constraints.T)
        # A generalised inverse (a rest reaching an end already fixes its speed, so C may repeat a constraint):
        # any G with M G M = M gives the same coefficients and covariance.
        correction = pm.matmul(gc, pm.generalized_inverse(pm.matmul(constraints, gc)))
        coefficients = coefficients - pm.matmul(correction, pm.matmul(constraints, coefficients))
        covariance = inverse - pm.matmul(correction, gc.T)
    return coefficients, 0.5 * (covariance + covariance.T)


def _lsq_fit(t: np.ndarray, x: np.ndarray, spacing_s: float, turns: tuple[float, ...] = (),
             rests: tuple[tuple[float, float], ...] = (), hold_rest: bool = True):
    """(knots, coefficients, covariance per unit variance, fit RMS) of the least-squares cubic spline.

    At each end of the record the spline is held at rest (zero speed) unless the data
    contradict it: unless holding it raises the residual sum of squares by more than
    ``RACK_REST_TEST_CHI2`` times the noise variance (a likelihood-ratio test with one degree of
    freedom; the bar is set well above the usual 6.6 because a spline with knots a few tenths
    of a second apart cannot follow the hand's first 0.2 s exactly and so leans towards a
    start speed that is not there). A record that starts or ends at rest then gets no
    spurious end speed, which the rack friction would turn into a spurious torque and the
    tyre carcass would remember; one cut in the middle of a stroke (15 mm/s, some fifty
    standard errors from rest) keeps its speed. Without `hold_rest` no end is held (only a rest
    reaching the end holds it). Over each of `rests` the spline is constant.
    None if the spline is ill-posed.
    """
    from scipy.interpolate import BSpline

    knots = _knot_vector(t, spacing_s, turns, rests)
    # Sparse (four B-splines are nonzero at a time): scipy's sparse products sum in a fixed order, without BLAS.
    design = BSpline.design_matrix(t, knots, 3).tocsr()
    gram = (design.T @ design).toarray()
    try:
        pm.cholesky(gram)
    except pm.LinAlgError:  # Schoenberg-Whitney fails: an interval without data
        return None
    inverse = pm.inv(gram)
    rhs = design.T @ x
    still = []  # B-spline coefficients acting over a rest are equal: the spline is constant there
    for a, b in rests:
        active = [j for j in range(len(rhs)) if knots[j] < b - 1e-9 and knots[j + 4] > a + 1e-9]
        for j, k in zip(active[:-1], active[1:]):
            row = np.zeros(len(rhs))
            row[j], row[k] = 1.0, -1.0
            still.append(row)
    free, _ = _constrained_solve(inverse, rhs, np.array(still).reshape(len(still), len(rhs)))
    rss_free = float(np.sum((design @ free - x) ** 2))
    noise_var = max(rss_free / max(len(t) - len(rhs), 1), 1e-30)
    speed_rows = np.array([BSpline(knots, np.eye(len(rhs))[j], 3)(np.array([t[0], t[-1]]), 1)
                           for j in range(len(rhs))]).T
    held, at_rest = list(still), []
    for row in speed_rows:
        trial, _ = _constrained_solve(inverse, rhs, np.array(held + [row]))
        rss = float(np.sum((design @ trial - x) ** 2))
        at_rest.append(hold_rest and rss - rss_free < RACK_REST_TEST_CHI2 * noise_var)
        if at_rest[-1]:
            held.append(row)
    coefficients, covariance = _constrained_solve(inverse, rhs, np.array(held).reshape(len(held), len(rhs)))
    rms = float(np.sqrt(np.mean((design @ coefficients - x) ** 2)))
    return knots, coefficients, covariance, rms, tuple(at_rest)


def knot_spacings(time_s: np.ndarray) -> list[float]:
    """The knot spacings tried, s: from the finer of the range's bottom and a few samples, up to its top."""
    dt = float(np.median(np.diff(time_s)))
    low, high = RACK_KNOT_SPACING_RANGE_S
    low = max(low, RACK_MIN_SAMPLES_PER_KNOT * dt)
    count = int(math.floor(pm.log(high / low) / pm.log(RACK_KNOT_SPACING_STEP))) + 1
    return [low * RACK_KNOT_SPACING_STEP**i for i in range(max(count, 1))]


def smooth_rack(time_s, rack_m, knot_spacing_s: float | None = None, hold_rest: bool = True,
                rest_resolution_m: float = 0.0) -> SmoothedRack:
    """The measured rack as a least-squares cubic spline; the knot spacing from the data unless given.

    With `hold_rest` (the default) each end is held at rest unless the data contradict it (:func:`_lsq_fit`) and
    the spline is constant over every pause of the hand (:func:`rest_intervals`); without, the ends and the
    pauses are free (the alternative the replay's uncertainty also replays).

    `rest_resolution_m`: for a rack whose rounding is coarser than its noise and not dithered by it (a rack derived
    from a quantised handwheel angle), the step of that rounding. At rest such a rack can drift by up to a step
    that second differences do not see as noise (the column's twist relaxing under one level of the angle), so
    the pause test (:func:`rest_intervals`) takes the rack's noise as at least that step. 0 (the default): the
    noise from the data alone.

    Chosen spacing: the largest tried (:func:`knot_spacings`) whose fit RMS per degree of
    freedom is within ``RACK_DISCREPANCY_FACTOR`` of the rack's noise RMS; if none is, the finest.
    """
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(rack_m, dtype=float)
    if t.ndim != 1 or len(t) != len(x) or len(t) < 8:
        raise UsageError("rack smoothing needs matching time and rack columns with at least 8 samples")
    if (np.diff(t) <= 0).any():
        raise UsageError("rack smoothing: time must be strictly increasing")
    noise = estimate_noise_rms(x)
    turns = turning_times(t, x)
    rests = rest_intervals(t, x, max(noise, rest_resolution_m)) if hold_rest else ()

    def build(fit, spacing, passing=()):
        knots, coefficients, inverse, rms, at_rest = fit
        return SmoothedRack.from_bspline(knots, coefficients, noise**2 * inverse, spacing, rms, noise, at_rest, turns,
                                         rests, passing, rest_resolution_m)

    if knot_spacing_s is not None:
        if not knot_spacing_s > 0:
            raise UsageError(f"knot spacing must be positive, got {knot_spacing_s:g} s")
        fit = _lsq_fit(t, x, knot_spacing_s, turns, rests, hold_rest)
        if fit is None:
            raise UsageError(f"rack smoothing: knot spacing {knot_spacing_s:g} s leaves intervals without samples")
        return build(fit, knot_spacing_s)
    best, passing = None, []
    for spacing in knot_spacings(t):
        fit = _lsq_fit(t, x, spacing, turns, rests, hold_rest)
        if fit is None:
            continue
        # the residual of a least-squares fit with p coefficients has n - p degrees of freedom
        unbiased = fit[3] * math.sqrt(len(t) / max(len(t) - len(fit[1]), 1))
        if unbiased <= RACK_DISCREPANCY_FACTOR * noise:
            passing.append(spacing)
        if best is None or unbiased <= RACK_DISCREPANCY_FACTOR * noise:
            best = (fit, spacing)
    if best is None:
        raise UsageError("rack smoothing: no knot spacing gives a well-posed spline (samples too uneven)")
    # the spacings run from fine to coarse, so the kept one is the coarsest that passed (or, none passing, the finest)
    return build(*best, passing=sorted(passing, reverse=True))
