"""Replays side by side (parksteer.diagnose.parallel): the same numbers in the same order as in line."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from parksteer.diagnose.engine import ReplayEngine
from parksteer.diagnose.parallel import ServingPool, can_fork, fork_map
from parksteer.diagnose.problem import Problem, load_files
from parksteer.reporting.report import diagnosis_dict
from parksteer.diagnose.select import diagnose
from parksteer.model.symbolic.components import resolve_effects

pytestmark = pytest.mark.skipif(not can_fork(), reason="the platform cannot fork: everything runs in line")

REPO = Path(__file__).resolve().parents[2]
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


def test_a_serving_pool_forks_again_for_another_key():
    """A pool keeps serving the function it was forked with while the key stays the same (a function given later
    for that key is not used), and asked to serve another key it ends its workers and forks new ones: the answers
    for the second key are the second key's, from processes other than the first key's."""
    first, second = object(), object()
    workers = ServingPool(2)
    try:
        made = workers.map(first, lambda x: ("first", x, os.getpid()), [1, 2])
        same_key = workers.map(first, lambda x: ("other", x, os.getpid()), [3, 4])
        other_key = workers.map(second, lambda x: ("second", x, os.getpid()), [5, 6])
    finally:
        workers.close()
    assert [r[:2] for r in made] == [("first", 1), ("first", 2)]
    assert [r[:2] for r in same_key] == [("first", 3), ("first", 4)]
    assert [r[:2] for r in other_key] == [("second", 5), ("second", 6)]
    assert not {pid for *_, pid in made + same_key} & {pid for *_, pid in other_key}
    assert workers.pool is None


def test_predictions_follow_the_problem_they_are_asked_on(params):
    """Predictions of two records on one problem, then on a problem whose files' torque lags moved (new instants),
    then on the first again: two workers give the arrays one process gives, bit for bit, and the lagged problem's
    differ from the first's (the workers answer for the problem asked, not the one they were first forked for)."""
    paths = [REPO / "data" / "samples" / "car" / f"{case}__ground.csv" for case in ("unladen", "part_laden")]
    files = load_files(paths, params)
    first = Problem(files, params)
    moved = first.with_files([replace(f, torque_lag_s=0.02) for f in files])
    effects = resolve_effects(None)
    predictions = {}
    for workers in (1, 2):
        engine = ReplayEngine(workers)
        try:
            predictions[workers] = [engine.predict(problem, effects, {}) for problem in (first, moved, first)]
        finally:
            engine.close()
    for one, two in zip(predictions[1], predictions[2]):
        assert all(np.array_equal(a, b) for a, b in zip(one, two))
    assert not np.allclose(predictions[2][0][0], predictions[2][1][0], atol=1e-3)
    assert all(np.array_equal(a, b) for a, b in zip(predictions[2][0], predictions[2][2]))


@pytest.mark.parametrize("workers", [1, 2])
def test_the_engine_counts_every_solve_once_wherever_it_runs(params, monkeypatch, workers):
    """ReplayEngine.evaluations (the report's replay count) is the number of replays asked for: one on a replay
    the engine made and did not keep, one on a replay made from it on another rack, one at other instants, and
    three mapped over the workers, each once, in line or in two worker processes (counted there by an independent
    tally of the solver's calls and of the solves the memo answered, returned with each result); the three mapped
    repeat solves made before, so the memo answers them, in line and in the workers alike (forked with it)."""
    import parksteer.diagnose.replay as replay_module

    real, calls = replay_module.solve, []
    monkeypatch.setattr(replay_module, "solve", lambda *a, **k: calls.append(os.getpid()) or real(*a, **k))
    f = load_files([REPO / "data" / "samples" / "car" / "unladen__ground.csv"], params)[0]
    effects = resolve_effects(None)
    moved = {"steering.rack_friction_force": params["steering.rack_friction_force"] + 80.0}
    engine = ReplayEngine(workers)
    try:
        one_off = engine.new_replay(effects, f.case, f.surface, params, f.rack, f.time_s)
        one_off.torque()
        one_off.on_rack(f.rack).torque(moved)
        one_off.at_times(f.time_s[1:]).torque()

        def job(overrides):
            before, found = len(calls), engine.solutions.found
            one_off.torque(overrides)
            return os.getpid(), len(calls) - before, engine.solutions.found - found

        mapped = engine.map(job, [{}, moved, {}])
    finally:
        engine.close()
    in_workers = [(solves, found) for pid, solves, found in mapped if pid != os.getpid()]
    assert len(in_workers) == (3 if workers == 2 else 0)
    assert len(calls) == 3 and [found for _, _, found in mapped] == [1, 1, 1]
    assert len(calls) + sum(solves + found for solves, found in in_workers) + (engine.solutions.found
                                                                              if workers == 1 else 0) == 6
    assert engine.evaluations == 6


