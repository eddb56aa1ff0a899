"""The report's cost line: where a diagnosis spends its replays and its seconds, stage by stage."""

from __future__ import annotations

import re

from parksteer.reporting.cost import cost_line


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
