"""A car's baseline (parksteer.diagnose.baseline): a manual car whose every record carries a rack friction bump no
candidate of the library has (a dent in the rack bore at +20 mm, parksteer.synthetic.outoflibrary, at 4 converter
steps RMS), two healthy records driven by different hands, and later records of other hands with a library effect
added at 3.5 steps. Absolutely every record is `unexplained` (the bump is outside the library); against the
baseline the added effect is named, a healthy record of a third hand is as the baseline, and the baseline file
reads back to the same verdicts. On the command line: `baseline`, then `diagnose --baseline`; a baseline of another
car or a damaged file is refused in one line."""

from __future__ import annotations

import hashlib
import json
import tomllib

import jsonschema
import numpy as np
import pytest

from parksteer.cli import main
from parksteer.diagnose.baseline import Baseline, learn_baseline
from parksteer.diagnose.baseline_learn import blocks_of
from parksteer.diagnose.problem import load_files
from parksteer.reporting.report import diagnosis_dict
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.synthetic.datasets import BASE_PERTURBATION
from parksteer.measure.converter import quantisation_step
from parksteer.measure.io import write_measurement
from parksteer.model.numeric.simulate import simulate
from parksteer.model.symbolic.components import discover_effects, resolve_effects, strength_parameter
from parksteer.parameters import DEFAULT_PATH, load_parameters
from parksteer.resources import data_file
from parksteer.synthetic.datasets import perturbed_base
from parksteer.synthetic.size_search import rms_difference
from parksteer.synthetic.outoflibrary import form_by_name
from parksteer.synthetic.variations import VARIATIONS, variation_rack, variation_record

pytestmark = pytest.mark.slow  # derives the models with the bump and the held form; each diagnosis replays ~1 min

PARAMS = load_parameters()
QUIRK = "oolib_friction_bump"
CAR_SEED = 77  # one car: the same base parameters, moved off the file's, in every record
QUIRK_STEPS = 4.0
CHANGE_STEPS = 3.5
PROBES = {QUIRK: 100.0, "column_friction": 0.5, "rack_damping": 1000.0}
# The library effects added to the later records. Both records are made with one model holding both, the one not
# added at its default strength, 0 (absent): the same forces as a model of the one added, and one derivation.
LATER_EFFECTS = ("column_friction", "rack_damping")
# (record, the hand's variation, seed, the library effect added later)
RECORDS = (("healthy_a", "rest_after_stop", 11, None), ("healthy_b", "uneven_strokes", 12, None),
           ("healthy_c", "lock_overshoot", 13, None), ("column", "rest_after_stop", 14, "column_friction"),
           ("damping", "uneven_strokes", 15, "rack_damping"))


def _sized(effects, key: str, steps: float, hand, logger, overrides: dict) -> float:
    """The strength of `key` that moves the clean torque by `steps` converter steps RMS (the effect is linear in
    its strength at these sizes: one probe)."""
    drive = variation_rack(PARAMS, hand)

    def torque(strength: float) -> np.ndarray:
        return np.asarray(simulate("unladen", effects=effects, overrides={**overrides, key: strength},
                                   rack_drive=drive, params=PARAMS, output_dt_s=0.01).columns["handwheel_torque_Nm"])

    probe = PROBES[key.partition(".")[0]]
    step = quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
    return probe * steps * step / rms_difference(torque(probe), torque(0.0))


def _record(variation: str, seed: int, added: str | None):
    """(measurement, the strengths put in) of one record of the car."""
    hand, logger = next(v for v in VARIATIONS if v.name == variation).settings(seed)
    overrides = perturbed_base(PARAMS, CAR_SEED, BASE_PERTURBATION)
    effects = [*resolve_effects(None), form_by_name(QUIRK).effect]
    quirk_key = f"{QUIRK}.strength"
    overrides[quirk_key] = _sized(resolve_effects(effects), quirk_key, QUIRK_STEPS, hand, logger, overrides)
    if added is not None:
        effects = [*effects, *(discover_effects()[name] for name in LATER_EFFECTS)]
        key = strength_parameter(discover_effects()[added]).key
        overrides[key] = _sized(resolve_effects(effects), key, CHANGE_STEPS, hand, logger, overrides)
    return variation_record(PARAMS, hand, logger, overrides=overrides, effects=resolve_effects(effects)), overrides


@pytest.fixture(scope="module")
def car(tmp_path_factory):
    """The car's records written as files, the baseline learnt from the two healthy ones and written, and each
    later record diagnosed against it (and absolutely)."""
    folder = tmp_path_factory.mktemp("car")
    paths, truths = {}, {}
    for name, variation, seed, added in RECORDS:
        measurement, truths[name] = _record(variation, seed, added)
        paths[name] = folder / f"{name}.csv"
        write_measurement(paths[name], measurement, PARAMS)
    healthy = load_files([paths["healthy_a"], paths["healthy_b"]], PARAMS)
    learnt = learn_baseline(healthy, PARAMS)
    written = learnt.write(folder / "car_baseline.toml")
    relative, absolute = {}, {}
    for name in ("healthy_c", "column", "damping"):
        files = load_files([paths[name]], PARAMS)
        relative[name] = diagnose(files, PARAMS, baseline=written)
        absolute[name] = diagnose(files, PARAMS)
    return {"paths": paths, "truths": truths, "learnt": learnt, "written": written, "relative": relative,
            "absolute": absolute, "folder": folder}


