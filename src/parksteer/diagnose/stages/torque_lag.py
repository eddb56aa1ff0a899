"""The torque channel's lag behind the rack channel, searched for each file (settings.torque_lag_fitted,
``parksteer diagnose --torque-lag``): a logger may sample the torque later than the rack, and the model is then
replayed at the instants the torque was really sampled (:attr:`parksteer.diagnose.problem.FileData.replay_time_s`).

Two stages. :class:`TorqueLag`, after the calibration: a lag and the calibrated parameters each absorb part of
the other's signature, so the lags are searched on the calibrated base model, and where one moved by a search
step or more the replay uncertainty and the calibration are made again at the lagged instants, until no lag
moves by a step (at most settings.torque_lag_rounds times). :class:`TorqueLagWithEffect`, last: the lag was
searched on the base model, which lacks the named effect, and an effect at the reversals (a stiction's breakaway)
pulls it off; searched again with the effect, a lag that moves by a step or more is kept and the whole table run
again on a new state with the lags held (the settings' torque_lag_fitted off), whose result is the diagnosis.

A lag moved by less than a step is kept in the file without making the replay uncertainty and the calibration
again; the replays from then on are at the file's new instants (the replay engine keeps one per lag).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ... import portable as pm
from ...errors import SolverError
from ...model.symbolic.components import Effect
from ..engine import ReplayEngine
from ..problem import Problem
from ..settings import DEFAULT_SETTINGS, DiagnosisSettings
from ..state import DiagnosisState
from .base import Stage, restart, run_table
from .calibrate import calibrated
from .replay_uncertainty import with_replay_uncertainty


def estimate_torque_lags(engine: ReplayEngine, problem: Problem, effects: list[Effect], overrides: dict[str, float],
                         settings: DiagnosisSettings = DEFAULT_SETTINGS) -> tuple[list[float], float]:
    """Search each file's torque channel lag behind its rack channel on the model `effects` with `overrides`
    (with settings.torque_lag_fitted: a grid search around the file's present lag and a parabola through its best
    three) and move the file's lag there where that lowers its weighted residual sum of squares by more than
    log(samples); return (each file's lag, the largest move (s)). A file fitted on its angle keeps none."""
    if not settings.torque_lag_fitted or settings.torque_lag_max_s <= 0.0:
        return [f.torque_lag_s for f in problem.files], 0.0
    lags = np.arange(-settings.torque_lag_max_s, settings.torque_lag_max_s + 0.5 * settings.torque_lag_step_s,
                     settings.torque_lag_step_s)
    largest = 0.0
    found = [f.torque_lag_s for f in problem.files]
    for i, f in enumerate(problem.files):
        if f.uses_angle:
            continue
        replay = engine.replay(problem, effects, i)  # at the file's present replay instants
        sigma = f.sigma_Nm

        def rss(lag: float) -> float:
            try:
                torque = replay.at_times(replay.time_s - lag).torque(overrides)
            except SolverError:  # the solver gave up at these instants: not a lag to keep
                return math.inf
            return float(np.sum(((f.torque_Nm - torque) / sigma) ** 2))

        values = np.array([rss(lag) for lag in lags])
        k = int(np.argmin(values))
        best, best_rss = float(lags[k]), float(values[k])
        if 0 < k < len(lags) - 1 and np.all(np.isfinite(values[k - 1 : k + 2])):
            left, centre, right = values[k - 1 : k + 2]
            curvature = left - 2.0 * centre + right
            if curvature > 0.0:
                vertex = best + 0.5 * settings.torque_lag_step_s * (left - right) / curvature
                at_vertex = rss(vertex)
                if at_vertex < best_rss:
                    best, best_rss = vertex, at_vertex
        at_zero = values[int(np.argmin(np.abs(lags)))]
        if at_zero - best_rss > pm.log(f.n):
            found[i] = float(f.torque_lag_s + best)
            largest = max(largest, abs(best))
    return found, largest


def lags_searched(state: DiagnosisState, engine: ReplayEngine, effects: list[Effect], overrides: dict[str, float],
                  why: str) -> tuple[Problem, bool]:
    """(the state's problem on files with the lags searched on `effects` with `overrides`, whether one moved by a
    search step or more). Where one did, the progress line says so and the new problem's files have no replay
    uncertainty yet (it was made at the old instants)."""
    problem, settings = state.problem, state.settings
    lags, largest = estimate_torque_lags(engine, problem, effects, overrides, settings)
    files = [replace(f, torque_lag_s=lag) for f, lag in zip(problem.files, lags)]
    if largest < settings.torque_lag_step_s:
        return problem.with_files(files), False
    state.progress(f"torque channel behind the rack's{why}: " + ", ".join(
        f"{f.label} {1000.0 * f.torque_lag_s:.1f} ms" for f in files if f.torque_lag_s))
    files = [replace(f, replay_uncertainty_Nm=None, replay_draws_Nm=None) for f in files]
    return problem.with_files(files), True


class TorqueLag(Stage):
    name = "torque_lag"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        base = list(state.base)
        for _ in range(state.settings.torque_lag_rounds):
            problem, moved = lags_searched(state, engine, base, state.calibration.overrides,
                                           " (replay uncertainty and calibration again at the lagged instants)")
            state = replace(state, problem=problem)
            if not moved:
                break
            state = replace(state, problem=with_replay_uncertainty(state, engine, base, state.start_values))
            state = replace(state, calibration=calibrated(state, engine, state.problem))
        return state


class TorqueLagWithEffect(Stage):
    name = "torque_lag_with_effect"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        if not state.settings.torque_lag_fitted or state.verdict != "missing":
            return state
        best = state.best_candidate
        problem, moved = lags_searched(state, engine, best.signature.model, best.refit.overrides,
                                       f" (again, with {best.name}; diagnosing again)")
        if not moved:
            return replace(state, problem=problem)
        held = restart(state, problem=problem, settings=replace(state.settings, torque_lag_fitted=False))
        return replace(run_table(held, engine), settings=state.settings)
