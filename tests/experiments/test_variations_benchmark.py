"""The variation benchmark: its scoring follows the stated targets, its hands do what they say, its cases share
their records as designed, and one small real case runs end to end."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from parksteer.synthetic.datasets import BASE_PERTURBATION
from parksteer.experiments.rows import VariationRow
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.experiments.variation_summary import outcome, summarise
from parksteer.experiments.variations import (
    COVERAGE_TARGET,
    NAMED_MIN_STEPS,
    NAMED_TARGET,
    NULL_ADEQUATE_TARGET,
    VariationDesign,
    run_case,
    variation_cases,
)
from parksteer.errors import UsageError
from parksteer.measure.io import read_measurement
from parksteer.parameters import DEFAULT_PATH, load_parameters
from parksteer.synthetic.variations import VARIATIONS, HandVariant, variation_hand

PARAMS = load_parameters()
FILES = (("unladen", "ground"), ("part_laden", "ground"), ("offset_68_5mm", "ground"))


def _design(variations=("pauses",), replicates=1, hidden=("rack_stiction",), steps=(3.5,)):
    return VariationDesign(tuple(variations), replicates, tuple(hidden), tuple(steps), FILES, 11, BASE_PERTURBATION)


def _row(variation, hidden="nothing", steps=0.0, verdict="adequate", named=False, covered=3, intervals=3,
         over=1.0, after=None, replicate=0, effect=""):
    return VariationRow(name=f"{variation}_{hidden}_{steps}", variation=variation, replicate=replicate,
                        hidden=hidden, steps=steps, steps_actual=steps, verdict=verdict, effect=effect,
                        named=named, false_alarm=hidden == "nothing" and verdict == "missing",
                        calibrated_over_floor=over, after_over_floor=after, covered=covered, intervals=intervals,
                        wall_s=10.0)


def test_summary_counts_each_target_by_hand_and_names_the_variation_that_misses():
    """On hand-made outcomes with known counts: the named rate counts only hidden effects of at least
    NAMED_MIN_STEPS steps (a 1-step miss does not count against it), nulls count as adequate only when called
    adequate, coverage pools every interval; a variation whose own rate falls below a target is listed with that
    target, and the grid's target fails when its pooled rate does."""
    rows = [
        _row("a"), _row("a", covered=2),
        _row("a", "rack_stiction", 3.5, "missing", True, 4, 4, over=5.0, after=1.01, effect="rack_stiction"),
        _row("a", "rack_stiction", 2.0, "missing", True, 4, 4, over=3.0, after=1.05, effect="rack_stiction"),
        _row("b", verdict="missing", over=1.2, effect="column_friction"),  # a false alarm
        replace(_row("b", "rack_stiction", 3.5, "unexplained", False, 1, 3, over=2.0), not_covered="p q",
                hidden_confounded_with="steering.rack_friction_force"),
        _row("b", "rack_stiction", 1.0, "adequate", False, 3, 3, over=1.1),  # below the named rate's size
    ]
    s = summarise(rows)
    t = s["targets"]
    assert NAMED_MIN_STEPS == 2.0
    assert t["named"]["count"] == [2, 3] and t["named"]["value"] == pytest.approx(2 / 3)
    assert t["null_adequate"]["count"] == [2, 3]
    assert t["coverage"]["count"] == [3 + 2 + 4 + 4 + 3 + 1 + 3, 3 + 3 + 4 + 4 + 3 + 3 + 3]
    assert not t["named"]["met"] and not t["null_adequate"]["met"]
    assert t["coverage"]["met"] == (20 / 23 >= COVERAGE_TARGET)
    assert not s["target_met"] and s["false_alarms"] == 1
    missed = {(m["variation"], m["target"]) for m in s["misses"]}
    assert ("b", "named") in missed and ("b", "null_adequate") in missed
    assert not any(v == "a" for v, _ in missed)  # variation a meets all three
    by = {v["variation"]: v for v in s["variations"]}
    assert by["a"]["named_count"] == [2, 2] and by["a"]["null_over_floor"] == [1.0, 1.0]
    assert by["a"]["named_after_over_floor"] == [1.01, 1.05]
    assert by["b"]["not_covered"] == {"p": 1, "q": 1} and by["a"]["not_covered"] == {}
    assert by["b"]["missed"][0] == {"hidden": "rack_stiction", "steps": 3.5, "said": "unexplained", "effect": "",
                                    "confounded_with": "steering.rack_friction_force"}
    h = s["by_hidden"]["rack_stiction"]
    assert h["named_count"] == [2, 3] and h["missed_flagged_confounded"] == 1
    assert h["observable_fraction"] is None  # no record says how much of its change survives a calibration
    kept = summarise([replace(r, steps_observable=0.5 * r.steps) for r in rows])["by_hidden"]["rack_stiction"]
    assert kept["observable_fraction"] == {"median": 0.5, "min": 0.5, "max": 0.5}
    assert h["confounded_with"] == ["steering.rack_friction_force"]
    assert h["missed_in"] == ["b"] and h["named_in_all_of"] == ["a"]
    assert s["null_over_floor"] == {"min": 1.0, "max": 1.2}
    assert s["thresholds"] == {"adequate_rms_factor": DEFAULT_SETTINGS.adequate_rms_factor,
                               "missing_rms_ceiling": DEFAULT_SETTINGS.missing_rms_ceiling}


