"""The assumed-values table: each band end's verdict by the headline's rule, and why an end is not adequate
(parksteer.diagnose.stages.assumed)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from parksteer.cli import main
from parksteer.diagnose.parallel import can_fork
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


# --- which values are assumed: declared in the vehicle file, not read from a source's prose ---------------------

def _polo_with(tmp_path, line_from: str, line_to: str):
    from pathlib import Path

    from parksteer.model.symbolic.components import discover_effects
    from parksteer.vehicle import vehicle_from_text

    discover_effects()
    text = (Path(__file__).resolve().parents[2] / "data" / "vehicles" / "polo_vi.toml").read_text(encoding="utf-8")
    assert line_from in text
    return vehicle_from_text(text.replace(line_from, line_to), tmp_path / "polo.toml")


def _assumed_keys(params):
    from parksteer.diagnose.stages.assumed import assumed_quantities
    from parksteer.model.symbolic.components import discover_effects

    effect = discover_effects()["electric_assist_column"]
    return {key for key, *_ in assumed_quantities(params, effect.name, effect)}


def test_a_value_declared_measured_is_not_replayed_whatever_its_source_says(tmp_path):
    """The Polo file's motor friction, whose source reads "assumed: ...", declared ``provenance = "measured"``
    leaves the assumed values; its torque constant, with the same kind of source and no declaration, stays, and so
    does the limit's smoothing declared assumed with a source that says nothing of it."""
    params = _polo_with(tmp_path, 'motor_friction_torque = { value = 0.02, unit = "N m", source = "assumed: ',
                        'motor_friction_torque = { value = 0.02, unit = "N m", provenance = "measured", source = "'
                        'assumed: ')
    assert params.provenance("electric_assist_column.motor_friction_torque") == "measured"
    keys = _assumed_keys(params)
    assert "motor_friction_torque" not in keys and "torque_constant" in keys
    params = _polo_with(tmp_path, 'source = "numerical: about 1 % of the limit" }',
                        'source = "a choice of the file", provenance = "assumed" }')
    assert "limit_smoothing" in _assumed_keys(params)


def test_an_unknown_provenance_is_refused_in_one_line(tmp_path):
    """``provenance = "guessed"`` is not one of measured, identified, assumed: refused naming the file and key."""
    import pytest

    from parksteer.parameters import ParameterError

    with pytest.raises(ParameterError) as refused:
        _polo_with(tmp_path, 'source = "numerical: about 1 % of the limit" }',
                   'source = "numerical: about 1 % of the limit", provenance = "guessed" }')
    message = str(refused.value)
    assert "\n" not in message and "polo.toml: assist.limit_smoothing: provenance 'guessed'" in message


def test_the_template_declares_given_values_measured_and_defaults_assumed(tmp_path):
    """`parksteer vehicle new --assist column` (assist_template): a value the specification gives is declared
    measured, every default assumed, so the diagnosis replays exactly the defaults at their bands' ends."""
    import re

    from parksteer.model.numeric.assist import assist_template

    section = assist_template("column", {"reduction_ratio": (17.0, "specification")})
    declared = dict(re.findall(r'^(\w+) = \{.*provenance = "(\w+)" \}$', section, flags=re.M))
    assert declared.pop("reduction_ratio") == "measured"
    assert declared and set(declared.values()) == {"assumed"}


# --- the band ends' replays, spread over the workers ------------------------------------------------------------

@pytest.mark.slow
@pytest.mark.skipif(not can_fork(), reason="the platform cannot fork: everything runs in line")
def test_the_band_ends_replayed_in_workers_give_the_table_of_one_process(capsys, tmp_path):
    """The band ends' replays are independent, so two worker processes give the table one process gives, to the
    bit (each end's fitted figures, verdicts and reasons), for the one record of an assisted car (whose ends the
    workers share out, not its files); and every solve a worker runs is counted: four a quantity (the calibrated
    model and the best candidate's refit at each end), in both.

    The record is the first half of the sample's (its rows to the right lock and back): what is compared is one
    process against its workers on the same problem, which the record's length does not enter."""
    root = Path(__file__).resolve().parents[2]
    lines = (root / "data" / "samples" / "polo_drag.csv").read_text(encoding="utf-8").splitlines()
    header = [line for line in lines if line.startswith("#")]
    names, *rows = [line for line in lines if not line.startswith("#")]
    half = tmp_path / "polo_drag.csv"
    half.write_text("\n".join([*header, names, *rows[: len(rows) // 2]]) + "\n", encoding="utf-8")
    arguments = ["diagnose", str(half), "--with-assist", "--vehicle",
                 str(root / "data" / "vehicles" / "polo_vi.toml"), "--json", "--quiet"]
    out = {}
    for jobs in (1, 2):
        assert main([*arguments, "--jobs", str(jobs)]) == 0
        out[jobs] = json.loads(capsys.readouterr().out)
    table = out[1]["assumed"]
    assert len(table["quantities"]) >= 5 and table["nominal"]["delta_bic"] is not None  # a refit replayed too
    assert json.dumps(out[2]["assumed"]) == json.dumps(table)
    for result in out.values():
        by_stage = result["cost"]["replays_by_stage"]  # cumulative, in the stages' order
        stages = list(by_stage)
        before = by_stage[stages[stages.index("assumed") - 1]]
        assert by_stage["assumed"] - before == 4 * len(table["quantities"])
    assert out[2]["cost"]["replays"] == out[1]["cost"]["replays"]


# --- against a baseline: a calibrated value that changed, by the headline's rule for it -------------------------

def test_a_changed_value_at_an_end_is_judged_by_its_interval_against_the_baselines_value():
    """A library strength is absent at 0: named only above 0 with its interval clear of 0. A calibrated value freed
    against a baseline (``changed:<key>``, fitted in its logarithm from the baseline's value, or as it stands from
    it for an angle) is absent at the baseline's value: it may be named where its interval leaves that value out,
    grown or shrunk, as the headline rule of diagnose/baseline_changed.py, never because it is far from 0."""
    from parksteer.diagnose.fitting import FitParameter
    from parksteer.diagnose.stages.assumed import clear_of_absence

    strength = FitParameter("column_friction.friction_torque", "linear", 1.0, 0.0, 5.0, 1e-3)
    assert clear_of_absence(strength, 0.05, 0.03, True)
    assert not clear_of_absence(strength, 0.02, 0.03, True) and clear_of_absence(strength, 0.02, 0.03, False)
    grown = FitParameter("steering.rack_friction_force", "log", 750.0, 375.0, 1500.0, 0.03)
    assert clear_of_absence(grown, 0.05, 0.03, True) and clear_of_absence(grown, -0.05, 0.03, True)
    assert not clear_of_absence(grown, 0.02, 0.03, True)  # 766 N: its interval holds the baseline's 750 N
    phase = FitParameter("steering.hooke_joint_phase", "offset", 0.4, -1.17, 1.97, 0.05)
    assert clear_of_absence(phase, 0.45, 0.03, True) and not clear_of_absence(phase, 0.42, 0.03, True)
    why = end_reason(_end("unexplained", 3.0, 40.0, "changed:steering.rack_friction_force", False, 1.0, 1.0), S,
                     "the baseline's value")
    assert "changed:steering.rack_friction_force's interval here holds the baseline's value" in why
