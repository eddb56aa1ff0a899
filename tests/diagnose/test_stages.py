"""The diagnosis as a table of stages over a frozen state (parksteer.diagnose.stages): a diagnosis reads the files
it is given and changes nothing in them, so that the answer about a record does not depend on what was asked of
it before.

The record is the variation benchmark's lagged logger (the torque channel 10 ms behind the rack at 50 Hz) with a
rack stiction hidden, diagnosed with the lag search on: the search moves each file's lag, and the named stiction
moves it again, so the table is run a second time with the lags held (stages/torque_lag.py) -- every path by which
the diagnosis once wrote into the caller's files (their lag, their replay uncertainty, whether their angle is
fitted).
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import replace

import numpy as np
import pytest

from parksteer.diagnose.problem import load_files
from parksteer.reporting.report import diagnosis_dict
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.measure.io import write_measurement
from parksteer.model.symbolic.components import discover_effects
from parksteer.parameters import load_parameters
from parksteer.synthetic.variations import variation_by_name, variation_record

PARAMS = load_parameters()
SEARCH = replace(DEFAULT_SETTINGS, torque_lag_fitted=True)


def _snapshot(value):
    """A deep copy of a file's fields (arrays copied), to compare with after a diagnosis."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _snapshot(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, np.ndarray):
        return value.copy()
    if isinstance(value, dict):
        return {k: _snapshot(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_snapshot(v) for v in value]
    return value


def _same(a, b) -> bool:
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and a.shape == b.shape and bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    return a is b or a == b


@pytest.fixture(scope="module")
def lagged_stiction(tmp_path_factory):
    hand, logger = variation_by_name("lag_10ms_50Hz").settings(8)
    path = tmp_path_factory.mktemp("stages") / "lag_10ms_50Hz_8.csv"
    record = variation_record(PARAMS, hand, logger, effects="+rack_stiction",
                              overrides={"rack_stiction.breakaway_excess": 760.0})
    write_measurement(path, record, PARAMS)
    return path


@pytest.fixture(scope="module")
def first(lagged_stiction):
    """The record's files diagnosed once (the lag searched), with the parameter file's rack friction as the start
    value and the effects found as the registry passed in: (files, registry, start, their copies made before the
    diagnosis, their copies made after it, the diagnosis)."""
    files = load_files([lagged_stiction], PARAMS)
    registry = dict(discover_effects())
    start = {"steering.rack_friction_force": PARAMS["steering.rack_friction_force"]}  # the parameter file's
    before = [_snapshot(f) for f in files], dict(registry), dict(start)
    result = diagnose(files, PARAMS, registry=registry, start=start, settings=SEARCH)
    after = [_snapshot(f) for f in files], dict(registry), list(registry), dict(start)
    return files, registry, start, before, after, result


def test_a_diagnosis_leaves_the_files_and_arguments_it_is_given_as_they_were(first):
    """After a diagnosis that moved the torque lag twice and diagnosed again with the lags held, every field of
    the caller's files (the lag, the replay uncertainty, the angle flag, the measured arrays) and the registry,
    start values and strengths passed in are exactly as before; the lag found is in the result's own files (the
    channel's 10 ms within 3.5 ms, as tests/diagnose/test_torque_lag.py finds it)."""
    _, _, _, before, (files_after, registry, registry_order, start), result = first
    assert result.verdict == "missing" and result.effect == "rack_stiction"
    assert all(_same(a, b) for a, b in zip(before[0], files_after)) and len(files_after) == len(before[0])
    assert registry == before[1] and registry_order == list(before[1]) and start == before[2]
    assert [f["torque_lag_s"] for f in files_after] == [0.0] and files_after[0]["replay_uncertainty_Nm"] is None
    (lag,) = [f.torque_lag_s for f in result.problem.files]
    assert lag == pytest.approx(0.010, abs=0.0035)
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.verdict = "adequate"


def test_the_same_files_diagnosed_twice_give_the_same_diagnosis(first):
    """A diagnosis depends on the record, not on what was asked of the same file objects before: diagnosed twice,
    the same files give the same JSON, number for number (timings apart). Once, the first diagnosis's lag stayed
    in the files and the second searched from there. The first diagnosis is the module's (the files, registry and
    start values passed in again as they were)."""
    files, registry, start, _, _, result = first
    runs = []
    for diagnosis in (result, diagnose(files, PARAMS, registry=registry, start=start, settings=SEARCH)):
        out = diagnosis_dict(diagnosis)
        out["cost"].pop("timings_s")
        runs.append(json.dumps(out))
    assert runs[0] == runs[1]
