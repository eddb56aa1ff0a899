"""A gain error within what the baseline fixed: the verdict against a boost table identified from the car's log.

``parksteer assist identify`` writes, beside the table it reads from a baseline record, the 95 % half-width of
the table's common gain (``[assist.boost] gain_uncertainty``: what the points' intervals leave of one scale of
all of them). A later record of the same car reads the map's gain more finely than one baseline fixes it (its
current against its torsion-bar torque, thousands of samples at 0.05 A), so the candidate ``boost_gain_error``
fitted to it finds the baseline table's own error: a fraction of a per cent, within the table's half-width of
one to two per cent, with a BIC gain of tens. That is no effect of the car. Where the best candidate is the gain
error and its 95 % interval lies within the file's half-width, the verdict is ``adequate`` and the report says
by how much the record's gain differs from the table's; a gain error reaching beyond the half-width stands (a
change of the map since the baseline, or a table read on too short a baseline). A file that states its map (no
``gain_uncertainty``) is taken as exact.
"""

from __future__ import annotations

from dataclasses import replace

from ...vehicle import BOOST_GAIN_UNCERTAINTY
from ..engine import ReplayEngine
from ..state import DiagnosisState
from .base import Stage

GAIN_CANDIDATE = "boost_gain_error"
GAIN_KEY = f"{GAIN_CANDIDATE}.strength"


def gain_uncertainty(params) -> float | None:
    """The file's identified table's gain half-width (relative), or None for a map the file states."""
    section, _, key = BOOST_GAIN_UNCERTAINTY.partition(".")
    value = params.sections.get(section, {}).get(key)
    return None if value is None else float(value)


class Baseline(Stage):
    name = "baseline"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        band = gain_uncertainty(state.problem.params)
        best = state.best_candidate
        if band is None or best is None or best.name != GAIN_CANDIDATE or best.refit is None:
            return state
        interval = best.refit.intervals(state.problem)[GAIN_KEY]
        low, high = (float(x) for x in interval["ci95"])
        within = -band <= low and high <= band
        found = {"effect": GAIN_CANDIDATE, "strength": float(interval["value"]), "ci95": [low, high],
                 "gain_uncertainty": band, "within": within, "verdict_before": state.verdict}
        state = state.with_output(self.name, found)
        if within and state.verdict == "missing":
            state = replace(state, verdict="adequate")
        return state
