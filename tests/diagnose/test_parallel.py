"""Replays side by side (parksteer.diagnose.parallel): the same numbers in the same order as in line."""

from __future__ import annotations

import os

import pytest

from parksteer.diagnose.parallel import can_fork, fork_map
from parksteer.diagnose.problem import load_files
from parksteer.diagnose.report import diagnosis_dict
from parksteer.diagnose.select import diagnose

pytestmark = pytest.mark.skipif(not can_fork(), reason="the platform cannot fork: everything runs in line")

TWO_FILES = (("unladen", "ground"), ("part_laden", "ground"))


def test_fork_map_keeps_the_order_and_runs_in_other_processes():
    """Each item's result comes back in the items' order; with two workers the work runs outside this process,
    and a map inside a worker runs in line there (no process forks twice)."""
    parent = os.getpid()

    def work(x):
        inner = fork_map(lambda y: os.getpid(), range(3), 2)
        return x * x, os.getpid(), inner

    out = fork_map(work, range(5), 2)
    assert [r[0] for r in out] == [x * x for x in range(5)]
    assert all(pid != parent for _, pid, _ in out)
    assert all(inner == [pid] * 3 for _, pid, inner in out)
    assert fork_map(lambda x: (x, os.getpid()), range(3), 1) == [(x, parent) for x in range(3)]


def test_two_workers_give_the_diagnosis_of_one(written, params, capsys):
    """A diagnosis of two files (moved base parameters, nothing hidden) with two workers, which replays the files
    side by side, and the candidates on a worker each, reports exactly what one worker reports: verdict, ranking,
    fitted values, statistics and replay count; with quiet=False each step says on stderr where it is."""
    paths, _ = written("null_two_files", kind="null", files=TWO_FILES,
                       base_overrides={"steering.rack_friction_force": 650.0})
    results = []
    for workers in (1, 2):
        d = diagnose(load_files(paths, params), params, workers=workers, quiet=workers == 1)
        result = diagnosis_dict(d)
        result["cost"].pop("timings_s", None)
        result["cost"].pop("wall_s", None)
        results.append(result)
    assert results[0] == results[1]
    lines = capsys.readouterr().err.splitlines()
    assert any("calibrating" in line for line in lines) and any("ranking" in line for line in lines)
    assert lines[-1].startswith(f"diagnose: verdict: {results[0]['verdict']}")