def test_the_healthy_car_is_outside_the_library_and_its_form_is_held(car):
    """The bump is no candidate's form: the healthy records are `unexplained` absolutely, and the baseline holds the
    form their residual's signature points to, a dissipative force on the rack (the class of a friction bump), with
    each strength's 95 % interval; the calibrated values carry their intervals too."""
    learnt = car["learnt"]
    assert learnt.verdict == "unexplained"
    assert learnt.form is not None and learnt.form.source == "signature"
    assert learnt.form.shape_class == "dissipative"
    for entry in [*learnt.form.strengths.values(), *learnt.calibrated.values()]:
        low, high = entry["ci95"]
        assert np.isfinite([low, high]).all() and low <= entry["value"] <= high
    assert set(learnt.calibrated) == {"tyre.friction_coefficient", "steering.rack_friction_force",
                                      "tyre.carcass_torsional_stiffness"}
    assert learnt.threshold.method.startswith("leave one out")
    assert [p["part"] for p in learnt.threshold.parts] == ["healthy_a.csv", "healthy_b.csv"]
    # the threshold is above each healthy part's own value: a prediction bound, not their largest
    assert learnt.threshold.over_floor > max(p["over_floor"] for p in learnt.threshold.parts)


@pytest.mark.parametrize("name, effect", [("column", "column_friction"), ("damping", "rack_damping")])
def test_a_later_change_is_named_against_the_baseline(car, name, effect):
    """A library effect added at 3.5 converter steps on top of the bump: absolutely the record is `unexplained`
    (the bump hides it), against the baseline it is `missing` with the effect added, and the fitted strength's 95 %
    interval holds the strength put in (the bump's strengths held: it cannot absorb the change)."""
    assert car["absolute"][name].verdict == "unexplained"
    found = car["relative"][name]
    assert found.verdict == "missing" and found.effect == effect
    key = strength_parameter(discover_effects()[effect]).key
    low, high = found.best.refit.intervals(found.problem)[key]["ci95"]
    assert low <= car["truths"][name][key] <= high


def test_a_healthy_record_of_another_hand_is_as_the_baseline(car):
    """A third healthy record, driven by a hand that overshoots each lock: absolutely `unexplained`, against the
    baseline `adequate` ("as the baseline"), and its JSON names the baseline by its file and content hash and
    validates against the schema."""
    assert car["absolute"]["healthy_c"].verdict == "unexplained"
    found = car["relative"]["healthy_c"]
    assert found.verdict == "adequate"
    result = diagnosis_dict(found)
    jsonschema.validate(result, json.loads(data_file("diagnosis.schema.json").read_text(encoding="utf-8")))
    written = car["written"]
    assert result["relative_to"]["baseline"] == written.path
    digest = hashlib.sha256((car["folder"] / "car_baseline.toml").read_bytes()).hexdigest()[:16]
    assert result["relative_to"]["content_hash"] == digest
    # the threshold of "as the baseline" where it is above the sensor's
    expected = max(DEFAULT_SETTINGS.adequate_rms_factor, written.threshold.over_floor)
    assert result["selection"]["thresholds"]["adequate_rms_factor"] == pytest.approx(expected)


def test_the_baseline_file_round_trips(car):
    """Written and read back, the baseline holds the same values to the last bit (floats are written by repr), and
    a later record diagnosed against the file read gives the verdict and fitted values of the one learnt."""
    learnt, read = car["learnt"], Baseline.read(car["written"].path)
    assert read.form == learnt.form
    assert read.calibrated == learnt.calibrated
    assert read.threshold == learnt.threshold
    assert (read.fingerprint, read.records, read.verdict) == (learnt.fingerprint, learnt.records, learnt.verdict)
    again = diagnose(load_files([car["paths"]["column"]], PARAMS), PARAMS, baseline=read)
    before = car["relative"]["column"]
    assert again.verdict == before.verdict and again.effect == before.effect
    assert again.best.refit.values == before.best.refit.values


