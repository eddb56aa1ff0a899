"""A user's own effect is calibrated when it is added (``Quantity.free``), and the diagnosis says what it changed.

The record is data/samples/worn_rack.csv: the paper's car with a rack friction peaked at the centre in a form no
candidate has (a Lorentzian, ``A / (1 + (x / 12 mm)^2)``, 150 N), its base parameters moved, another hand, a 50 Hz
logger's quantisation and noise (data/samples/make_samples.py). The effects passed back are the hand-written
Gaussian of examples/user_effect/ and the file --suggest-effect writes; neither is the form that made the record.
The diagnoses run without the candidate library (an empty registry), which builds only the model with the effect:
what is tested is the calibration of the free strengths and the section on them, not the ranking.
"""

from __future__ import annotations

import json
import pickle

import jsonschema
import pytest
from pages_check import assert_same_sections

from parksteer.diagnose.calibrate import free_strengths
from parksteer.diagnose.problem import load_files
from parksteer.reporting.report import diagnosis_dict
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.stages import STAGES
from parksteer.diagnose.stages.user_effect import with_user_effect_stage
from parksteer.diagnose.suggest import suggest
from parksteer.model.symbolic.components import discover_effects, resolve_effects
from parksteer.resources import data_file

pytestmark = pytest.mark.slow  # derives the models with the user's effects


@pytest.fixture(scope="module")
def record(repo_root):
    return [str(repo_root / "data" / "samples" / "worn_rack.csv")]


@pytest.fixture(scope="module")
def hand_written(record, params, repo_root):
    effects = resolve_effects(f"+{repo_root / 'examples' / 'user_effect' / 'centre_friction.py'}")
    return diagnose(load_files(record, params), params, effects, registry={})


def test_the_package_s_effects_declare_nothing_free():
    """No effect of the package declares a free quantity, so a diagnosis of the package's effects calibrates what
    it always did and runs its table unchanged (no user-effect stage)."""
    effects = list(discover_effects().values())
    assert free_strengths(effects) == []
    assert with_user_effect_stage(STAGES, effects) is STAGES


def test_a_hand_written_effect_is_fitted_and_brings_the_error_to_the_floor(hand_written):
    """The worn bore written from the physics (a Gaussian bump of rack friction, peak force and width free):
    calibrated without it the record leaves more than twice the noise floor; with it, its peak force and width
    fitted with the calibrated parameters, the error is at the floor and the verdict is adequate. The fitted peak
    is of the hidden 150 N's size (the Gaussian and the Lorentzian differ in shape, so not equal): its interval
    excludes 0 and lies between 50 and 300 N, in N."""
    found = hand_written.outputs["user_effect"]
    without, with_it = found.rungs[1]["over_floor"], found.rungs[2]["over_floor"]
    assert without > 2.0 and with_it <= hand_written.settings.adequate_rms_factor
    assert hand_written.verdict == "adequate"
    peak = found.strengths["centre_friction.peak_force"]
    assert peak["unit"] == "N" and 50.0 < peak["ci95"][0] and peak["ci95"][1] < 300.0
    assert "centre_friction.width" in found.strengths  # a free shape parameter is fitted too


def test_the_error_falls_as_the_strength_grows(hand_written):
    """The sweep moves the peak force (whose 0 means absent) from 0 to its fitted value, the width held at its fit:
    the weighted error falls at every step, from above twice the floor to the fit's own error."""
    sweep = hand_written.outputs["user_effect"].sweep
    assert sweep["keys"] == ["centre_friction.peak_force"] and sweep["values"][sweep["keys"][0]][0] == 0.0
    errors = sweep["over_floor"]
    assert errors[0] > 2.0 and all(b < a for a, b in zip(errors, errors[1:]))


def test_the_json_holds_the_section_and_keeps_the_schema(hand_written):
    """The JSON of a diagnosis with a user's effect carries its section (ladder, strengths with units, residual by
    phase, sweep) and stays valid against the published schema; the residual falls in the plateau, where a
    friction force shows most."""
    result = diagnosis_dict(hand_written)
    jsonschema.validate(result, json.loads(data_file("diagnosis.schema.json").read_text(encoding="utf-8")))
    plateau = [r for r in result["user_effect"]["phases"] if r["phase"] == "plateau"]
    assert plateau and all(r["with_rms_Nm"] < r["without_rms_Nm"] for r in plateau)


def test_the_suggested_file_passed_back_as_it_stands_gives_the_error_it_promises(record, params, tmp_path):
    """The file --suggest-effect writes declares its strengths free with the fitted values as their defaults (no
    toggle to edit); loaded again as it stands and diagnosed, the strengths are fitted again and the error is
    the one its fit promised, within 5 %, at the floor."""
    files = load_files(record, params)
    first = diagnose(files, params, registry={})
    signature = first.outputs["signature"]
    assert signature.effect_class is not None
    path = tmp_path / "missing.py"
    suggestion = suggest(first.problem, first.calibration, signature, path)
    text = path.read_text(encoding="utf-8")
    assert "free=True" in text and "FITTED_AS_DEFAULTS" not in text
    again = diagnose(load_files(record, params), params, resolve_effects(f"+{path}"), registry={})
    after = again.outputs["user_effect"].rungs[-1]["over_floor"]
    assert after == pytest.approx(suggestion.after_over_floor, rel=0.05)
    assert again.verdict == "adequate"
    # what the reports say of it (one test, for one diagnosis more than this module can spend)
    result, before = diagnosis_dict(again), diagnosis_dict(first)
    check_suggested_intervals(result, before)