def test_the_separating_replays_are_the_same_in_workers_and_in_line(params):
    """differences_by_condition (where two fitted models would differ, in the conditions the data do not cover):
    spread over two workers, every row is the one a single process gives, bit for bit, and each is the RMS
    difference of two replays made alone on that condition's prepared run."""
    from parksteer.diagnose.replay import Replay
    from parksteer.diagnose.stages.separate import conditions_not_covered, differences_by_condition

    problem = Problem(load_files([REPO / "data" / "samples" / "car" / "unladen__ground.csv"], params), params)
    effects = resolve_effects(None)
    friction = params["steering.rack_friction_force"]
    runs = [(effects, {}), (effects, {"steering.rack_friction_force": friction + 80.0}),
            (effects, {"steering.rack_friction_force": friction - 50.0})]
    rows = {}
    for workers in (1, 2):
        engine = ReplayEngine(workers)
        try:
            rows[workers] = differences_by_condition(engine, problem, runs)
        finally:
            engine.close()
    assert rows[1] == rows[2]
    f = problem.files[0]
    conditions = conditions_not_covered(problem)
    assert [(r["case"], r["surface"]) for r in rows[1][0]] == conditions
    case, surface = conditions[-1]
    alone = Replay(effects, case, surface, params, f.rack, f.time_s)
    expected = float(np.sqrt(np.mean((alone.torque() - alone.torque(runs[2][1])) ** 2)))
    assert rows[2][1][-1]["predicted_difference_rms_Nm"] == expected


def test_the_replay_ensemble_is_the_same_on_two_workers(params):
    """with_replay_uncertainty (the replay's own uncertainty: racks logged again, smoothed and replayed): its
    random numbers drawn in order in this process and its racks smoothed and replayed on two workers, every
    draw's torque and the spread are the one process's, bit for bit, also with a rack rounded coarser than its
    noise (a second draw per rack, within its levels); the spread is not zero."""
    from parksteer.diagnose.ensemble import with_replay_uncertainty

    f = load_files([REPO / "data" / "samples" / "car" / "unladen__ground.csv"], params)[0]
    effects = resolve_effects(None)
    for rounding_m in (0.0, 0.0008):
        problem = Problem([replace(f, rack=replace(f.rack, rest_resolution_m=rounding_m))], params)
        found = {}
        for workers in (1, 2):
            engine = ReplayEngine(workers)
            try:
                found[workers] = with_replay_uncertainty(engine, problem, effects, draws=4).files[0]
            finally:
                engine.close()
            assert engine.evaluations == 4
        assert np.array_equal(found[1].replay_draws_Nm, found[2].replay_draws_Nm)
        assert np.array_equal(found[1].replay_uncertainty_Nm, found[2].replay_uncertainty_Nm)
        assert np.max(found[2].replay_uncertainty_Nm) > 0.0


def test_what_workers_find_of_a_models_direct_quantities_is_kept(params):
    """ReplayEngine.map keeps what its workers found of which quantities only enter a compiled model's equations
    (ReplayEngine.direct, found by preparing the run with the quantity moved): after a map whose workers replayed
    a rack friction and a wheel load moved, the engine knows both, as a replay in this process finds them (the
    friction only in the equations, the load in the preparation too), so workers forked later need not test them."""
    from parksteer.diagnose.replay import Replay

    f = load_files([REPO / "data" / "samples" / "car" / "unladen__ground.csv"], params)[0]
    effects = resolve_effects(None)
    moves = [{"steering.rack_friction_force": params["steering.rack_friction_force"] + 80.0},
             {"case.load_left": 1.05 * params["cases.unladen.load_left"]}]
    engine = ReplayEngine(2)
    try:
        replay = engine.new_replay(effects, f.case, f.surface, params, f.rack, f.time_s)
        pids = engine.map(lambda overrides: replay.torque(overrides).size and os.getpid(), moves)
    finally:
        engine.close()
    alone = Replay(effects, f.case, f.surface, params, f.rack, f.time_s)
    for overrides in moves:
        alone.torque(overrides)
    assert os.getpid() not in pids  # found by the workers alone
    assert engine.direct == alone.direct
    assert sorted(engine.direct.values()) == [False, True]
