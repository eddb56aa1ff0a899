"""The baseline benchmark (parksteer.experiments.baseline): its design from the configuration, its scoring, a
tiny grid run end to end, and its figure (parksteer.figures.baseline)."""

from __future__ import annotations

import json

import pytest

from parksteer.errors import UsageError
from parksteer.experiments.baseline import Car, Later, design_from_config, run_car, score, summarise

CAR = {"name": "bore", "kind": "manual", "quirk": "bore_friction", "quirk_floors": 5.0,
       "healthy_hand": "rest_after_stop", "healthy_bits": 12, "seed": 4501,
       "later": [{"what": "null", "hand": "pauses", "bits": 10}]}


def _said(verdict="adequate", effect="", named=False, confident=False, wrong=False, over=1.0):
    return {"verdict": verdict, "effect": effect, "indistinguishable": "", "named": named, "confident": confident,
            "confident_wrong": wrong, "changed_value": effect.startswith("changed:"), "bic_margin": None,
            "over_floor": over}


def _row(kind, hidden, absolute, baseline, floors=3.0):
    return {"car": "c", "name": f"{hidden}", "kind": kind, "hidden": hidden, "hand": "pauses", "bits": 12,
            "tier": "rack", "floors_requested": floors, "floors": floors, "strength": 1.0, "floor_Nm": 0.02,
            "absolute": absolute, "baseline": baseline}


def test_design_refuses_what_it_does_not_know_in_one_line():
    """A quirk, a later record or a converter the benchmark has not got is refused naming the car and the value."""
    assert design_from_config({"cars": [CAR]}).cars[0].later == (Later("null", "pauses", 10),)
    for key, value, said in (("quirk", "worn_rack", "worn_rack"), ("healthy_bits", 13, "13 bits"),
                             ("later", [{"what": "brake_judder", "hand": "pauses", "bits": 10}], "brake_judder")):
        with pytest.raises(UsageError, match=said) as error:
            design_from_config({"cars": [{**CAR, key: value}]})
        assert "bore" in str(error.value) and "\n" not in str(error.value)


def test_scoring_holds_each_bar_to_its_definition():
    """Named 3 of 4 meets the bar and 2 of 4 does not; one null not adequate fails the nulls; an out-of-class change
    named with confidence fails, named without confidence does not; a confident wrong name on a null fails; a side
    that was not run scores None."""
    named = [_row("hidden", f"h{i}", _said("missing", "x", named=i < 3), None) for i in range(4)]
    nulls = [_row("null", "null", _said(), None, 0.0), _row("null", "null", _said(), None, 0.0)]
    outclass = [_row("outclass", "joint_phasing", _said("missing", "column_friction", confident=False), None)]
    good = score(named + nulls + outclass, "absolute")
    assert good["named"] == [3, 4] and good["met"]
    assert score(named + nulls + outclass, "baseline") is None
    two = [_row("hidden", f"h{i}", _said("missing", "x", named=i < 2), None) for i in range(4)]
    assert not score(two + nulls, "absolute")["bars"]["named"]
    false_alarm = [_row("null", "null", _said("missing", "rack_damping", confident=True, wrong=True), None, 0.0)]
    scored = score(named + nulls + false_alarm, "absolute")
    assert not scored["bars"]["nulls_adequate"] and not scored["bars"]["no_confident_wrong"]
    confident = [_row("outclass", "joint_phasing", _said("missing", "column_friction", confident=True), None)]
    assert not score(named + nulls + confident, "absolute")["bars"]["out_of_class_not_confident"]
    small = [_row("hidden", "h", _said("unexplained"), None, floors=1.0)]  # below 2 floors: not counted
    assert score(named + small, "absolute")["named"] == [3, 4]


