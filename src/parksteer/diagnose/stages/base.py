"""The contract every stage of a diagnosis keeps (:class:`Stage`), the loop that runs a table of them
(:func:`run_table`), and the helper that spreads a stage's independent replays over the workers
(:func:`in_workers`). The table itself, and how to add a stage, is in :mod:`parksteer.diagnose.stages`."""

from __future__ import annotations

import time
from dataclasses import replace

from ..parallel import fork_map, forks
from ..problem import Problem
from ..state import DiagnosisState


class Stage:
    """One step of a diagnosis: a function from a frozen state to a new one.

    `name` is the key its time takes in ``Diagnosis.timings_s`` (the JSON's ``cost.timings_s``); :meth:`message`
    is the progress line printed before it runs (None: none); :meth:`run` returns a new state
    (``dataclasses.replace``) and changes nothing it was given. A stage reads the settings from the state
    (``state.settings``), never from elsewhere.
    """

    name: str = ""

    def message(self, state: DiagnosisState) -> str | None:
        return None

    def run(self, state: DiagnosisState) -> DiagnosisState:
        raise NotImplementedError


def run_table(state: DiagnosisState) -> DiagnosisState:
    """Run the state's table of stages in order, each on the state the one before returned, timing each and
    counting the replays run by its end."""
    for stage in state.table:
        clock = time.perf_counter()
        line = stage.message(state)
        if line is not None:
            state.progress(line)
        state = stage.run(state)
        state = state.with_cost(stage.name, time.perf_counter() - clock)
    return state


def restart(state: DiagnosisState, **changes) -> DiagnosisState:
    """A state with this one's inputs (and `changes`, e.g. other settings or files) and nothing found yet."""
    fresh = DiagnosisState(state.settings, state.problem, state.base, state.registry, state.strengths, state.start,
                           state.progress, state.table)
    return replace(fresh, **changes)


def in_workers(problem: Problem, function, items: list, by_candidate: bool) -> list:
    """`function` over `items` (candidates), spread over the workers if `by_candidate` or the predictions do
    not spread the files; the replays the workers ran are counted. `function` must return what pickles: a
    result that holds effects returns a copy without them (``dataclasses.replace``), and the caller puts them
    back."""
    if (problem.parallel_files and not by_candidate) or not forks(len(items), problem.workers):
        return [function(item) for item in items]

    def counted(item):
        before = problem.evaluations
        return function(item), problem.evaluations - before

    out = fork_map(counted, items, problem.workers)
    problem.count_extra(sum(evaluations for _, evaluations in out))
    return [result for result, _ in out]
