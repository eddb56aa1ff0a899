"""A measured rack as a motion the model can follow: position, speed and acceleration at any time.

:func:`smooth_rack` replaces a quantised, noisy rack by a least-squares cubic spline (the fit and its settings:
:mod:`parksteer.measure.rack_fit`) with evenly spaced knots and one at each reversal, the spacing the largest that
fits the rack within its own noise (the discrepancy principle), each end held at rest unless the data contradict
it: replayed as it stands, a converter's steps make the speed and acceleration spikes and flip the rack friction.
:meth:`SmoothedRack.perturbed` and :meth:`SmoothedRack.resmoothed` give other racks the data allow as well, and
``SmoothedRack.passing_spacings_s`` every spacing that passes the discrepancy test, for the replay uncertainty
(:mod:`parksteer.diagnose.problem`, :func:`parksteer.diagnose.ensemble.ensemble_plan`); :func:`rounding_draw`
adds the motion a coarsely rounded rack hides. Every rack here is a
:class:`~parksteer.measure.rack_spline.RackSpline` (``breaks``, ``coefficients``, ``start_s``, ``end_s``; metres and
seconds), the rack motion :func:`parksteer.model.numeric.prescribed.solve` takes. Why and what smoothing cannot fix:
docs/measurement.md, "The smoothed rack".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from .bspline import piecewise_cubic
from .metrics import estimate_noise_rms
from .rack_fit import (
    RACK_DISCREPANCY_FACTOR,
    RACK_MIN_SAMPLES_PER_KNOT,
    knot_spacings,
    lsq_fit,
    rest_intervals,
    turning_times,
)
from .rack_spline import RackSpline



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
    # what a search for the spacing (smooth_rack without one) fitted, holding rests: its time, rack and noise, and the
    # fit of every passing spacing (held_at gives them); None for a rack smoothed otherwise
    search_fits: tuple | None = field(default=None, repr=False)

    @classmethod
    def from_bspline(cls, knots, bspline, covariance, knot_spacing_s, fit_rms_m, noise_rms_m,
                     held_at_rest=(False, False), turning_times_s=(), rest_intervals_s=(),
                     passing_spacings_s=(), rest_resolution_m=0.0, search_fits=None) -> SmoothedRack:
        piecewise = RackSpline(*piecewise_cubic(knots, bspline))
        return cls(piecewise.breaks, piecewise.coefficients, knots, bspline, covariance, float(knot_spacing_s),
                   float(fit_rms_m), float(noise_rms_m), tuple(held_at_rest), tuple(turning_times_s),
                   tuple(rest_intervals_s), tuple(float(x) for x in passing_spacings_s) or (float(knot_spacing_s),),
                   float(rest_resolution_m), search_fits)

    @classmethod
    def from_fit(cls, fit, spacing, noise, turning_times_s, rest_intervals_s, rest_resolution_m, passing=(),
                 search_fits=None) -> SmoothedRack:
        """The rack of one least-squares fit (``lsq_fit``'s knots, coefficients, inverse normal matrix, RMS and
        held ends) at knot `spacing`, its covariance scaled by the rack's `noise` RMS."""
        knots, coefficients, inverse, rms, at_rest = fit
        return cls.from_bspline(knots, coefficients, noise**2 * inverse, spacing, rms, noise, at_rest, turning_times_s,
                                rest_intervals_s, passing, rest_resolution_m, search_fits)

    def held_at(self, time_s, rack_m, spacing: float) -> SmoothedRack | None:
        """``smooth_rack(time_s, rack_m, spacing, rest_resolution_m=self.rest_resolution_m)`` made from the fit the
        search for this rack's spacing made at `spacing` (the same fit of the same data: the same spline), where that
        search fitted these very `time_s` and `rack_m` and `spacing` passed; otherwise None."""
        fit = self.search_fits[3].get(spacing) if self._searched(time_s, rack_m) else None
        if fit is None:
            return None
        return SmoothedRack.from_fit(fit, spacing, self.search_fits[2], self.turning_times_s, self.rest_intervals_s,
                                     self.rest_resolution_m)

    def _searched(self, time_s, rack_m) -> bool:
        """Whether a search for this rack's spacing, holding rests, fitted these very `time_s` and `rack_m` (so its
        noise, turning times and pauses are theirs)."""
        return self.search_fits is not None and (np.array_equal(self.search_fits[0], time_s)
                                                 and np.array_equal(self.search_fits[1], rack_m))

    def smoothed_at(self, time_s, rack_m, spacing: float, hold_rest: bool, memo: dict | None = None) -> SmoothedRack:
        """``smooth_rack(time_s, rack_m, spacing, hold_rest, rest_resolution_m=self.rest_resolution_m)``, taken from
        the search's fit where :meth:`held_at` has it; made once per `memo` (its owner's: :func:`_remembered`)."""
        t, x = np.asarray(time_s, dtype=float), np.asarray(rack_m, dtype=float)

        def made() -> SmoothedRack:
            rack = hold_rest and self.held_at(t, x, spacing)
            if not rack and self._searched(t, x):  # its own record: its noise, turns and pauses are known
                rack = _smoothed_at_spacing(t, x, spacing, bool(hold_rest), self.rest_resolution_m, self.noise_rms_m,
                                            self.turning_times_s, self.rest_intervals_s if hold_rest else ())
            return rack or smooth_rack(t, x, spacing, bool(hold_rest), self.rest_resolution_m)

        return _remembered(memo, self, ("smoothed", t.tobytes(), x.tobytes(), float(spacing), bool(hold_rest)), made)

    def perturbed(self, rng: np.random.Generator) -> SmoothedRack:
        """A rack the data allow as well: coefficients drawn from their least-squares distribution."""
        factor = pm.psd_factor(self.coefficient_covariance)
        draw = self.bspline + pm.matmul(factor, rng.standard_normal(factor.shape[1]))
        return SmoothedRack.from_bspline(self.knots, draw, self.coefficient_covariance, self.knot_spacing_s,
                                         self.fit_rms_m, self.noise_rms_m, self.held_at_rest, self.turning_times_s,
                                         self.rest_intervals_s, self.passing_spacings_s, self.rest_resolution_m)

    def resmoothed(self, time_s: np.ndarray, log: Callable[[np.ndarray], np.ndarray],
                   hold_rest: bool = True, memo: dict | None = None) -> SmoothedRack:
        """A rack the logger could equally have recorded: this spline at `time_s`, logged by `log`, smoothed again.

        `log` maps a clean rack (m) to a logged one (noise and rounding to the logger's levels;
        see :func:`parksteer.diagnose.ensemble.relogged_rack`); the smoothing keeps this knot
        spacing (and the same tests for rest at the ends). Unlike :meth:`perturbed`, this keeps
        what makes an 8-bit rack hard near a turning point: there the rack stays within one
        converter step for a tenth of a second or more, its rounding errors are the same from
        sample to sample rather than independent, and the turning time the data fix is
        correspondingly less certain. The same logged rack again (the same drawn numbers) is smoothed once per
        `memo` (:func:`_remembered`).
        """
        t = np.asarray(time_s, dtype=float)
        logged = np.asarray(log(self.evaluate(t)[0]), dtype=float)
        return _remembered(memo, self, ("resmoothed", t.tobytes(), logged.tobytes(), bool(hold_rest)),
                           lambda: smooth_rack(t, logged, self.knot_spacing_s, bool(hold_rest)))

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
    t = np.asarray(time_s, dtype=float)
    knots, interval = _rounding_knots(t)
    count = len(knots) - 4
    first, last = knots[:count], knots[4 : count + 4]  # the span of each B-spline
    centres = 0.5 * (first + last)
    crossed = np.abs(rack.evaluate(centres)[1]) * interval / step_m
    sigma = step_m / math.sqrt(12.0) / np.sqrt(np.maximum(crossed, 1.0))
    for a, b in held:
        sigma[(first >= a) & (last <= b)] = 0.0
    draw = sigma * rng.standard_normal(count)
    return rack.plus(RackSpline(*piecewise_cubic(knots, draw)))


