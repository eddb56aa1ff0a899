"""The report's cost line: where a diagnosis spends its replays and its seconds, stage by stage."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import pytest

from parksteer.diagnose.parallel import can_fork
from parksteer.diagnose.problem import Problem, load_files
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.diagnose.stages.separate import conditions_not_covered
from parksteer.reporting.cost import cost_line
from parksteer.reporting.report import diagnosis_dict

ROOT = Path(__file__).resolve().parents[2]


def test_the_cost_line_splits_the_replays_and_seconds_by_stage():
    """The stages' replays (the differences of the running counts each stage ended at) add up to the diagnosis's
    replays, the stages' seconds to its total; a stage with no replay under a hundredth of a second is left out."""
    cost = {"replays": 60,
            "replays_by_stage": {"nominal": 9, "calibration": 21, "torque_lag": 21, "scores": 45, "refits": 60,
                                 "verdict": 60},
            "timings_s": {"nominal": 0.64, "calibration": 0.25, "torque_lag": 0.001, "scores": 0.81, "refits": 0.35,
                          "verdict": 0.0}}
    line = cost_line(cost)
    inside = line[line.index("(") + 1 : line.rindex(")")]
    stages = {name: (int(n), float(s)) for name, n, s in re.findall(r"(\w[\w ]*): (\d+) replays, ([\d.]+) s", inside)}
    assert list(stages) == ["nominal", "calibration", "scores", "refits"]
    assert sum(n for n, _ in stages.values()) == 60
    assert line.startswith("Cost: 60 replays, 2.05 s (")
    assert abs(sum(s for _, s in stages.values()) - 2.05) < 0.011


def test_a_cost_without_timings_gives_the_replays_alone():
    """A result written without its timings (a test's, or one whose machine times were dropped) still states its
    replays."""
    assert cost_line({"replays": 7}) == "Cost: 7 replays."


@pytest.mark.slow
@pytest.mark.skipif(not can_fork(), reason="the platform cannot fork: the workers' count is the in-line one")
def test_every_replay_of_the_identification_stage_is_counted_in_line_and_in_workers(params):
    """The identification stage replays each calibrated parameter that the data do not fix at both ends of its
    interval under every load case and surface the record does not cover (stages/identify.py): with the
    threshold of "fixed" at 0, none of the three is fixed, and the stage's replays in the cost (the difference of
    the running counts either side of it) are exactly 3 parameters x 2 ends x the uncovered conditions, whether
    the conditions are replayed in this process or spread over two workers (whose solves reach the count through
    ReplayEngine.map)."""
    files = load_files([ROOT / "data" / "measurements" / "example_unladen.csv"], params)
    settings = replace(DEFAULT_SETTINGS, identified_relative_halfwidth=0.0, confound_tests=False)
    conditions = len(conditions_not_covered(Problem(files, params)))
    assert conditions > 0
    for workers in (1, 2):
        result = diagnose(files, params, settings=settings, workers=workers)
        unfixed = [r for r in result.identification if r["status"] == "not fixed"]
        assert len(unfixed) == 3 and all(r["fixed_by"] is not None for r in unfixed)
        by_stage = list(diagnosis_dict(result)["cost"]["replays_by_stage"].items())
        at = [name for name, _ in by_stage].index("identification")
        assert by_stage[at][1] - by_stage[at - 1][1] == 3 * 2 * conditions, workers