def test_summary_meets_every_target_when_all_is_right():
    """All nulls adequate, every hidden effect named, every interval covering: each target holds, none missed."""
    rows = [_row(v, r) for v in ("a", "b") for r in ("nothing",)] + [
        _row(v, "kingpin_friction", 2.0, "missing", True, 4, 4, after=1.0, effect="kingpin_friction")
        for v in ("a", "b")]
    s = summarise(rows)
    assert s["target_met"] and s["misses"] == []
    assert {k: v["value"] for k, v in s["targets"].items()} == {"named": 1.0, "null_adequate": 1.0, "coverage": 1.0}
    assert NAMED_TARGET <= 1.0 and NULL_ADEQUATE_TARGET <= 1.0


def _interval(lo, hi):
    return {"value": 0.5 * (lo + hi), "ci95": [lo, hi], "standard_error": (hi - lo) / 4}


def _result(verdict, effect, group=(), ranking=(), calibrated=None):
    return {"verdict": verdict, "effect": effect, "indistinguishable": [{"effect": g} for g in group],
            "ranking": list(ranking), "calibrated": calibrated or {}, "noise_floor_Nm": 0.2,
            "statistics": {"calibrated": {"weighted_rms_Nm": 0.3},
                           "with_effect": {"weighted_rms_Nm": 0.21} if verdict == "missing" else None},
            "cost": {"wall_s": 9.0}}


def _truth(hidden=None, strength=None):
    return {"name": "x", "variation": "pauses", "replicate": 0, "hidden": hidden,
            "steps_requested": 3.5 if hidden else None, "steps": 3.4 if hidden else None,
            "strength_key": "rack_stiction.breakaway_excess" if hidden else None, "strength": strength,
            "base_overrides": {"tyre.friction_coefficient": 0.8, "steering.rack_friction_force": 700.0}}


def test_outcome_names_from_the_group_and_scores_the_reported_models_intervals():
    """The hidden effect counts as named when it is in the group reported beside the named one. The intervals
    scored are those of the model reported (with the named effect): a base parameter's interval missing its true
    value is not covered, and the named effect, which was not the hidden one, is truly absent, so its strength's
    interval covers only if it holds 0. The error ratios are in noise floors."""
    ranking = [{"effect": "column_friction", "strength_parameter": "column_friction.torque",
                "parameters": {"tyre.friction_coefficient": _interval(0.7, 0.9),
                               "steering.rack_friction_force": _interval(710.0, 750.0),
                               "column_friction.torque": _interval(0.1, 0.3)}}]
    result = _result("missing", "column_friction", group=["rack_stiction"], ranking=ranking)
    o = outcome(_truth("rack_stiction", 250.0), result)
    assert o.named and not o.false_alarm and o.hidden_confounded_with == ""
    assert (o.covered, o.intervals) == (1, 3)
    assert o.not_covered == "column_friction.torque steering.rack_friction_force"
    assert o.calibrated_over_floor == pytest.approx(1.5) and o.after_over_floor == pytest.approx(1.05)