def check_suggested_intervals(result, before):
    """The suggested effect's strengths each carry a 95 % interval or say why they have none (here: 15 strengths
    and 3 car parameters against 9 two-second blocks of an 18 s record, and the block sandwich needs more blocks
    than parameters); the car's calibrated intervals stay what the data fix: finite, each no wider than twice its
    width without the effect, where unconditioned they reach the parameters' bounds. The suggested shape (bumps
    along the rack, times the sign of the rack's speed) sums to a uniform rack friction, so the rack friction
    force's signature is nearly all the strengths' too, and both reports say its value holds only with the shape
    as fitted; the two pages show the same sections."""
    strengths = result["user_effect"]["strengths"]
    assert len(strengths) == 15
    for entry in strengths.values():
        assert entry["ci95"] is not None or "more blocks than parameters" in entry["why_not_fixed"]
    for key, entry in before["calibrated"].items():
        low, high = result["calibrated"][key]["ci95"]
        assert high - low <= 2.0 * (entry["ci95"][1] - entry["ci95"][0]), key
    shares = result["user_effect"]["not_made_by_strengths"]
    assert shares["steering.rack_friction_force"] < 0.1 < shares["tyre.friction_coefficient"]
    text, page = assert_same_sections(result)
    assert "holds only with the effect's shape as fitted" in text and "more blocks than parameters" in page
    fixed = next(line for line in text.splitlines() if line.startswith("- steering.rack_friction_force:"))
    assert "held at their fit" in fixed


def test_the_form_a_suggestion_is_fitted_on_is_the_force_its_file_writes(record, params, tmp_path, monkeypatch):
    """A suggestion is fitted on its form (its knots given as values) and written as a file with the knots as
    numbers: the two are one force. The file replayed as it stands (its strengths at the fitted START) and the form
    replayed at the fitted strengths give the same torque on the calibrated car, to 1e-6 N m (against a 0.03 N m
    floor) once the two compiled models are integrated tightly (relative 1e-10; at the diagnosis's 1e-5 their
    different steps leave about 1e-3 N m)."""
    import numpy as np

    from parksteer.model.numeric import prescribed

    from parksteer.diagnose.engine import ReplayEngine
    from parksteer.diagnose.suggest import shape_of

    files = load_files(record, params)
    first = diagnose(files, params, registry={})
    signature = first.outputs["signature"]
    path = tmp_path / "missing.py"
    suggestion = suggest(first.problem, first.calibration, signature, path)
    form, _ = shape_of(signature)
    rtol, atol_factor, *rest = prescribed.solve.__defaults__
    monkeypatch.setattr(prescribed.solve, "__defaults__", (1e-10, atol_factor * 1e-4, *rest))
    fitted = suggestion.fit.overrides
    base = {k: v for k, v in fitted.items() if not k.startswith(f"{form.name}.")}
    engine = ReplayEngine()
    on_form = engine.predict(first.problem, suggestion.fit.effects, fitted)
    written = next(e for e in resolve_effects(f"+{path}") if e.name == suggestion.effect_name)
    model = sorted([*first.calibration.effects, written], key=lambda e: e.name)
    on_file = engine.predict(first.problem, model, base)
    gap = max(float(np.max(np.abs(a - b))) for a, b in zip(on_form, on_file))
    change = max(float(np.max(np.abs(a - b))) for a, b in zip(on_form, first.calibration.predictions))
    assert change > 0.05 and gap < 1e-6


def test_a_file_effect_replays_on_workers_as_in_line(hand_written):
    """An effect loaded from its file and handed to diagnose() (the Python route, not only the command line's)
    replays on a diagnosis's worker processes, which are sent it by its place among the effects they inherited
    (pickle cannot find its class by name): two files' predictions with two workers are those of one process, bit
    for bit (before, a diagnosis on several workers failed with a PicklingError)."""
    import numpy as np

    from parksteer.diagnose.engine import ReplayEngine
    from parksteer.diagnose.parallel import can_fork

    if not can_fork():
        pytest.skip("the platform cannot fork: everything runs in line")
    effects = list(hand_written.base_effects)
    assert any(e.name == "centre_friction" for e in effects)
    with pytest.raises(pickle.PicklingError):
        pickle.dumps(next(e for e in effects if e.name == "centre_friction"))
    problem = hand_written.problem.with_files([hand_written.problem.files[0]] * 2)
    predictions = {}
    for workers in (1, 2):
        engine = ReplayEngine(workers, effects=tuple(effects))
        try:
            assert engine.parallel_files(problem) == (workers == 2)
            predictions[workers] = engine.predict(problem, effects, {})
        finally:
            engine.close()
    assert all(np.array_equal(a, b) for a, b in zip(predictions[1], predictions[2]))


def test_compare_fits_the_free_strengths_it_is_not_given(record, params, repo_root):
    """`parksteer compare` with the hand-written effect fits its free peak force and width with the calibrated
    parameters (printed with their units) and compares the record with the fitted model, well below the model with
    the peak force given as 0 by --set, which it holds."""
    from parksteer.diagnose.compare import compare_files

    effects = resolve_effects(f"+{repo_root / 'examples' / 'user_effect' / 'centre_friction.py'}")
    fitted = compare_files(load_files(record, params), params, effects)
    held = compare_files(load_files(record, params), params, effects, {"centre_friction.peak_force": 0.0})
    assert fitted.fitted["centre_friction.peak_force"]["unit"] == "N"
    assert fitted.fitted["centre_friction.peak_force"]["value"] > 50.0
    assert "centre_friction.peak_force" not in held.fitted and held.overrides["centre_friction.peak_force"] == 0.0
    assert fitted.statistics["weighted_rms_Nm"] < 0.7 * held.statistics["weighted_rms_Nm"]
