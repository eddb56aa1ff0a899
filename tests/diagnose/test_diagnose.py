"""parksteer diagnose: verdicts on data whose truth is known, the JSON schema, the error ladder, a user's effect."""

from __future__ import annotations

import json

import jsonschema
import numpy as np
import pytest

from parksteer.cli import main
from parksteer.reporting.ladder import error_ladder
from parksteer.diagnose.problem import load_files
from parksteer.reporting.report import SCHEMA_PATH, diagnosis_dict
from parksteer.diagnose.select import diagnose
from parksteer.synthetic.datasets import USER_EFFECT_PATH
from parksteer.model.symbolic.components import MODULES_ENV, discover_effects, load_effect_module

# Base parameters moved off the parameter file's values, as a real car's would be: a diagnosis must calibrate them.
OFF_NOMINAL = {"tyre.friction_coefficient": 0.70, "steering.rack_friction_force": 650.0,
               "tyre.carcass_torsional_stiffness": 800.0}


@pytest.fixture(scope="module")
def schema():
    return json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def registry_with_user_effect():
    registry = discover_effects()
    effect = load_effect_module(str(USER_EFFECT_PATH))
    registry[effect.name] = effect
    return registry


@pytest.fixture(scope="module")
def hidden_user_effect(written, params, registry_with_user_effect):
    """The example's out-of-balance column hidden at 5 converter steps, diagnosed with the effect registered.

    Its phase (where the mass sits on the column) is the effect's default: a user who adds the effect knows it,
    and only its strength is fitted.
    """
    paths, truth = written("imbalance_5", kind="outside", hidden="column_imbalance", steps=5.0,
                           base_overrides=OFF_NOMINAL, phase=0.0)
    files = load_files(paths, params)
    return diagnose(files, params, registry=registry_with_user_effect), truth


@pytest.fixture(scope="module")
def null_diagnosis(diagnosed):
    return diagnosed("null_off_nominal", kind="null", base_overrides=OFF_NOMINAL)


@pytest.fixture(scope="module")
def drift_diagnosis(written, params):
    paths, _ = written("drift_5", kind="outside", hidden="torque_drift", steps=5.0, base_overrides=OFF_NOMINAL)
    return diagnose(load_files(paths, params), params)


def test_a_hidden_library_candidate_is_named_with_its_strength(written, params):
    """Rack breakaway friction 400 N above the kinetic level (a steering gear that has stood), hidden in one cycle
    with moved base parameters: the diagnosis names rack_stiction, its 95 % interval for the excess force holds
    the hidden one and excludes zero, and the kinetic rack friction is found within 3 %. The excess shows only at
    the reversals, where the replay is least certain (the knot spacings the rack data allow place the turn
    differently), so the data fix it to about half its size (451 N, 216 to 687 N); an ensemble about the chosen
    spline alone claimed 367 to 381 N, which missed the hidden 400 N."""
    paths, truth = written("stiction_400", kind="candidate", hidden="rack_stiction", strength=400.0,
                           base_overrides=OFF_NOMINAL)
    diagnosis = diagnose(load_files(paths, params), params)
    assert diagnosis.verdict == "missing" and diagnosis.effect == "rack_stiction"
    values = diagnosis.best.refit.values
    low, high = diagnosis.best.refit.intervals(diagnosis.problem)["rack_stiction.breakaway_excess"]["ci95"]
    assert 0.0 < low <= 400.0 <= high
    assert values["steering.rack_friction_force"] == pytest.approx(OFF_NOMINAL["steering.rack_friction_force"],
                                                                  rel=0.03)


def test_nothing_hidden_is_adequate_once_calibrated(null_diagnosis):
    """Data from the paper's model with moved parameters: the calibrated model sits at the noise floor and no
    candidate is called missing; the calibration finds the moved friction force within 3 % (a wrong parameter is
    not mistaken for a missing effect)."""
    assert null_diagnosis.verdict == "adequate"
    assert null_diagnosis.effect is None
    force = null_diagnosis.calibration.values["steering.rack_friction_force"]
    assert force == pytest.approx(OFF_NOMINAL["steering.rack_friction_force"], rel=0.03)


def test_a_disturbance_outside_the_library_is_unexplained(drift_diagnosis):
    """A drifting torque-sensor zero is no mechanism of the library: the residual stays structured (well above the
    noise floor) and no candidate removes most of it."""
    assert drift_diagnosis.verdict == "unexplained"
    assert drift_diagnosis.effect is None
    stats = drift_diagnosis.statistics(drift_diagnosis.calibration.predictions)
    assert stats["weighted_rms_Nm"] > 2.0 * stats["noise_floor_Nm"]


