"""A later record diagnosed against the boost table `parksteer assist identify` read from a baseline record of the
same car: a gain error within the table's own uncertainty is the baseline's, one beyond it is the car's.

The records are the independent assisted truth's (:mod:`parksteer.experiments.assisted_truth`, design seed 31337,
rack logged, 12-bit torsion-bar torque): the baseline a null on its baseline hand, the owner's file the gear's data
sheet (no map), then a null on another hand and the same car with its map's gain 5 % up (2 noise floors of the
torsion-bar torque). A later record reads the map's gain to about 0.3 % (95 %); the baseline fixes the
table's to 1.8 %.
"""

from __future__ import annotations

import tomllib

import pytest

from parksteer.reporting.pages import markdown_report
from parksteer.diagnose.problem import load_files
from parksteer.reporting.report import diagnosis_dict
from parksteer.diagnose.select import diagnose
from parksteer.errors import UsageError
from parksteer.experiments.assisted_truth import _write, baseline_record, case_truth_and_record
from parksteer.experiments.assisted_truth_design import TruthDesign, cases
from parksteer.experiments.assisted_truth_owner import identified_route, owner_file
from parksteer.experiments.benchmark import BENCHMARK_SETTINGS
from parksteer.parameters import ParameterError
from parksteer.vehicle import load_vehicle, vehicle_from_text

DESIGN = TruthDesign(tiers=("rack",), seed=31337, null_variations=("pauses",), hidden_variations=("uneven_strokes",),
                     hidden=("boost_gain_error",), floors=(2.0,), out_of_class_variations=(),
                     torque_converters=((12, 10.24),))


@pytest.fixture(scope="module")
def results(repo_root, tmp_path_factory):
    folder = tmp_path_factory.mktemp("baseline")
    vehicle = repo_root / "data" / "vehicles" / "polo_vi.toml"
    params = load_vehicle(vehicle)
    owner = owner_file(vehicle, DESIGN, folder)
    baseline = folder / "baseline.csv"
    _write(baseline, baseline_record(params, DESIGN, "rack"), owner.params)
    identified = identified_route(owner, baseline, folder)
    out = {}
    for case in cases(DESIGN):
        truth, record = case_truth_and_record(params, DESIGN, case)
        path = folder / f"{case.name}.csv"
        _write(path, record, owner.params)
        files = load_files([path], identified.params, assist=identified.assist)

        out[case.kind] = (truth, diagnosis_dict(diagnose(files, identified.params, identified.effects,
                                                         settings=BENCHMARK_SETTINGS)))
    return folder, out


def test_the_identified_file_states_its_tables_gain_uncertainty(results):
    """The written file carries the table's gain half-width, and the vehicle reader keeps it apart from the model's
    quantities (the law does not read it)."""
    folder, _ = results
    written = next(folder.glob("identified_*.toml"))
    entry = tomllib.loads(written.read_text(encoding="utf-8"))["assist"]["boost"]["gain_uncertainty"]
    assert 0.002 < entry["value"] < 0.05 and entry["unit"] == "1"
    params = load_vehicle(written)
    assert params["boost.gain_uncertainty"] == pytest.approx(entry["value"])


def test_a_gain_error_within_the_baselines_uncertainty_is_the_baselines(results):
    """Nothing changed since the baseline: the record's gain differs from the table's by a fraction of a per cent,
    a BIC gain of tens on this record alone, within the table's half-width: adequate, and the report says so."""
    _, out = results
    _, result = out["null"]
    b = result["baseline"]
    assert b["verdict_before"] == "missing" and b["within"]
    assert result["verdict"] == "adequate" and result["effect"] is None
    assert abs(b["strength"]) < 0.01 < b["gain_uncertainty"] < 0.05
    assert "the difference is the baseline's own" in markdown_report(result)


def test_a_gain_error_beyond_it_is_the_cars(results):
    """The map 5 % stronger than at the baseline: named, its interval beyond the table's half-width and holding the
    truth's change."""
    _, out = results
    truth, result = out["hidden"]
    b = result["baseline"]
    assert result["verdict"] == "missing" and result["effect"] == "boost_gain_error" and not b["within"]
    assert b["ci95"][0] - 0.01 < truth["strength"] < b["ci95"][1] + 0.01


@pytest.mark.parametrize("value", ["-0.01", "0.9", "true"])
def test_a_gain_uncertainty_that_is_no_half_width_is_refused_in_one_line(repo_root, value):
    text = (repo_root / "data" / "vehicles" / "polo_vi.toml").read_text(encoding="utf-8")
    text = text.replace("[assist.boost]\n", "[assist.boost]\n"
                        f'gain_uncertainty = {{ value = {value}, unit = "1", source = "a test" }}\n', 1)
    with pytest.raises((ParameterError, UsageError)) as caught:
        vehicle_from_text(text, "car.toml")
    assert "assist.boost.gain_uncertainty" in str(caught.value) and "\n" not in str(caught.value)
