"""A calibrated value that changed since the baseline (parksteer.diagnose.baseline_changed): against a baseline each
held calibrated value is a candidate of its own, ``changed:<key>``, in the same selection as the library's. A record
of the model whose rack friction grew by a quarter since the baseline is named by it, the fitted value's interval
holding the value put in and leaving out the baseline's; a record of the same car with nothing changed stays
adequate, no freed value refitted (each interval holds the baseline's value); and the sentence of the report says
from what to what the value moved."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.diagnose.baseline import Baseline
from parksteer.diagnose.baseline_changed import PREFIX, ChangedValues, changed_key, with_changed_values
from parksteer.diagnose.baseline_form import Threshold, vehicle_fingerprint
from parksteer.diagnose.problem import load_files
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.diagnose.stages import STAGES
from parksteer.experiments.benchmark import BENCHMARK_SETTINGS
from parksteer.measure.io import write_measurement
from parksteer.model.symbolic.components import resolve_effects
from parksteer.parameters import load_parameters
from parksteer.reporting.relative_text import relative_sentence
from parksteer.reporting.report import diagnosis_dict
from parksteer.synthetic.variations import VARIATIONS, variation_record

PARAMS = load_parameters()
RACK = "steering.rack_friction_force"
CALIBRATED = ("tyre.friction_coefficient", RACK, "tyre.carcass_torsional_stiffness")
GROWTH = 1.25  # the later record's rack friction over the baseline's


def _baseline(values: dict) -> Baseline:
    """A baseline of the parameter file's car whose healthy record was adequate, its calibrated values `values`
    (intervals of 1 % either side), the threshold the sensor's."""
    calibrated = {k: {"value": v, "ci95": [0.99 * v, 1.01 * v]} for k, v in values.items()}
    return Baseline(None, vehicle_fingerprint(PARAMS), ("healthy.csv",), tuple(e.name for e in resolve_effects(None)),
                    calibrated, "adequate", 1.0, None, Threshold(0.0, 0.0, "the sensor's floor"))


def test_each_held_value_is_a_candidate_after_the_refits():
    """The table against a baseline: one stage that frees every calibrated value the baseline holds, right after the
    library's refits (so the selection compares both), an angle fitted as it stands and the others in their
    logarithm; without refits in the table nothing is added. A candidate's name gives back its key."""
    baseline = _baseline({k: float(PARAMS.value(k, "unladen")) for k in CALIBRATED})
    table = baseline.table(STAGES, DEFAULT_SETTINGS)
    names = [s.name for s in table]
    assert len(table) == len(STAGES) + 1
    assert names.index("changed_values") == names.index("refits") + 1 < names.index("selection")
    stage = table[names.index("changed_values")]
    assert isinstance(stage, ChangedValues) and stage.keys == CALIBRATED
    assert set(stage.offsets) == {k for k, _, _ in DEFAULT_SETTINGS.calibrated_with_angle_offsets}
    without_refits = tuple(s for s in STAGES if s.name != "refits")
    assert with_changed_values(without_refits, CALIBRATED, DEFAULT_SETTINGS) == without_refits
    assert changed_key(PREFIX + RACK) == RACK and changed_key("column_friction") is None


@pytest.fixture(scope="module")
def judged(tmp_path_factory):
    """A record of the model with nothing hidden and one whose rack friction grew by a quarter, of one hand and
    logger, each diagnosed against a baseline that holds the file's values."""
    folder = tmp_path_factory.mktemp("changed")
    variation = next(v for v in VARIATIONS if v.name == "rest_after_stop")
    hand, logger = variation.settings(31)
    was = float(PARAMS.value(RACK, "unladen"))
    baseline = _baseline({k: float(PARAMS.value(k, "unladen")) for k in CALIBRATED})
    out = {"was": was, "baseline": baseline}
    for name, overrides in (("null", {}), ("grown", {RACK: GROWTH * was})):
        path = folder / f"{name}.csv"
        write_measurement(path, variation_record(PARAMS, hand, logger, overrides=overrides), PARAMS)
        out[name] = diagnose(load_files([path], PARAMS), PARAMS, settings=BENCHMARK_SETTINGS, baseline=baseline)
    return out


@pytest.mark.slow
def test_a_grown_rack_friction_is_named_as_the_value_that_changed(judged):
    """The rack friction grown by 25 % (the model's own torque otherwise): held at the baseline's value no library
    candidate is its form, freed it is named, its 95 % interval holding the value put in and leaving out the
    baseline's; the report says from what to what it moved, and that it is no library effect."""
    found = judged["grown"]
    assert found.verdict == "missing" and found.effect == PREFIX + RACK
    low, high = found.best.refit.intervals(found.problem)[RACK]["ci95"]
    assert low <= GROWTH * judged["was"] <= high
    assert not low <= judged["was"] <= high
    sentence = relative_sentence(diagnosis_dict(found))
    assert f"Changed: {RACK}, from" in sentence and "not a library effect" in sentence
    assert "(content hash None; the healthy records were adequate)" in sentence


@pytest.mark.slow
def test_a_record_with_nothing_changed_stays_as_the_baseline(judged):
    """Nothing changed: the verdict is adequate, and no freed value is refitted, each one's interval holding the
    baseline's value (the rule that names no change the data do not hold apart from none)."""
    found = judged["null"]
    assert found.verdict == "adequate"
    freed = [c for c in found.candidates if changed_key(c.name) is not None]
    assert sorted(changed_key(c.name) for c in freed) == sorted(CALIBRATED)
    assert all(c.refit is None for c in freed)
    assert np.isfinite([c.score.statistic for c in freed]).all()


@pytest.mark.slow
def test_the_error_ladder_ends_at_a_changed_value(judged):
    """The HTML report's error ladder grows the model by named effects; a calibrated value that changed is no effect:
    its rung (the freed value's refit, whose error is below the held calibration's) is the last, and no diagnosis is
    made with the value's key taken for an effect's strength."""
    from parksteer.reporting.ladder import error_ladder

    from dataclasses import replace

    # The ladder stops at the floor too: with an adequate factor no error meets, only the changed value stops it.
    found = judged["grown"]
    found = replace(found, settings=replace(found.settings, adequate_rms_factor=1e-3))
    ladder = error_ladder(found.problem.files, PARAMS, list(found.base_effects), first=found)
    labels = [r["label"] for r in ladder.as_dict()["rungs"]]
    assert labels[-1] == f"+ {PREFIX}{RACK}" and len(labels) == 3
    assert len(ladder.diagnoses) == 1
    rungs = ladder.as_dict()["rungs"]
    assert rungs[-1]["parameters"][RACK] > judged["was"]
    assert rungs[-1]["weighted_rms_Nm"] < rungs[1]["weighted_rms_Nm"]
