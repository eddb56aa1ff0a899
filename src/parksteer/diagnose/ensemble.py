"""The replay ensemble: how far the replay alone can be off at each sample.

The smoothed rack is one spline among many the rack data allow equally well. When the file states its logger (the
rack's full scale and bits), the smoothed rack is logged again (analog noise, rounding to the converter's levels) and
smoothed again a few times (:func:`relogged_rack`, a parametric bootstrap of the logging and smoothing); otherwise
splines are drawn from the least-squares distribution of the coefficients
(:meth:`parksteer.measure.smoothing.SmoothedRack.perturbed`). The draws start from the rack smoothed at each knot
spacing the data allow (:func:`ensemble_plan`); a rack rounded more coarsely than its noise
(``FileData.rack.rest_resolution_m``) is moved within its rounding where it is slow
(:func:`parksteer.measure.smoothing.rounding_draw`); where the smoothing held an end or a pause at rest, every other
draw leaves it free. The spread of the replayed torque at each sample is delta_i (N m), small on the plateaus and
large at a reversal; each sample's attainable error is ``sigma_i = sqrt(noise_floor^2 + delta_i^2)``, and residuals
are weighted by it, so a perfect model has weighted residuals of unit variance. Why: docs/diagnosis.md and
docs/measurement.md, "The smoothed rack".
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .. import portable as pm
from ..measure.converter import add_noise, quantise
from ..measure.smoothing import SmoothedRack, rounding_draw, rounding_draw_size
from ..model.symbolic.components import Effect
from .engine import ReplayEngine
from ..measure.column import rack_logger
from .problem import FileData, Problem
from .settings import DEFAULT_SETTINGS


def with_replay_uncertainty(engine: ReplayEngine, problem: Problem, effects: list[Effect],
                            overrides: dict[str, float] | None = None,
                            draws: int = DEFAULT_SETTINGS.replay_ensemble_draws,
                            seed: int = DEFAULT_SETTINGS.replay_ensemble_seed, keep_larger: bool = False) -> Problem:
    """`problem` on files with their replay uncertainty: the spread of replays, by `engine`, of racks the data
    allow (module docstring).

    The spread is widened by one sample either side (a running maximum), since a torque
    drop the draws place on one sample may fall on its neighbour. With `keep_larger`, each
    sample keeps the larger of this and the uncertainty already estimated.
    """
    rng = np.random.default_rng(seed)
    # The random numbers are drawn here, in order (one random stream); each draw's rack is logged, smoothed and
    # replayed side by side on the workers from its numbers (DrawnInAdvance).
    jobs = []
    for i, f in enumerate(problem.files):
        base = engine.replay(problem, effects, i)
        base.parameter_vector(overrides)  # any run the overrides need is prepared once, here
        logger = rack_logger(f.measurement, problem.params)
        # An end held at rest may be a hand still slowing there, and a pause's edges are not sharp
        # (rack_fit.RACK_REST_TEST_CHI2, RACK_REST_MIN_S): every other draw smooths with the ends and the
        # pauses free, so the samples there carry that doubt.
        released = any(f.rack.held_at_rest) or bool(f.rack.rest_intervals_s)
        for spacing, hold in ensemble_plan(f, draws, released):
            # without a logger the draw's coefficients come from this stream, so its source is smoothed here; with
            # one, the job smooths it where it runs (a worker, side by side with the others), once per process
            perturbed = None if logger is not None else _source(f, spacing, hold, engine.smoothed_racks).perturbed(rng)
            drawn = []
            if logger is not None and logger[2] > 0.0:  # the analog noise add_noise draws (none at 0 RMS)
                drawn.append(("normal", (0.0, logger[2], f.time_s.shape), rng.normal(0.0, logger[2], f.time_s.shape)))
            if f.rack.rest_resolution_m > 0.0:
                count = rounding_draw_size(f.time_s)
                drawn.append(("standard_normal", (count,), rng.standard_normal(count)))
            jobs.append((i, spacing, hold, perturbed, tuple(drawn)))

    def replayed_draw(job) -> np.ndarray:
        i, spacing, hold, rack, drawn = job
        f, numbers = problem.files[i], DrawnInAdvance(drawn)
        logger = rack_logger(f.measurement, problem.params)
        if rack is None:
            rack = relogged_rack(_source(f, spacing, hold, engine.smoothed_racks), f.time_s, *logger, numbers,
                                 hold_rest=hold, memo=engine.smoothed_racks)
        if f.rack.rest_resolution_m > 0.0:  # a rounding coarser than the noise: the rack within its levels
            rack = rounding_draw(rack, f.time_s, f.rack.rest_resolution_m, numbers,
                                 held=rack.rest_intervals_s if hold else ())
        numbers.check_used()
        return engine.signals(problem, effects, i, overrides, engine.replay(problem, effects, i).on_rack(rack))

    replayed = engine.map(replayed_draw, jobs)
    files = []
    for i, f in enumerate(problem.files):
        runs = np.array(replayed[i * draws : (i + 1) * draws])
        torque_runs = runs[:, : f.n]
        f = replace(f, replay_draws_Nm=torque_runs - torque_runs.mean(axis=0),
                    replay_uncertainty_Nm=_spread(torque_runs, f.replay_uncertainty_Nm if keep_larger else None))
        if f.uses_angle:  # each draw's angle carries its own fitted zero (Problem.signals)
            angle_runs = runs[:, f.n : 2 * f.n]
            # The replayed torque is itself off by about its attainable error, and the twist that passes it by
            # as much through the column's compliance (in a dead band: the band, where |T| is that small).
            through_torque = engine.replay(problem, effects, i).twist_spread(f.sigma_Nm, overrides)
            spread = pm.hypot(_spread(angle_runs, None), pm.running_max3(through_torque))
            before = f.replay_uncertainty_rad if keep_larger else None
            f = replace(f, replay_draws_rad=angle_runs - angle_runs.mean(axis=0),
                        replay_uncertainty_rad=spread if before is None else np.maximum(spread, before))
        if f.uses_motor:
            motor_runs = runs[:, f.m - f.n :]
            before = f.replay_uncertainty_motor if keep_larger else None
            f = replace(f, replay_draws_motor=motor_runs - motor_runs.mean(axis=0),
                        replay_uncertainty_motor=_spread(motor_runs, before))
        files.append(f)
    return problem.with_files(files)


def _spread(runs: np.ndarray, before: np.ndarray | None) -> np.ndarray:
    """The draws' standard deviation at each sample, widened by one sample either side; at least `before`."""
    spread = pm.running_max3(np.std(runs, axis=0, ddof=1))
    return spread if before is None else np.maximum(spread, before)


