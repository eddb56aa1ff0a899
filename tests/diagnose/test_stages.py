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


def test_a_diagnosis_leaves_the_files_and_arguments_it_is_given_as_they_were(lagged_stiction):
    """After a diagnosis that moved the torque lag twice and diagnosed again with the lags held, every field of
    the caller's files (the lag, the replay uncertainty, the angle flag, the measured arrays) and the registry,
    start values and strengths passed in are exactly as before; the lag found is in the result's own files (the
    channel's 10 ms within 3.5 ms, as tests/diagnose/test_torque_lag.py finds it)."""
    files = load_files([lagged_stiction], PARAMS)
    registry = dict(discover_effects())
    start = {"steering.rack_friction_force": PARAMS["steering.rack_friction_force"]}  # the parameter file's
    before = [_snapshot(f) for f in files], dict(registry), dict(start)
    result = diagnose(files, PARAMS, registry=registry, start=start, settings=SEARCH)
    assert result.verdict == "missing" and result.effect == "rack_stiction"
    assert all(_same(a, _snapshot(f)) for a, f in zip(before[0], files))
    assert registry == before[1] and list(registry) == list(before[1]) and start == before[2]
    assert [f.torque_lag_s for f in files] == [0.0] and files[0].replay_uncertainty_Nm is None
    (lag,) = [f.torque_lag_s for f in result.problem.files]
    assert lag == pytest.approx(0.010, abs=0.0035)
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.verdict = "adequate"


def test_the_same_files_diagnosed_twice_give_the_same_diagnosis(lagged_stiction):
    """A diagnosis depends on the record, not on what was asked of the same file objects before: diagnosed twice,
    the same files give the same JSON, number for number (timings apart). Once, the first diagnosis's lag stayed
    in the files and the second searched from there."""
    files = load_files([lagged_stiction], PARAMS)
    runs = []
    for _ in range(2):
        out = diagnosis_dict(diagnose(files, PARAMS, settings=SEARCH))
        out["cost"].pop("timings_s")
        runs.append(json.dumps(out))
    assert runs[0] == runs[1]