def _first_half(path, folder):
    """A copy of the native record `path`, under the same name in `folder`, with the first half of its rows (its
    header as it is)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    header = [line for line in lines if line.startswith("#")]
    rows = [line for line in lines if not line.startswith("#")]  # the column names, then the samples
    folder.mkdir(parents=True, exist_ok=True)
    half = folder / path.name
    half.write_text("\n".join(header + rows[: 1 + (len(rows) - 1) // 2]) + "\n", encoding="utf-8")
    return half


def test_command_line_baseline_then_diagnose(car, tmp_path, capsys):
    """`parksteer baseline` on one healthy record (the threshold from its 2 s blocks, each out of sample, with the
    held form refitted on the other blocks), then `diagnose --baseline` on a later record: exit 0, the file
    written, the JSON valid and naming the file; the healthy records themselves given as the baseline (the two the
    module's baseline file was learnt from) are learnt in memory to the same verdict and fitted values as that file
    gives; `baseline` refuses to overwrite without --force.

    The one record is the first half of a healthy record (its cycle to the right lock and back, the bump's place
    in it): what is checked is the command's route through the blocks and the files it writes and reads, which the
    record's length does not enter, and each block's refit costs a replay of the whole record, so the half record
    takes about a quarter of the whole one's time."""
    out = tmp_path / "one.toml"
    one = _first_half(car["paths"]["healthy_a"], tmp_path / "half")
    assert main(["baseline", str(one), "--out", str(out), "--quiet"]) == 0
    assert "wrote" in capsys.readouterr().out
    text = out.read_text(encoding="utf-8")
    threshold = tomllib.loads(text)["threshold"]
    assert threshold["method"].startswith("blocks") and "held form refitted on the other blocks" in threshold["method"]
    blocks = blocks_of(load_files([one], PARAMS)[0], DEFAULT_SETTINGS.interval_block_s)
    assert blocks >= 3
    assert [p["part"] for p in threshold["parts"]] == [f"healthy_a.csv (block {k} of {blocks})"
                                                       for k in range(1, blocks + 1)]
    assert main(["diagnose", str(car["paths"]["column"]), "--baseline", str(out), "--json", "--quiet"]) == 0
    result = json.loads(capsys.readouterr().out)
    jsonschema.validate(result, json.loads(data_file("diagnosis.schema.json").read_text(encoding="utf-8")))
    assert result["relative_to"]["baseline"] == str(out)
    # in memory against from the file: the healthy records the module's baseline file was learnt from, whose
    # diagnosis against the file the module holds (a baseline of two records is learnt at half the replays of one
    # record's blocks)
    assert main(["diagnose", str(car["paths"]["column"]), "--baseline", str(car["paths"]["healthy_a"]),
                 "--baseline", str(car["paths"]["healthy_b"]), "--json", "--quiet"]) == 0
    in_memory = json.loads(capsys.readouterr().out)
    assert in_memory["relative_to"]["baseline"] is None
    assert in_memory["relative_to"]["records"] == ["healthy_a.csv", "healthy_b.csv"]
    from_file = json.loads(json.dumps(diagnosis_dict(car["relative"]["column"]), allow_nan=False))
    assert from_file["relative_to"]["baseline"] == car["written"].path
    assert (in_memory["verdict"], in_memory["effect"], in_memory["calibrated"]) == \
        (from_file["verdict"], from_file["effect"], from_file["calibrated"])
    assert main(["baseline", str(one), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--out" in err[0] and "--force" in err[0]
    assert out.read_text(encoding="utf-8") == text


@pytest.mark.parametrize("other", ["car", "model"])
def test_a_baseline_of_another_car_or_model_is_refused(car, tmp_path, capsys, other):
    """The baseline is of the car of the packaged parameter file, with the default effects. A record diagnosed as a
    car whose rack friction differs (a parameter file with that one value changed), or with a column friction in
    the model, is refused against it in one line naming the baseline file and the key, exit 2."""
    options = ["--effects=+column_friction"]
    if other == "car":
        path = tmp_path / "other_car.toml"
        text = DEFAULT_PATH.read_text(encoding="utf-8")
        assert 'rack_friction_force = { value = 730.0,' in text
        path.write_text(text.replace('rack_friction_force = { value = 730.0,',
                                     'rack_friction_force = { value = 800.0,'), encoding="utf-8")
        options = ["--parameters", str(path)]
    assert main(["diagnose", str(car["paths"]["column"]), "--baseline", car["written"].path, *options, "--json",
                 "--quiet"]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    key = "vehicle.fingerprint" if other == "car" else "records.model"
    assert len(err) == 1 and "car_baseline.toml" in err[0] and key in err[0] and captured.out == ""


@pytest.mark.parametrize("damage", ["garbage", "missing_key"])
def test_a_damaged_baseline_file_is_refused(car, tmp_path, capsys, damage):
    """A baseline file that is not TOML, or lacks its threshold, is refused in one line naming the file (and the
    key), exit 2, before any replay."""
    text = (car["folder"] / "car_baseline.toml").read_text(encoding="utf-8")
    broken = tmp_path / "broken.toml"
    broken.write_text("this is [not toml" if damage == "garbage" else text.split("[threshold]")[0],
                      encoding="utf-8")
    assert main(["diagnose", str(car["paths"]["column"]), "--baseline", str(broken), "--json", "--quiet"]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and "broken.toml" in err[0] and captured.out == ""
    if damage == "missing_key":
        assert "'threshold'" in err[0]
