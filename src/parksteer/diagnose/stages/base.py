"""The contract every stage of a diagnosis keeps (:class:`Stage`) and the loop that runs a table of them
(:func:`run_table`). The table itself, and how to add a stage, is in :mod:`parksteer.diagnose.stages`; a stage's
replays run through the replay engine it is handed (:class:`parksteer.diagnose.engine.ReplayEngine`, whose
:meth:`~parksteer.diagnose.engine.ReplayEngine.in_workers` spreads a stage's independent replays over the
workers)."""

from __future__ import annotations

import time
from dataclasses import replace

from ..engine import ReplayEngine
from ..state import DiagnosisState


class Stage:
    """One step of a diagnosis: a function from a frozen state to a new one.

    `name` is the key its time takes in ``Diagnosis.timings_s`` (the JSON's ``cost.timings_s``); :meth:`message`
    is the progress line printed before it runs (None: none); :meth:`run` returns a new state
    (``dataclasses.replace``) and changes nothing in the state it was given. Its replays run on the `engine` it is
    handed, the one thing of a diagnosis that changes (its replays, counts and workers). A stage reads the
    settings from the state (``state.settings``), never from elsewhere.
    """

    name: str = ""

    def message(self, state: DiagnosisState) -> str | None:
        return None

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        raise NotImplementedError


def run_table(state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
    """Run the state's table of stages in order on `engine`, each on the state the one before returned, timing
    each and counting the replays run by its end."""
    for stage in state.table:
        clock = time.perf_counter()
        line = stage.message(state)
        if line is not None:
            state.progress(line)
        state = stage.run(state, engine)
        state = state.with_cost(stage.name, time.perf_counter() - clock, engine.evaluations)
    return state


def restart(state: DiagnosisState, **changes) -> DiagnosisState:
    """A state with this one's inputs (and `changes`, e.g. other settings or files) and nothing found yet."""
    fresh = DiagnosisState(state.settings, state.problem, state.base, state.registry, state.strengths, state.start,
                           state.progress, state.table, state.held)
    return replace(fresh, **changes)