def test_outcome_records_when_the_diagnosis_warned_the_hidden_effect_is_confounded():
    """A hidden effect called adequate is not named; when the diagnosis listed it as confounded with a calibrated
    parameter, the outcome keeps that warning (the miss was flagged, not silent)."""
    result = {**_result("adequate", None, calibrated={"steering.rack_friction_force": _interval(760.0, 780.0)}),
              "confounded": [{"effect": "kingpin_friction", "confounded_with": "steering.rack_friction_force",
                              "identifiable_fraction": 0.1}]}
    truth = {**_truth("kingpin_friction", 0.003), "strength_key": "kingpin_friction.friction_radius"}
    o = outcome(truth, result)
    assert not o.named and o.hidden_confounded_with == "steering.rack_friction_force"
    assert (o.covered, o.intervals) == (0, 1)  # the rack friction absorbed the hidden friction: 770 vs 700


def test_outcome_of_a_null_scores_the_calibrated_intervals_and_a_false_alarm():
    """With nothing hidden, an adequate verdict's intervals are the calibrated base's, against the perturbed base;
    a missing verdict on a null is a false alarm and never counts as named."""
    calibrated = {"tyre.friction_coefficient": _interval(0.75, 0.85),
                  "steering.rack_friction_force": _interval(650.0, 720.0)}
    o = outcome(_truth(), _result("adequate", None, calibrated=calibrated))
    assert (o.covered, o.intervals, o.named, o.false_alarm) == (2, 2, False, False)
    ranking = [{"effect": "rack_damping", "strength_parameter": "rack_damping.coefficient",
                "parameters": {"rack_damping.coefficient": _interval(-1.0, 5.0)}}]
    o = outcome(_truth(), _result("missing", "rack_damping", ranking=ranking))
    assert o.false_alarm and not o.named and (o.covered, o.intervals) == (1, 1)


def test_cases_of_one_variation_share_their_records_and_a_smaller_grid_is_part_of_a_larger():
    """The null and each hidden effect of one variation and replicate are diagnosed on records of the same hand,
    noise and base parameters (one seed), so a difference in verdict is the hidden effect's; variations and
    replicates have their own seeds; a case keeps its seed when the grid grows."""
    small = variation_cases(_design(("pauses", "lock_overshoot")))
    large = variation_cases(_design(tuple(v.name for v in VARIATIONS), replicates=2,
                                    hidden=("rack_stiction", "column_friction"), steps=(2.0, 3.5)))
    by_name = {c.name: c for c in large}
    assert all(c.name in by_name and by_name[c.name].seed == c.seed for c in small)
    assert len(small) == 4 and len(large) == 2 * len(VARIATIONS) * 5
    seeds = {}
    for c in large:
        seeds.setdefault((c.variation.name, c.replicate), set()).add(c.seed)
    assert all(len(s) == 1 for s in seeds.values())
    assert len({next(iter(s)) for s in seeds.values()}) == len(seeds)


def test_an_unknown_variation_or_too_many_files_is_refused_in_one_line():
    """A grid naming a variation that does not exist, or one that needs more files than listed, is refused."""
    section = {"full_grid": False, "seed": 1, "files": [["unladen", "ground"]],
               "small": {"variations": ["no_such"], "replicates": 1, "hidden": [], "steps": [1.0]},
               "full": {"variations": ["pauses"], "replicates": 1, "hidden": [], "steps": [1.0]}}
    with pytest.raises(UsageError, match="no_such") as info:
        VariationDesign.from_config(section)
    assert "\n" not in str(info.value)
    section["small"]["variations"] = ["three_files"]
    with pytest.raises(UsageError, match="three_files needs 3 files"):
        VariationDesign.from_config(section)


@pytest.mark.parametrize("effect, confounded", [("kingpin_friction", True), ("rack_stiction", False)])
def test_what_a_calibration_can_absorb_of_a_hidden_effect(effect, confounded):
    """On one load, a king-pin friction (the load times a friction radius, a torque about each king-pin axis that
    the steering arms pass to the rack as a nearly constant force) is mostly a change of the calibrated rack
    friction force: less than the diagnosis's confounded_fraction (0.3) of its change survives the projection off
    the calibrated directions, the same verdict the diagnosis reaches on its own from the replayed signature. A
    rack stiction (a breakaway peak at each rack reversal, which no constant force, friction coefficient or carcass
    stiffness makes) keeps most of its change. The size is set on the whole change (2 steps +-2 %)."""
    from parksteer.experiments.variations import _case_files, hidden_strength
    from parksteer.synthetic.datasets import perturbed_base
    from parksteer.measure.converter import quantisation_step

    design = _design(("pauses",), hidden=(effect,), steps=(2.0,))
    case = next(c for c in variation_cases(design) if c.hidden)
    files = _case_files(case, design)
    logger = files[0][3]
    step = quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
    _key, strength, change, observable = hidden_strength(PARAMS, files, perturbed_base(PARAMS, case.seed, BASE_PERTURBATION),
                                                         effect, 2.0 * step)
    assert strength > 0.0 and change == pytest.approx(2.0 * step, rel=0.021)
    kept = observable / change
    assert kept < DEFAULT_SETTINGS.confounded_fraction if confounded else kept > 0.8


