"""The replay engine: everything of a diagnosis that replays and changes, in one object the stages are handed.

:func:`parksteer.diagnose.select.diagnose` makes one :class:`ReplayEngine` and hands it to every stage
(``stage.run(state, engine)``); the state a stage returns is frozen, the engine openly mutable, keeping its counts on
itself as scipy's ``OdeSolver`` keeps ``nfev``. It owns:

- `models`: the compiled models loaded, each found again by its effects (:class:`LoadedModels`);
- `hosts`: which compiled model each effect set is replayed on
  (:func:`parksteer.diagnose.candidates.replay_models`);
- `direct`: which quantities only enter a compiled model's equations
  (:meth:`parksteer.diagnose.replay.Replay._is_direct`);
- `prepared`: the prepared runs by host model, case, surface and parameters, shared by every replay on them;
- `replays`: one :class:`parksteer.diagnose.replay.Replay` per effect set, file and torque lag (the kept ones);
- `solves`: the count every replay it makes adds its solves to, kept or not (a replay on another rack or at
  other instants made from one of them too: :class:`parksteer.diagnose.replay.SolveCount`);
- `solutions`, `smoothed_racks`: the latest solves by their exact inputs
  (:class:`parksteer.diagnose.replay.SolutionMemo`), and the racks the replay ensemble smooths again
  (:meth:`parksteer.measure.smoothing.SmoothedRack.smoothed_at`), each asked again by a later stage;
- `pool`, `workers`: the worker processes a prediction spreads its files over (:mod:`parksteer.diagnose.parallel`),
  forked for each problem they serve, holding the diagnosis's effects and their classes;
- `other_replays`: the solves run in worker processes, which each worker's copy of `solves` counted, so that
  :attr:`evaluations` counts every solve, wherever it ran.

How the stages use it: docs/diagnosis.md.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..model.numeric.compiled import CompiledModel, CompiledModels
from ..model.symbolic.components import Effect
from .parallel import ServingPool, fork_map, forks
from .problem import Problem
from .replay import Replay, SolutionMemo, SolveCount


class LoadedModels(CompiledModels):
    """The compiled models of one diagnosis, each effect set's found once: the cache key hashes the symbolic
    half's and the effects' source (:func:`parksteer.model.codegen.cache.model_key`), which a diagnosis does not
    change, and every prepared run of the set would hash it again."""

    def __init__(self) -> None:
        super().__init__()
        # the effects' ids -> (the effects, kept so that their ids stay theirs; the compiled model)
        self.by_effects: dict[tuple[int, ...], tuple[list[Effect], CompiledModel]] = {}

    def of(self, effects: list[Effect]) -> CompiledModel:
        key = tuple(map(id, effects))
        if key not in self.by_effects:
            self.by_effects[key] = (list(effects), super().of(effects))
        return self.by_effects[key][1]


def effect_key(effects: list[Effect]) -> tuple[str, ...]:
    """An effect set's key: its effects' names, sorted."""
    return tuple(sorted(e.name for e in effects))


def inherited_effects(effects: list[Effect]) -> tuple:
    """`effects` and their classes, each once, in order: what a diagnosis's workers hold when forked, so that a
    prediction's tasks name them by place (:class:`parksteer.diagnose.parallel.InheritedPickler`), a class loaded
    from a user's file or made by a factory among them."""
    found: dict[int, object] = {}
    for effect in effects:
        found.setdefault(id(effect), effect)
        found.setdefault(id(type(effect)), type(effect))
    return tuple(found.values())