def _rounding_knots(t: np.ndarray) -> tuple[np.ndarray, float]:
    """The knots of :func:`rounding_draw`'s B-spline on `t` and their interval (s)."""
    interval = RACK_MIN_SAMPLES_PER_KNOT * float(np.median(np.diff(t)))
    pieces = max(1, int(round((t[-1] - t[0]) / interval)))
    inner = t[0] + (t[-1] - t[0]) * np.arange(pieces + 1) / pieces
    return np.concatenate([[t[0]] * 3, inner, [t[-1]] * 3]), interval


def rounding_draw_size(time_s: np.ndarray) -> int:
    """How many standard normal numbers :func:`rounding_draw` on `time_s` draws (one call, whatever the rack)."""
    return len(_rounding_knots(np.asarray(time_s, dtype=float))[0]) - 4


def smooth_rack(time_s, rack_m, knot_spacing_s: float | None = None, hold_rest: bool = True,
                rest_resolution_m: float = 0.0) -> SmoothedRack:
    """The measured rack as a least-squares cubic spline; the knot spacing from the data unless given.

    With `hold_rest` (the default) each end is held at rest unless the data contradict it (:func:`lsq_fit`) and
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

    if knot_spacing_s is not None:
        return _smoothed_at_spacing(t, x, knot_spacing_s, hold_rest, rest_resolution_m, noise, turns, rests)
    best, passing = None, {}
    for spacing in knot_spacings(t):
        fit = lsq_fit(t, x, spacing, turns, rests, hold_rest)
        if fit is None:
            continue
        # the residual of a least-squares fit with p coefficients has n - p degrees of freedom
        unbiased = fit[3] * math.sqrt(len(t) / max(len(t) - len(fit[1]), 1))
        if unbiased <= RACK_DISCREPANCY_FACTOR * noise:
            passing[float(spacing)] = fit
        if best is None or unbiased <= RACK_DISCREPANCY_FACTOR * noise:
            best = (fit, spacing)
    if best is None:
        raise UsageError("rack smoothing: no knot spacing gives a well-posed spline (samples too uneven)")
    # the spacings run from fine to coarse, so the kept one is the coarsest that passed (or, none passing, the finest)
    # (the replay ensemble smooths the rack again at the passing spacings, holding rests: held_at)
    return SmoothedRack.from_fit(*best, noise, turns, rests, rest_resolution_m, sorted(passing, reverse=True),
                                 (t, x, noise, passing) if hold_rest and passing else None)


def _remembered(memo: dict | None, rack: SmoothedRack, key: tuple, made: Callable[[], SmoothedRack]) -> SmoothedRack:
    """``made()``, kept in `memo` (a dict its owner keeps, e.g. a diagnosis's replay engine; None: not kept) under
    `rack` and `key` (the exact bytes of the other inputs): a rack smoothed from the same inputs is the same spline.
    `memo` holds `rack` beside the answer, so the identity in its key stays that rack's; the rack itself is left as
    it was."""
    if memo is None:
        return made()
    full_key = (id(rack), *key)
    if full_key not in memo:
        memo[full_key] = (rack, made())
    return memo[full_key][1]


def _smoothed_at_spacing(t: np.ndarray, x: np.ndarray, knot_spacing_s: float, hold_rest: bool, rest_resolution_m: float,
                         noise: float, turns: tuple[float, ...], rests: tuple[tuple[float, float], ...]
                         ) -> SmoothedRack:
    """:func:`smooth_rack` at a given knot spacing, from the rack's noise RMS, turning times and pauses (those
    smooth_rack finds in `t` and `x`)."""
    if not knot_spacing_s > 0:
        raise UsageError(f"knot spacing must be positive, got {knot_spacing_s:g} s")
    fit = lsq_fit(t, x, knot_spacing_s, turns, rests, hold_rest)
    if fit is None:
        raise UsageError(f"rack smoothing: knot spacing {knot_spacing_s:g} s leaves intervals without samples")
    return SmoothedRack.from_fit(fit, knot_spacing_s, noise, turns, rests, rest_resolution_m)
