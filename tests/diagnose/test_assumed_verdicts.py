"""The assumed-values table: each band end's verdict by the headline's rule, and why an end is not adequate
(parksteer.diagnose.stages.assumed)."""

from __future__ import annotations

from parksteer.diagnose.settings import DEFAULT_SETTINGS as S
from parksteer.diagnose.stages.assumed import end_reason


def _end(verdict, over, gain=None, candidate=None, clear=None, after=None, spread=None):
    return {"verdict": verdict, "calibrated_over_floor": over, "delta_bic": gain, "candidate": candidate,
            "candidate_clear_of_zero": clear, "after_over_floor": after, "spread_over_floor": spread}


def test_an_end_just_above_the_adequate_threshold_says_so():
    """A band end whose calibrated model sits at 1.17 noise floors (the adequate threshold is 1.15) with no
    candidate evidenced is unexplained, and its reason names both figures: the reader sees why it is not adequate
    although it is close to the floor."""
    why = end_reason(_end("unexplained", 1.17, 3.0, "assist_motor_friction", True, 1.16, 1.12), S)
    assert "1.17 noise floors, above the 1.15 of adequate" in why
    assert "assist_motor_friction not evidenced (BIC gain 3" in why


def test_an_end_whose_candidate_holds_zero_says_it_may_not_be_named():
    """At an end where the candidate's first-order strength (or its interval) reaches 0, the rule does not name it
    whatever its BIC gain, and the reason says so."""
    why = end_reason(_end("unexplained", 3.35, 80.0, "brush_patch", False, 1.0, 1.0), S)
    assert "above the 1.15 of adequate" in why and "brush_patch's strength here holds 0" in why


def test_an_evidenced_candidate_that_leaves_too_much_is_explained_by_its_thresholds():
    """A candidate evidenced at an end but leaving 1.6 floors (over the 1.3 ceiling) is not named, and the reason
    quotes what a name needs."""
    why = end_reason(_end("unexplained", 2.0, 40.0, "column_friction", True, 1.6, 1.55), S)
    assert "column_friction evidenced (BIC gain 40) but leaves 1.6 floors" in why
    assert f"within {S.missing_rms_ceiling:g}" in why


def test_a_named_end_and_an_adequate_end_say_what_held():
    """A named end gives the candidate's gain over the threshold; an adequate one the error within the band."""
    assert end_reason(_end("missing", 1.5, 30.0, "column_friction", True, 1.02, 1.0), S).startswith(
        "column_friction evidenced (BIC gain 30 > 10), 1.02 floors with it")
    assert "1.05 noise floors, within the 1.15 of adequate; no candidate evidenced" in end_reason(
        _end("adequate", 1.05), S)
