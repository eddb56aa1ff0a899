"""The band of a confident name against a car's baseline (parksteer.diagnose.baseline_learn, baseline_form): on the
healthy parts the best candidate's lead over the second best is the car's own misfit taken up by two candidates
that fit alike, so a later record's lead no larger than the healthy parts' bound is not a confident name. No
replay: these are facts about the lead's share of a part, the bound over the parts and the band it sets."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from parksteer.diagnose.baseline import Baseline
from parksteer.diagnose.baseline_form import Threshold
from parksteer.diagnose.baseline_learn import _block_threshold, fold_row, pooled_bound
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.experiments.baseline import judged


def _candidate(name: str, delta_bic: float, prediction: np.ndarray):
    return SimpleNamespace(name=name, delta_bic=delta_bic, refit=SimpleNamespace(predictions=[prediction]))


def _found(measured, calibration, candidates):
    f = SimpleNamespace(measured=measured, sigma=np.ones_like(measured), signals=1)
    return SimpleNamespace(problem=SimpleNamespace(files=[f]), calibration=SimpleNamespace(predictions=[calibration]),
                           candidates=candidates, verdict="missing")


def test_a_parts_lead_is_its_signed_share_of_the_fall_from_the_second_best_to_the_best():
    """The lead of the best candidate over the second best is apportioned to a part by the share, on the part's
    samples, of the weighted sum of squares by which the best's refit falls below the second best's. Where the two
    refits agree on a part, its lead is 0, whatever either gains there; where the second best fits better, the
    part's lead is below 0; the parts' leads add up to the whole lead (here in shares -1 : 0 : 2 of a fall of 1)."""
    n = 30
    measured = np.zeros(n)
    calibration = np.full(n, 2.0)  # the calibration misses by 2 everywhere
    second = np.full(n, 1.0)
    best = second.copy()
    best[:10] = np.sqrt(1.1)  # worse than the second best on the first part by a sum of squares of 1 ...
    best[20:] = np.sqrt(0.8)  # ... better on the third by 2; the second part alike
    found = _found(measured, calibration, [_candidate("a", 30.0, best), _candidate("b", 22.0, second),
                                          _candidate("c", -3.0, calibration)])
    parts = [np.arange(n) // 10 == k for k in range(3)]
    leads = [fold_row(found, f"part {k}", mask)["lead"] for k, mask in enumerate(parts)]
    assert leads == pytest.approx([-8.0, 0.0, 16.0])
    assert sum(leads) == pytest.approx(30.0 - 22.0)


def test_without_a_second_best_that_gains_the_lead_is_the_gain():
    """A second best whose BIC gain is below 0 loses to the calibration itself (gain 0): the lead is then the best
    candidate's whole gain, apportioned as its gain is."""
    n = 20
    measured, calibration = np.zeros(n), np.full(n, 1.0)
    found = _found(measured, calibration, [_candidate("a", 12.0, np.full(n, 0.5)),
                                          _candidate("b", -2.0, np.full(n, 0.9))])
    row = fold_row(found, "part", np.arange(n) < 5)
    assert row["lead"] == pytest.approx(row["delta_bic"]) == pytest.approx(3.0)


def test_a_lead_below_the_healthy_parts_bound_is_not_confident_and_above_it_is():
    """Healthy blocks whose leads per sample are L_k bound a later record's mean lead per sample by the pooled
    prediction bound L; a later record of N samples is judged with the band max(6, L N): a right name that leads
    its rival by a little less than L N is within the band (not confident), by a little more it is confident; and
    a wrong name that leads by less is not a confident wrong answer."""
    samples = 400
    rows = [{"part": f"block {k}", "samples": samples, "over_floor": 2.0, "delta_bic": 30.0, "lead": lead}
            for k, lead in enumerate([0.4, 1.2, 0.8, 2.0, 0.2, 1.0, 0.6, 1.6, 0.9, 0.3])]
    threshold = _block_threshold(rows, "blocks")
    bound = pooled_bound([r["lead"] / samples for r in rows], len(rows))
    assert threshold.lead_per_sample == pytest.approx(bound)
    later = 4000
    band = threshold.settings_for(DEFAULT_SETTINGS, later).bic_indistinguishable
    assert band == pytest.approx(bound * later) and band > DEFAULT_SETTINGS.bic_indistinguishable

    def result(effect: str, lead: float) -> dict:
        return {"verdict": "missing", "effect": effect, "indistinguishable": [],
                "ranking": [{"effect": effect, "delta_bic": 300.0 + lead}, {"effect": "other", "delta_bic": 300.0}],
                "selection": {"thresholds": {"bic_indistinguishable": band}},
                "statistics": {"calibrated": {"weighted_rms_Nm": 0.05}}, "noise_floor_Nm": 0.01}

    truth = {"kind": "hidden", "hidden": "column_friction"}
    assert not judged(truth, result("column_friction", 0.95 * band))["confident"]
    assert judged(truth, result("column_friction", 1.05 * band))["confident"]
    wrong = judged(truth, result("rack_damping", 0.95 * band))
    assert not wrong["confident_wrong"] and not wrong["named"]


def test_healthy_parts_that_never_lead_leave_the_settings_band():
    """Where the healthy parts' leads are all 0 (no candidate takes up the car's misfit), the band is the settings'
    own: the bound never lowers it."""
    rows = [{"part": f"block {k}", "samples": 400, "over_floor": 1.0, "delta_bic": 0.0, "lead": 0.0}
            for k in range(10)]
    threshold = _block_threshold(rows, "blocks")
    assert threshold.lead_per_sample == 0.0
    assert threshold.settings_for(DEFAULT_SETTINGS, 4000).bic_indistinguishable == \
        DEFAULT_SETTINGS.bic_indistinguishable


def test_a_baseline_file_keeps_its_lead_and_one_written_before_reads_with_the_settings_band(tmp_path):
    """The lead bound is written with the threshold and read back as written; a baseline file written before the
    lead was learnt (no `lead_per_sample` under [threshold]) still loads, with a lead of 0, so the band of a later
    record is the settings'."""
    rack = {"value": 650.0, "ci95": [640.0, 660.0], "standard_error": 5.0, "source": "a test"}
    baseline = Baseline(None, "0" * 16, ("healthy.csv",), (), {"steering.rack_friction_force": rack},
                        "adequate", 1.0, None, Threshold(1.5, 0.01, "blocks", (), 0.0025))
    path = tmp_path / "car_baseline.toml"
    baseline.write(path)
    assert Baseline.read(path).threshold.lead_per_sample == 0.0025
    text = path.read_text(encoding="utf-8")
    older = "\n".join(line for line in text.splitlines() if not line.startswith("lead_per_sample"))
    assert older != text
    old = tmp_path / "old_baseline.toml"
    old.write_text(older, encoding="utf-8")
    read = Baseline.read(old)
    assert read.threshold.lead_per_sample == 0.0 and read.threshold.bic_per_sample == 0.01
    band = read.threshold.settings_for(DEFAULT_SETTINGS, 4000).bic_indistinguishable
    assert band == DEFAULT_SETTINGS.bic_indistinguishable