def test_uneven_strokes_and_lock_overshoot_keep_the_travel():
    """Uneven strokes reach the right lock at the scaled first-stroke time and still end at straight ahead; a
    driver who overshoots turns past each lock by the stated fraction, is back at it after the return time, and
    ends at straight
    ahead (each stroke's rate integrates to its travel)."""
    p = PARAMS.sections["input"]
    lock, first = p["handwheel_lock_angle"], p["time_to_right_lock"]
    t, angle = variation_hand(PARAMS, HandVariant(0.05, 0.2, stroke_scale=(0.7, 1.3, 0.85), seed=2))
    assert np.max(angle) == pytest.approx(lock, rel=1e-6) and np.min(angle) == pytest.approx(-lock, rel=1e-6)
    assert t[np.argmax(angle)] == pytest.approx(0.7 * first, abs=0.05)
    assert abs(angle[-1]) < 1e-9 * lock
    t, angle = variation_hand(PARAMS, HandVariant(0.05, 0.2, overshoot=0.05, overshoot_return_s=0.8, seed=2))
    assert np.max(angle) == pytest.approx(1.05 * lock, rel=1e-6)
    assert np.min(angle) == pytest.approx(-1.05 * lock, rel=1e-6)
    assert np.interp(first + 0.8, t, angle) == pytest.approx(lock, rel=1e-6)  # back at the lock after 0.8 s
    assert abs(angle[-1]) < 1e-9 * lock


def test_a_null_case_runs_end_to_end(tmp_path):
    """A null of the 50 Hz variation, written to a file and diagnosed from it: nothing hidden, so the true model
    sits at the noise floor and the diagnosis says adequate (the calibrated error within adequate_rms_factor
    floors); the truth file records nothing hidden and the perturbed base the intervals are scored against."""
    design = _design(("rate_8pc_50Hz",), hidden=())
    (case,) = variation_cases(design)
    folder = tmp_path / "files"
    folder.mkdir()
    result = run_case(DEFAULT_PATH, design, case.name, folder, tmp_path / "t.json", tmp_path / "d.json")
    truth = json.loads((tmp_path / "t.json").read_text(encoding="utf-8"))
    record = read_measurement(folder / "unladen__ground.csv")
    assert record.metadata["sample_rate_hz"].startswith("50")
    assert truth["hidden"] is None and set(truth["base_overrides"]) == set(BASE_PERTURBATION)
    o = outcome(truth, result)
    assert o.verdict == "adequate" and not o.false_alarm
    assert o.calibrated_over_floor < DEFAULT_SETTINGS.adequate_rms_factor
    assert o.intervals == len(BASE_PERTURBATION)


def test_a_lagged_torque_channel_is_the_unlagged_one_shifted_and_the_rack_is_untouched():
    """A logger whose torque channel converts 10 ms after the rack: with fine converters and no noise, its rack
    is the plain logger's rack and its torque is the plain torque 10 ms earlier (linear interpolation between
    samples 10 ms apart at 100 Hz is exact at the sample times: the shift is one sample), away from the first
    sample, where the lagged channel holds its first value."""
    from parksteer.synthetic.variations import VariationLogger, variation_record

    hand = HandVariant(0.05, 0.2, seed=4)
    fine = dict(rack_bits=24, torque_bits=24, rack_noise_m=0.0, torque_noise_Nm=0.0, seed=4)
    plain = variation_record(PARAMS, hand, VariationLogger(100.0, **fine))
    lagged = variation_record(PARAMS, hand, VariationLogger(100.0, torque_lag_s=0.01, **fine))
    assert np.array_equal(plain.columns["rack_m"], lagged.columns["rack_m"])
    step = 2 * 25.0 / (2**24 - 1)
    shifted = lagged.columns["handwheel_torque_Nm"][1:] - plain.columns["handwheel_torque_Nm"][:-1]
    assert np.max(np.abs(shifted)) < 2 * step + 1e-6
    assert lagged.metadata["torque_lag_s"] == "0.01"