def ensemble_plan(f: FileData, draws: int, released: bool) -> list[tuple[float, bool]]:
    """The knot spacing of the smoothed rack each draw of the replay ensemble is logged again from, and whether it
    holds rests.

    Every knot spacing whose fit passes the discrepancy test
    (:attr:`parksteer.measure.smoothing.SmoothedRack.passing_spacings_s`) fits the rack within its noise, and at a
    reversal they differ in how the spline eases into and out of the turn, which the data do not fix: the draws are
    spread over the passing spacings, the chosen one first and the finest last (evenly by index). With `released`, the
    draws come in pairs, the first held at rest as the chosen spline is, the second with the ends and pauses free. A
    record whose chosen spacing is the only one to pass draws every time about that spline. Why about one spline alone
    the replay misses the truth at a sound car's reversals: docs/diagnosis.md.
    """
    spacings = f.rack.passing_spacings_s
    pair = 2 if released else 1
    slots = max(draws // pair, 1)
    out = []
    for k in range(draws):
        slot = (k // pair) % slots
        index = int(slot * (len(spacings) - 1) / (slots - 1) + 0.5) if slots > 1 else 0
        out.append((spacings[index], not (released and k % 2)))
    return out


def _source(f: FileData, spacing: float, hold: bool, memo: dict) -> SmoothedRack:
    """The file's rack smoothed at `spacing` (holding rests or not): the rack itself at its own spacing, held; else
    made once per `memo` (the engine's, in each process: :meth:`parksteer.measure.smoothing.SmoothedRack.
    smoothed_at`, which takes the search's fit where it has one), and so its draws logged again are smoothed once
    too."""
    if hold and spacing == f.rack.knot_spacing_s:
        return f.rack
    return f.rack.smoothed_at(f.time_s, f.rack_m, spacing, hold, memo)


class DrawnInAdvance:
    """Stands in for a random generator (``numpy.random.Generator``) in a function that draws from one, as
    :func:`relogged_rack` and :func:`parksteer.measure.smoothing.rounding_draw` do: it gives back, in order, the
    numbers drawn in advance from the generator itself (`drawn`: each call's method, arguments and values) and
    refuses any other call, so the function computes, in another process, exactly what it would have computed
    drawing from the generator in order."""

    def __init__(self, drawn) -> None:
        self.drawn = list(drawn)

    def _next(self, method: str, arguments: tuple) -> np.ndarray:
        if not self.drawn or self.drawn[0][:2] != (method, arguments):
            raise RuntimeError(f"replay ensemble: {method}{arguments} asked for, but drawn in advance: "
                               f"{[d[:2] for d in self.drawn]}")
        return self.drawn.pop(0)[2]

    def normal(self, loc: float = 0.0, scale: float = 1.0, size=None) -> np.ndarray:
        return self._next("normal", (loc, scale, size))

    def standard_normal(self, size=None) -> np.ndarray:
        return self._next("standard_normal", (size,))

    def check_used(self) -> None:
        if self.drawn:
            raise RuntimeError(f"replay ensemble: drawn in advance but not used: {[d[:2] for d in self.drawn]}")


def relogged_rack(rack: SmoothedRack, time_s: np.ndarray, full_scale: float, bits: int, analog_rms: float,
                  rng: np.random.Generator, hold_rest: bool = True, memo: dict | None = None) -> SmoothedRack:
    """A rack the logger could equally have recorded: `rack` at `time_s` with analog noise of `analog_rms`,
    rounded to the levels of a `bits` converter over +-`full_scale`, and smoothed again
    (:meth:`parksteer.measure.smoothing.SmoothedRack.resmoothed`, once per `memo`)."""
    return rack.resmoothed(time_s, lambda clean: quantise(add_noise(clean, analog_rms, rng), full_scale, bits),
                           hold_rest, memo)