def test_an_out_of_class_change_read_as_a_changed_value_is_its_own_column():
    """An out-of-class change named with confidence as a calibrated value that moved (changed:<key>) is counted in a
    column of its own, not as a library effect named (the bar on those holds) and not as not named; a hidden change
    of a calibrated value is named right only by its own changed:<key>, and a library effect named instead of it
    with confidence is a confident wrong name."""
    from parksteer.experiments.baseline import judged

    nulls = [_row("null", "null", _said(), None, 0.0)]
    read = [_row("outclass", "bore_friction", _said("missing", "changed:steering.rack_friction_force",
                                                     confident=True), None)]
    scored = score(nulls + read, "absolute")
    assert scored["out_of_class_changed_value"] == [1, 1] and scored["out_of_class_confident"] == [0, 1]
    assert scored["bars"]["out_of_class_not_confident"]
    key = "changed:steering.rack_friction_force"
    truth = {"kind": "hidden", "hidden": key}

    def result(effect, gains):
        return {"verdict": "missing", "effect": effect, "indistinguishable": [],
                "ranking": [{"delta_bic": g} for g in gains],
                "selection": {"thresholds": {"bic_indistinguishable": 6.0}},
                "statistics": {"calibrated": {"weighted_rms_Nm": 0.03}}, "noise_floor_Nm": 0.02}

    right = judged(truth, result(key, [40.0, 12.0]))
    assert right["named"] and right["changed_value"] and not right["confident_wrong"]
    wrong = judged(truth, result("kingpin_friction", [40.0, 12.0]))
    assert not wrong["named"] and wrong["confident_wrong"] and not wrong["changed_value"]


def test_a_later_record_may_hide_a_change_of_a_calibrated_value():
    """The design knows a change of the rack friction as a hidden change (kind hidden), its record's name free of
    the key's colon; an assisted car refuses it (its calibration is another)."""
    key = "changed:steering.rack_friction_force"
    later = Later(key, "pauses", 12, 3.0)
    assert later.kind == "hidden" and ":" not in later.name
    design = design_from_config({"cars": [{**CAR, "later": [{"what": key, "hand": "pauses", "bits": 12,
                                                              "floors": 3.0}]}]})
    assert design.cars[0].later == (later,)
    assisted = {**CAR, "kind": "assisted", "quirk": "exp", "later": [{"what": key, "hand": "pauses", "bits": 12}]}
    with pytest.raises(UsageError, match="changed:steering.rack_friction_force") as error:
        design_from_config({"cars": [assisted]})
    assert "\n" not in str(error.value)


def test_figure_renders_both_sides_and_the_json_scores_them(tmp_path):
    """The figure draws every later record on both sides (a side not run drawn as such), its CSV has one row a
    record, and the JSON holds each car's score per side."""
    from parksteer.figures.baseline import gather_baseline_figure

    car = {"car": "c", "kind": "manual", "quirk": "bore_friction", "tier": "rack", "quirk_floors": 5.0,
           "baseline_method": "run", "healthy": {"verdict": "unexplained", "effect": "", "over_floor": 1.7},
           "learn_wall_s": 1.0,
           "rows": [_row("null", "null", _said("unexplained", over=1.6), _said(over=0.9), 0.0),
                    _row("hidden", "column_friction", _said("unexplained", over=2.1),
                         _said("missing", "column_friction", named=True, confident=True, over=1.0))]}
    other = {**car, "car": "d", "baseline_method": "not run",
             "rows": [{**r, "car": "d", "baseline": None} for r in car["rows"]]}
    paths = []
    for c in (car, other):
        path = tmp_path / f"{c['car']}.json"
        path.write_text(json.dumps(c), encoding="utf-8")
        paths.append(path)
    svg, csv, out = tmp_path / "f.svg", tmp_path / "f.csv", tmp_path / "f.json"
    summary = gather_baseline_figure(paths, svg, csv, out)
    text = svg.read_text(encoding="utf-8")
    assert text.startswith("<?xml") and "not run" in text and "column_friction" in text
    assert len([line for line in csv.read_text().splitlines() if line and not line.startswith("#")]) == 1 + 4
    written = json.loads(out.read_text())
    assert written["cars"]["c"]["baseline"]["named"] == [1, 1] and written["cars"]["d"]["baseline"] is None
    assert summary["baseline_method"] == "not run"


@pytest.mark.slow
def test_a_tiny_car_runs_on_both_sides():
    """A manual car with one later null: its quirk sized on the healthy record to the asked noise floors, the
    null's record judged on both sides (the baseline side where the method is there)."""
    from parksteer.experiments.baseline import baseline_api
    from parksteer.parameters import load_parameters

    car = Car("tiny", "manual", "bore_friction", "rest_after_stop", 12, (Later("null", "pauses", 10),), seed=11)
    out = run_car(load_parameters(), car)
    assert out["quirk_floors"] == pytest.approx(5.0, rel=1e-6)
    (row,) = out["rows"]
    assert row["kind"] == "null" and row["absolute"]["verdict"] in ("adequate", "missing", "unexplained")
    assert (row["baseline"] is not None) == baseline_api()[1]
    assert summarise([out])["cars"]["tiny"]["absolute"]["nulls_adequate"][1] == 1