class ReplayEngine:
    """The replays of one diagnosis (module docstring). `workers` > 1 spreads independent replays over forked
    processes (the same numbers as in line); `hosts` maps an effect set's key (:func:`effect_key`) to the effects
    of the compiled model it is replayed on, each host's effects beyond the set absent at their values in the
    parameters (:func:`parksteer.diagnose.candidates.shares_diagnosis_model`); the workers hold the hosts'
    effects and `effects` (the diagnosis's model and candidates), which a prediction may replay
    (:func:`inherited_effects`). :meth:`close` ends the pool, :meth:`terminate` at once (on an interrupt or an
    error)."""

    def __init__(self, workers: int = 1, hosts: dict[tuple[str, ...], list[Effect]] | None = None,
                 effects: tuple[Effect, ...] = ()):
        self.workers = max(int(workers), 1)
        self.models = LoadedModels()
        self.hosts: dict[tuple[str, ...], list[Effect]] = dict(hosts or {})
        self.direct: dict[tuple[str, str], bool] = {}
        # (host key, case, surface, id(parameters)) -> (the parameters, kept so that their id stays theirs; runs)
        self.prepared: dict[tuple, tuple[object, dict]] = {}
        self.replays: dict[tuple, Replay] = {}
        self.solves = SolveCount()
        self.solutions = SolutionMemo()
        self.smoothed_racks: dict[tuple, tuple] = {}
        self.other_replays = 0
        self.pool = ServingPool(self.workers, inherited_effects([*effects, *(e for host in self.hosts.values()
                                                                          for e in host)]))

    @property
    def evaluations(self) -> int:
        """Every solve run so far: those of the replays made here (:attr:`solves`) and :attr:`other_replays`."""
        return self.solves.solves + self.other_replays

    def count(self, evaluations: int) -> None:
        """Count solves run in worker processes (whose replays counted them in their own copy of :attr:`solves`)."""
        self.other_replays += evaluations

    def new_replay(self, effects: list[Effect], case: str, surface: str, params, rack, time_s) -> Replay:
        """A replay of `effects` on its host's compiled model, sharing what the engine knows of that model and the
        runs prepared on it; not kept, its solves counted in :attr:`solves`."""
        model_effects = self.hosts.get(effect_key(effects), list(effects))
        key = (effect_key(model_effects), case, surface, id(params))
        if key not in self.prepared:
            self.prepared[key] = (params, {})
        return Replay(list(effects), case, surface, params, rack, time_s, model_effects=model_effects,
                      direct=self.direct, models=self.models, shared_runs=self.prepared[key][1], counter=self.solves,
                      solutions=self.solutions)

    def replay(self, problem: Problem, effects: list[Effect], index: int) -> Replay:
        """The kept replay of `effects` on file `index` of `problem`, at the file's instants (made when first asked
        for at the file's torque lag)."""
        f = problem.files[index]
        key = (effect_key(effects), index, f.torque_lag_s)
        if key not in self.replays:
            self.replays[key] = self.new_replay(effects, f.case, f.surface, problem.params, f.rack, f.replay_time_s)
        return self.replays[key]

    def signals(self, problem: Problem, effects: list[Effect], index: int, overrides: dict[str, float] | None = None,
                replay: Replay | None = None) -> np.ndarray:
        """File `index`'s fitted signals replayed: the torque, then the handwheel angle or the motor channel where
        fitted.

        The angle channel's zero is the sensor's, not the model's: with ``angle_offset_fitted`` the replayed
        angle is shifted by the mean of the measured minus replayed angle (a constant fitted in closed form)."""
        f = problem.files[index]
        replay = replay if replay is not None else self.replay(problem, effects, index)
        if f.uses_motor:  # an assisted car's torsion-bar torque and its motor's current or torque
            solution = replay.solve(overrides)
            motor = solution.motor_current_A if f.motor_column == "motor_current_A" else solution.motor_torque_Nm
            return np.concatenate([solution.torque_Nm, motor])
        if not f.uses_angle:
            return replay.torque(overrides)
        solution = replay.solve(overrides, outputs=True)
        angle = solution.handwheel[:, 0]
        if problem.angle_offset_fitted:
            angle = angle + float(np.mean(f.angle_rad - angle))
        return np.concatenate([solution.torque_Nm, angle])

    def parallel_files(self, problem: Problem) -> bool:
        """Whether predictions on `problem` spread its files over the workers (else the callers spread candidates)."""
        return len(problem.files) > 1 and forks(len(problem.files), self.workers)

    def predict(self, problem: Problem, effects: list[Effect], overrides: dict[str, float] | None = None
                ) -> list[np.ndarray]:
        """The fitted signals replayed at every file's samples (one array per file).

        With several files and workers, on workers forked for `problem` (:class:`parksteer.diagnose.parallel.
        ServingPool`: forked again when the problem is another); a worker's replays are its own copies, each what
        its key says (module docstring), so the numbers are those of the files replayed in line."""
        if self.parallel_files(problem):
            tasks = [(list(effects), i, overrides) for i in range(len(problem.files))]
            out = self.pool.map(problem, lambda task: self.signals(problem, *task), tasks)
            if out is not None:
                self.count(len(tasks))
                return out
        return [self.signals(problem, effects, i, overrides) for i in range(len(problem.files))]

    def map(self, function: Callable, items: list) -> list:
        """``[function(item) for item in items]`` on the workers (:func:`parksteer.diagnose.parallel.fork_map`),
        the solves they ran counted (in line, :attr:`solves` counts them itself), and what they found of which
        quantities only enter a compiled model's equations (:attr:`direct`, a property of the model) kept here, so
        that workers forked later do not test it again."""
        if not forks(len(items), self.workers):
            return [function(item) for item in items]

        def counted(item):
            before, known = self.evaluations, set(self.direct)
            result = function(item)
            return result, self.evaluations - before, {k: v for k, v in self.direct.items() if k not in known}

        out = fork_map(counted, items, self.workers)
        self.count(sum(evaluations for _, evaluations, _ in out))
        for _, _, found in out:
            for known, direct in found.items():
                self.direct.setdefault(known, direct)
        return [result for result, _, _ in out]

    def in_workers(self, problem: Problem, function: Callable, items: list, by_candidate: bool) -> list:
        """`function` over `items` (candidates), spread over the workers if `by_candidate` or the predictions do
        not spread the files (:meth:`map`). `function` must return what pickles: a result that holds effects
        returns a copy without them (``dataclasses.replace``), and the caller puts them back."""
        if self.parallel_files(problem) and not by_candidate:
            return [function(item) for item in items]
        return self.map(function, items)

    def close(self) -> None:
        """End the worker pool, if one was started; later predictions run in line."""
        self.workers = 1
        self.pool.close()

    def terminate(self) -> None:
        """End the worker pool now, its work unfinished (an interrupt, an error); later predictions run in line."""
        self.workers = 1
        self.pool.terminate()
