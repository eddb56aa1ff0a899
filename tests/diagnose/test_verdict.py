"""The verdict rule (parksteer.diagnose.stages.verdict.choose_verdict) on the numbers real diagnoses produced.

The rule is logic, not physics: these tests pin what each verdict means, with the statistics of records the
benchmarks produced (weighted RMS in noise floors, BIC gains, the fraction of the excess a candidate removes).
"""

from __future__ import annotations

from parksteer.diagnose.stages.verdict import choose_verdict, trimmed_rms
from parksteer.diagnose.settings import DEFAULT_SETTINGS as S


def test_a_strongly_evidenced_candidate_that_leaves_the_error_far_above_the_floor_is_not_named():
    # Top-mount wind-up hidden out of class: the brush patch removed 68 % of the excess (the 60 % rule alone would
    # name it) and left 1.67 floors, above anything a record with nothing hidden reaches.
    assert choose_verdict(2.59, 496.1, 1.67, 0.685) == "unexplained"
    # The same gain and fraction, leaving the error within the spread of null records: named.
    assert choose_verdict(2.59, 496.1, 1.2, 0.685) == "missing"


def test_an_effect_that_brings_the_error_to_the_floor_is_named_whatever_fraction_it_removes():
    # Column friction at two steps: the calibration absorbed most of it (base 1.03 floors) and the refit leaves 1.02.
    assert choose_verdict(1.033, 25.0, 1.021, 0.1) == "missing"


def test_evidence_below_the_bic_threshold_never_names_an_effect():
    assert choose_verdict(1.9, S.bic_missing_threshold - 0.1, 1.0, 0.99) == "unexplained"
    assert choose_verdict(1.05, S.bic_missing_threshold - 0.1, 1.0, 0.99) == "adequate"


def test_adequate_needs_the_base_model_at_the_floor_and_no_strong_evidence():
    assert choose_verdict(1.02, None, None, None) == "adequate"
    assert choose_verdict(S.adequate_rms_factor + 0.01, None, None, None) == "unexplained"
    # A strongly evidenced candidate on a base model already at the floor is named, never hidden under "adequate".
    assert choose_verdict(1.05, 40.0, 1.0, None) == "missing"


def test_the_ceiling_sits_above_every_null_and_every_correctly_named_record_of_the_benchmarks():
    # The spread the setting's reason quotes: nulls reach 1.24 floors, correctly named effects leave 1.09 at most.
    assert S.adequate_rms_factor < 1.24 < S.missing_rms_ceiling < 1.67
    assert 1.09 < S.missing_rms_ceiling


def test_the_report_names_the_nearest_candidate_of_an_unexplained_verdict():
    from parksteer.reporting.sections import _nearest

    thresholds = {"bic_missing": S.bic_missing_threshold, "missing_rms_ceiling": S.missing_rms_ceiling}
    result = {"noise_floor_Nm": 0.2, "selection": {"thresholds": thresholds},
              "ranking": [{"effect": "brush_patch", "delta_bic": 496.1, "weighted_rms_after_Nm": 0.334}]}
    text = _nearest(result)
    assert "brush_patch" in text and "1.67 noise floors" in text
    result["ranking"][0]["delta_bic"] = 5.0
    assert _nearest(result) == ""


def test_a_misfit_confined_to_a_few_instants_does_not_block_a_name_but_one_along_the_strokes_does():
    """The ceiling is checked without the largest 2 % of residuals. A lash named from the handwheel angle leaves
    1.68 floors in all, but only 1.15 without the instants where the hand crosses the band (which the rack does not
    time); the top-mount wind-up read as the brush patch leaves 1.57 even without its largest 2 %."""
    assert choose_verdict(6.7, 1494.0, 1.68, 0.96, S, spread_ratio=1.15) == "missing"
    assert choose_verdict(2.59, 487.0, 1.68, 0.685, S, spread_ratio=1.57) == "unexplained"
    # the trimmed RMS: unit residuals with 2 % of wild ones give 1; spread-out residuals of 1.5 give 1.5
    residuals = [1.0] * 98 + [25.0, -30.0]
    assert trimmed_rms(residuals, 0.02) == 1.0
    assert trimmed_rms([1.5, -1.5] * 50, 0.02) == 1.5