def test_a_registered_user_effect_is_named_with_its_strength(hidden_user_effect):
    """The out-of-balance column, registered from its own file, is named first; its fitted strength (the
    gravity torque amplitude m g e sin(lambda)) holds the hidden one within its 95 % interval or 5 %; adding it
    brings the error to the noise floor (within 1.2 times)."""
    diagnosis, truth = hidden_user_effect
    assert diagnosis.verdict == "missing"
    assert diagnosis.effect == "column_imbalance"
    fitted = diagnosis.best.refit.intervals(diagnosis.problem)["column_imbalance.strength"]
    low, high = fitted["ci95"]
    assert low <= truth["strength"] <= high or fitted["value"] == pytest.approx(truth["strength"], rel=0.05)
    after = diagnosis.statistics(diagnosis.best.refit.predictions)
    assert after["weighted_rms_Nm"] < 1.2 * after["noise_floor_Nm"]


def test_diagnosis_json_follows_its_schema(schema, null_diagnosis, drift_diagnosis, hidden_user_effect):
    """Every verdict's JSON validates against workflow/schemas/diagnosis.schema.json; a made-up verdict does not."""
    jsonschema.Draft202012Validator.check_schema(schema)
    for diagnosis in (null_diagnosis, drift_diagnosis, hidden_user_effect[0]):
        result = json.loads(json.dumps(diagnosis_dict(diagnosis)))  # as a consumer reads it
        jsonschema.validate(result, schema)
    broken = {**result, "verdict": "probably"}
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(broken, schema)


def test_the_error_ladder_falls_to_the_noise_floor(hidden_user_effect, params):
    """Each rung lowers the weighted error: the paper's values, calibrated, + the named effect, which ends within
    1.2 noise floors."""
    diagnosis, _ = hidden_user_effect
    ladder = error_ladder([f for f in diagnosis.problem.files], params, first=diagnosis)
    errors = [r["weighted_rms_Nm"] for r in ladder.rungs]
    assert [r["label"] for r in ladder.rungs] == ["paper's model", "calibrated", "+ column_imbalance"]
    assert all(a > b for a, b in zip(errors, errors[1:]))
    assert ladder.rungs[-1]["over_floor"] < 1.2


def test_the_user_effect_joins_compare_by_spec_and_by_environment(written, tmp_path, capsys, monkeypatch):
    """Joined by an effects spec or by PARKSTEER_EFFECT_MODULES, the example effect changes the replayed torque by
    T_u sin(column angle - phase): with T_u = 1 N m the RMS change is close to 1 / sqrt(2) N m."""
    paths, _ = written("own_model", kind="null")
    runs = {}
    for label, args, env in (
        ("without", [], None),
        ("spec", [f"--effects=+{USER_EFFECT_PATH}", "--set", "column_imbalance.strength=1"], None),
        ("env", ["--effects=+column_imbalance", "--set", "column_imbalance.strength=1"], str(USER_EFFECT_PATH)),
    ):
        if env:
            monkeypatch.setenv(MODULES_ENV, env)
        assert main(["compare", str(paths[0]), "--json", *args]) == 0
        runs[label] = json.loads(capsys.readouterr().out)
    assert "column_imbalance" in runs["spec"]["effects"] and "column_imbalance" in runs["env"]["effects"]
    assert runs["spec"]["files"][0]["overall"]["rms"] == pytest.approx(runs["env"]["files"][0]["overall"]["rms"])
    base = runs["without"]["files"][0]["overall"]["rms"]
    added = runs["spec"]["files"][0]["overall"]["rms"]
    assert np.sqrt(max(added**2 - base**2, 0.0)) == pytest.approx(1 / np.sqrt(2), rel=0.15)


def test_diagnose_command_writes_json_report_and_figure(written, tmp_path, capsys):
    """The command's JSON validates, the markdown report states the verdict and links the figure; progress goes
    to stderr, and --quiet with --jobs 2 prints nothing there and the same JSON (timings apart)."""
    paths, _ = written("null_off_nominal", kind="null", base_overrides=OFF_NOMINAL)
    report, plot = tmp_path / "report.md", tmp_path / "diagnosis.svg"
    assert main(["diagnose", str(paths[0]), "--json", "--report", str(report), "--plot", str(plot)]) == 0
    captured = capsys.readouterr()
    result = json.loads(captured.out)
    assert captured.err.splitlines()[-1].startswith(f"diagnose: verdict: {result['verdict']}")
    jsonschema.validate(result, json.loads(SCHEMA_PATH.read_text(encoding="utf-8")))
    text = report.read_text(encoding="utf-8")
    assert f"Verdict: {result['verdict']}" in text and "diagnosis.svg" in text
    assert plot.read_text(encoding="utf-8").startswith("<?xml")
    assert main(["diagnose", str(paths[0]), "--json", "--quiet", "--jobs", "2"]) == 0
    captured = capsys.readouterr()
    again = json.loads(captured.out)
    assert captured.err == ""
    for r in (result, again):
        r["cost"].pop("timings_s")
    assert again == result
