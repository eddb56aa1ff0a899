"""The least-squares cubic spline a measured rack is smoothed with: its knots (evenly spaced, one at each
reversal), the pauses of the hand where it is held constant, the ends held at rest unless the data contradict it,
and the settings of the method (each with its reason). :func:`parksteer.measure.smoothing.smooth_rack` chooses
the spacing."""

from __future__ import annotations

import math

import numpy as np

from .. import portable as pm
from .bspline import DesignMatrix, derivative_rows
from .phases import local_linear_fit

# Smoothing settings (settings of the method, not properties of the car; each with its reason).
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
# noise variances (see lsq_fit).
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
    signs = np.sign(speed[moving])
    reversals = np.flatnonzero(signs[:-1] != signs[1:]) if level > 0 else np.array([], dtype=int)
    for a, b in zip(moving[reversals], moving[reversals + 1]):  # steady motions of opposite sign
        segment = speed[a : b + 1]
        k = a + int(np.flatnonzero(np.sign(segment[:-1]) != np.sign(segment[1:]))[0])
        v0, v1 = speed[k], speed[k + 1]
        turns.append(float(time_s[k] + (time_s[k + 1] - time_s[k]) * v0 / (v0 - v1)))
    return tuple(turns)


class _ConstrainedFits:
    """Least squares with linear equality constraints C c = 0 for subsets C of one set of constraint rows, from the
    inverse of the normal equations' matrix: (coefficients, their covariance per unit variance).

    The products of the inverse with every row are formed once: each entry of a product is a sum of its own, so a
    subset's products are the same bits as products formed with that subset alone."""

    def __init__(self, inverse: np.ndarray, rhs: np.ndarray, rows: np.ndarray):
        self.inverse = inverse
        self.unconstrained = pm.matmul(inverse, rhs)
        if len(rows):
            self.inverse_rows = pm.matmul(inverse, rows.T)
            self.row_products = pm.matmul(rows, self.inverse_rows)
            self.row_values = pm.matmul(rows, self.unconstrained)

    def solve(self, chosen: list[int], covariance: bool = True):
        """The fit held to the rows `chosen` (the covariance, the costlier part, only if asked for)."""
        coefficients, full = self.unconstrained, self.inverse
        if chosen:
            gc = self.inverse_rows[:, chosen]
            # A generalised inverse (a rest reaching an end already fixes its speed, so C may repeat a constraint):
            # any G with M G M = M gives the same coefficients and covariance.
            correction = pm.matmul(gc, pm.generalized_inverse(self.row_products[np.ix_(chosen, chosen)]))
            coefficients = coefficients - pm.matmul(correction, self.row_values[chosen])
            if covariance:
                full = self.inverse - pm.matmul(correction, gc.T)
        return coefficients, (0.5 * (full + full.T) if covariance else None)


def lsq_fit(t: np.ndarray, x: np.ndarray, spacing_s: float, turns: tuple[float, ...] = (),
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
    knots = _knot_vector(t, spacing_s, turns, rests)
    # Four B-splines are nonzero at a time; the products sum over the samples in order, without BLAS.
    design = DesignMatrix(t, knots)
    gram = design.gram()
    try:
        pm.cholesky(gram)
    except pm.LinAlgError:  # Schoenberg-Whitney fails: an interval without data
        return None
    inverse = pm.inv(gram)
    rhs = design.transpose_times(x)
    still = []  # B-spline coefficients acting over a rest are equal: the spline is constant there
    for a, b in rests:
        active = [j for j in range(len(rhs)) if knots[j] < b - 1e-9 and knots[j + 4] > a + 1e-9]
        for j, k in zip(active[:-1], active[1:]):
            row = np.zeros(len(rhs))
            row[j], row[k] = 1.0, -1.0
            still.append(row)
    speed_rows = derivative_rows(knots, np.array([t[0], t[-1]]))
    fits = _ConstrainedFits(inverse, rhs, np.array(still + list(speed_rows)).reshape(-1, len(rhs)))
    held = list(range(len(still)))
    free, _ = fits.solve(held, covariance=False)
    rss_free = float(np.sum((design.times(free) - x) ** 2))
    noise_var = max(rss_free / max(len(t) - len(rhs), 1), 1e-30)
    at_rest = []
    for end in range(len(speed_rows)):
        trial, _ = fits.solve(held + [len(still) + end], covariance=False)
        rss = float(np.sum((design.times(trial) - x) ** 2))
        at_rest.append(hold_rest and rss - rss_free < RACK_REST_TEST_CHI2 * noise_var)
        if at_rest[-1]:
            held.append(len(still) + end)
    coefficients, covariance = fits.solve(held)
    rms = float(np.sqrt(np.mean((design.times(coefficients) - x) ** 2)))
    return knots, coefficients, covariance, rms, tuple(at_rest)


def knot_spacings(time_s: np.ndarray) -> list[float]:
    """The knot spacings tried, s: from the finer of the range's bottom and a few samples, up to its top."""
    dt = float(np.median(np.diff(time_s)))
    low, high = RACK_KNOT_SPACING_RANGE_S
    low = max(low, RACK_MIN_SAMPLES_PER_KNOT * dt)
    count = int(math.floor(pm.log(high / low) / pm.log(RACK_KNOT_SPACING_STEP))) + 1
    return [low * RACK_KNOT_SPACING_STEP**i for i in range(max(count, 1))]
