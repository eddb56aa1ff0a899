"""Synthetic data sets with something hidden: sizes, disturbances, and the truth kept out of the files."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.synthetic.datasets import (
    DISTURBANCES,
    Disturbance,
    benchmark_specs,
    clean_run,
    hand,
    torque_step_Nm,
)
from parksteer.model.symbolic.components import discover_effects


def test_hidden_imbalance_has_the_requested_rms(written, params):
    """The out-of-balance column adds T_u sin(column angle) to the handwheel torque; over several column turns its
    RMS is T_u / sqrt(2), so 3 converter steps RMS need T_u close to 3 x 0.196 N m x sqrt(2) = 0.83 N m; and
    regenerating the clean runs with and without it gives the 3 steps RMS the bisection aimed at (within 5 %)."""
    paths, truth = written("imbalance_3", kind="outside", hidden="column_imbalance", steps=3.0)
    step = torque_step_Nm(params)
    assert truth["strength"] == pytest.approx(3.0 * step * np.sqrt(2.0), rel=0.1)
    profile = hand(params, truth["seed"] * 100)
    disturbance = Disturbance("column_imbalance", truth["strength"], truth["phase"])
    effects, overrides = disturbance.effects_and_overrides()
    with_it = clean_run(params, "unladen", "ground", profile, effects, overrides)["handwheel_torque_Nm"]
    without = clean_run(params, "unladen", "ground", profile)["handwheel_torque_Nm"]
    assert np.sqrt(np.mean((with_it - without) ** 2)) == pytest.approx(3.0 * step, rel=0.05)


def test_the_truth_stays_out_of_the_files(written):
    """A measurement file says it is synthetic and how it was logged, never what is hidden in it."""
    paths, truth = written("imbalance_3", kind="outside", hidden="column_imbalance", steps=3.0)
    text = paths[0].read_text(encoding="utf-8")
    header = [line for line in text.splitlines() if line.startswith("#")]
    keys = {line[1:].partition(":")[0].strip() for line in header}
    assert "# synthetic: true" in header
    assert "imbalance" not in text
    assert not keys & {"model", "model_key", "components", "effects", "hidden", "strength", "drive"}


def test_a_drift_from_zero_to_a_has_rms_a_over_root_3(params):
    """A sensor zero drifting linearly from 0 to a over the record adds an error of RMS a / sqrt(3)."""
    t = np.linspace(0.0, 18.0, 9001)
    columns = {"time_s": t, "handwheel_torque_Nm": np.zeros_like(t), "rack_m": np.zeros_like(t)}
    drifted = Disturbance("torque_drift", 0.9).apply(params, columns)["handwheel_torque_Nm"]
    assert drifted[0] == 0.0 and drifted[-1] == pytest.approx(0.9)
    assert np.sqrt(np.mean(drifted**2)) == pytest.approx(0.9 / np.sqrt(3.0), rel=1e-3)


def test_a_damaged_tooth_repeats_once_per_pinion_turn(params):
    """The transmission error of one pinion tooth recurs every 2 pi / G of rack travel (G = 186.47 rad/m: 33.7 mm),
    and scales the torque by 1 + A G cos(G x + phase)."""
    ratio = params["steering.handwheel_to_rack_ratio"]
    rack = np.linspace(0.0, 0.2, 20001)
    columns = {"time_s": np.linspace(0, 1, rack.size), "handwheel_torque_Nm": np.full(rack.size, 10.0), "rack_m": rack}
    out = Disturbance("gear_tooth", 1e-4).apply(params, columns)
    torque = out["handwheel_torque_Nm"]
    peaks = rack[1:-1][(torque[1:-1] > torque[:-2]) & (torque[1:-1] >= torque[2:])]
    assert np.diff(peaks) == pytest.approx(2 * np.pi / ratio, rel=1e-3)
    assert torque.max() == pytest.approx(10.0 * (1 + 1e-4 * ratio), rel=1e-4)


def test_a_lagging_torque_channel_shows_the_reversal_drop_late(params):
    """A torque channel late by 0.1 s shows the drop at the reversal 0.1 s after the rack turns."""
    profile = hand(params, 11)
    clean = clean_run(params, "unladen", "ground", profile)
    lagged = Disturbance("channel_lag", 0.1).apply(params, clean)
    t = clean["time_s"]
    window = (t > 3.5) & (t < 6.0)  # around the reversal at right lock (4.5 s)
    drop_clean = t[window][np.argmin(np.diff(clean["handwheel_torque_Nm"][window]))]
    drop_lagged = t[window][np.argmin(np.diff(lagged["handwheel_torque_Nm"][window]))]
    assert drop_lagged - drop_clean == pytest.approx(0.1, abs=0.01)


def test_the_benchmark_covers_every_candidate_nulls_and_disturbances(params, benchmark_design):
    """Every candidate of the registry at every strength, the nulls, and every disturbance outside the library at
    each size, and nothing else; all seeds distinct; base perturbations within their stated ranges."""
    specs = benchmark_specs(params, benchmark_design)
    registry = discover_effects()
    candidates = sorted(n for n, e in registry.items() if not e.in_default_set and e.diagnosis_candidate)
    assert len(specs) == (len(candidates) * len(benchmark_design.steps) + benchmark_design.nulls
                          + len(DISTURBANCES) * len(benchmark_design.disturbance_steps))
    for name in candidates:
        assert sorted(s.steps for s in specs if s.hidden == name) == sorted(benchmark_design.steps)
    assert sum(s.kind == "null" for s in specs) == benchmark_design.nulls
    assert {s.hidden for s in specs if s.kind == "outside"} == set(DISTURBANCES)
    assert len({s.seed for s in specs}) == len(specs)
    for s in specs:
        for key, value in s.base_overrides.items():
            assert abs(value / params[key] - 1.0) <= benchmark_design.perturbation[key]


def test_a_hidden_candidates_record_simulates_each_run_once(params, benchmark_design, monkeypatch):
    """A data set's size search ends on the clean run at the strength it returns; the truth's size and the record
    are that run: no file is simulated twice with the same effects and values, and the record's clean torque is
    the run at the truth's strength (its RMS change from the base run is the truth's steps, as the size is defined)."""
    import parksteer.synthetic.datasets as datasets

    runs = []
    original = datasets.clean_run

    def counted(params, case, surface, profile, effects=None, overrides=None):
        runs.append((case, surface, id(profile), effects,
                     tuple(sorted((overrides or {}).items()))))
        return original(params, case, surface, profile, effects, overrides)

    monkeypatch.setattr(datasets, "clean_run", counted)
    spec = datasets.DatasetSpec("rack_damping_2", 4243, (("unladen", "ground"),), "candidate", "rack_damping", 2.0,
                                {}, search=benchmark_design.search)
    truth = datasets.make_dataset(params, spec).truth
    assert len(runs) == len(set(runs))
    profile = hand(params, spec.seed * 100)
    key = truth["strength_key"]
    with_it = original(params, "unladen", "ground", profile, "+rack_damping", {key: truth["strength"]})
    without = original(params, "unladen", "ground", profile)
    change = np.sqrt(np.mean((with_it["handwheel_torque_Nm"] - without["handwheel_torque_Nm"]) ** 2))
    assert change / torque_step_Nm(params) == pytest.approx(truth["steps"], rel=1e-12)
