"""The out-of-class benchmark: its truth generator is not the diagnosis model, its logger chain does what it
says, its scoring follows the stated targets, and one small case runs end to end."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.diagnose.candidates import candidate_effects
from parksteer.experiments.outclass import outcome, run_case
from parksteer.errors import UsageError
from parksteer.model.symbolic.components import discover_effects, resolve_effects
from parksteer.parameters import DEFAULT_PATH, load_parameters
from parksteer.synthetic.datasets import hand
from parksteer.synthetic.outclass import (
    ChainLogger,
    OutclassDesign,
    chain_logged,
    chain_torque_step_Nm,
    outclass_rivals,
    outclass_specs,
)
from parksteer.synthetic.size_search import SizeSearch

CHAIN = ChainLogger(sample_rate_hz=50.0, anti_alias_hz=10.0, anti_alias_order=2, torque_lag_s=0.01, torque_bits=8,
                    rack_bits=12)

OUTCLASS_RIVALS = outclass_rivals()  # each rival effect's closest and related candidates


def _design(rivals=("top_mount_windup",), steps=(4.0,), nulls=0, files=(("unladen", "ground"),)):
    return OutclassDesign(tuple(rivals), tuple(steps), nulls, tuple(files), 1e-9, CHAIN, 7,
                          {"tyre.friction_coefficient": 0.05}, SizeSearch(4, 0.1, 0.3))


def test_rivals_are_no_candidates_and_closest_entries_are():
    """The inverse crime is ruled out by construction: no rival is among the candidates the diagnosis fits (it
    cannot name the truth's form), while every 'closest' and 'related' entry is one (it can name those)."""
    registry = discover_effects()
    testable = {e.name for e in candidate_effects(resolve_effects(None), registry)[0]}
    assert testable, "the diagnosis has candidates"
    for rival, entry in OUTCLASS_RIVALS.items():
        assert rival in registry and not registry[rival].diagnosis_candidate
        assert rival not in testable
        assert entry["reason"]
        for name in ([entry["closest"]] if entry["closest"] else []) + list(entry["related"]):
            assert name in testable, f"{rival}: {name} is not a diagnosis candidate"


def test_a_candidate_is_refused_as_a_rival():
    """A diagnosis candidate hidden as a 'rival' would be the in-class benchmark again: refused."""
    with pytest.raises(UsageError, match="rack_stiction"):
        outclass_specs(load_parameters(), _design(rivals=("rack_stiction",)))


def test_logger_chain_lag_quantisation_and_dc_gain():
    """Through the chain, the torque sits on the 8-bit grid and the rack on the 12-bit grid of their full scales;
    a constant stays at its value (the filter's unit gain at DC, started from rest); and with identical ramps on
    both channels the torque lags the rack by the channel lag (the filter delays both alike)."""
    params = load_parameters()
    t = np.arange(0.0, 12.0 + 1e-9, 0.001)
    ramp = np.clip(t - 1.0, 0.0, 10.0) / 10.0 - 0.5  # at rest, a 10 s ramp, at rest
    columns = {"time_s": t, "rack_m": 0.1 * ramp, "handwheel_torque_Nm": 20.0 * ramp}
    m = chain_logged(params, columns, CHAIN, "unladen", "ground", 3, hand(params, 1))
    rack, torque, time_s = m.columns["rack_m"], m.columns["handwheel_torque_Nm"], m.columns["time_s"]
    s = params.sections["synthetic"]
    step = chain_torque_step_Nm(params, CHAIN)
    assert step == pytest.approx(2 * s["full_scale_torque"] / 255)
    levels = (torque + s["full_scale_torque"]) / step
    assert np.allclose(levels, np.rint(levels), atol=1e-9)
    rack_levels = (rack + s["full_scale_rack"]) / (2 * s["full_scale_rack"] / (2**12 - 1))
    assert np.allclose(rack_levels, np.rint(rack_levels), atol=1e-6)
    at_rest = time_s < 0.9
    assert abs(np.mean(torque[at_rest]) - (-10.0)) < 0.1  # noise 0.15 N m and a 0.2 N m step average out
    cruise = (time_s > 2.0) & (time_s < 10.0)
    # both ramps move 1/10 of their span per second: a time shift is the difference over that rate
    lag = np.mean(rack[cruise] / 0.1 - torque[cruise] / 20.0) / 0.1
    assert lag == pytest.approx(CHAIN.torque_lag_s, abs=0.004)


def _result(verdict, effect=None, gains=(), group=()):
    stats = {"weighted_rms_Nm": 0.4, "rms_Nm": 0.4}
    return {"verdict": verdict, "effect": effect, "noise_floor_Nm": 0.16,
            "selection": {"thresholds": {"bic_indistinguishable": 6.0, "bic_missing": 10.0}},
            "ranking": [{"effect": f"c{i}", "delta_bic": g, "weighted_rms_after_Nm": 0.3, "explained_fraction": 0.5}
                        for i, g in enumerate(gains)],
            "indistinguishable": [{"effect": g} for g in group],
            "statistics": {"calibrated": stats, "with_effect": stats if effect else None}, "cost": {"wall_s": 1.0}}


def _truth(hidden="rolling_resistance", steps=4.0, kind="rival"):
    entry = OUTCLASS_RIVALS.get(hidden, {"closest": None, "related": ()})
    return {"name": "o0", "kind": kind, "hidden": hidden, "steps_requested": steps, "steps": steps,
            "closest": entry["closest"], "related": list(entry["related"])}


def test_scoring_follows_the_targets():
    """The stated targets: an unrelated candidate named with a margin beyond the band (6) is a confident wrong
    answer, within it is not; 'adequate' at >= 3 steps misses, below it does not; the closest, a related
    candidate, or 'unexplained' meet the target."""
    wrong = outcome(_truth(), _result("missing", "rack_lash", gains=(30.0, 10.0)))
    assert (wrong.relation, wrong.bic_margin, wrong.confident_wrong, wrong.target_met) == (
        "unrelated", 20.0, True, False)
    close_call = outcome(_truth(), _result("missing", "rack_lash", gains=(30.0, 26.0), group=("braked_wheels",)))
    assert close_call.relation == "unrelated" and not close_call.confident_wrong
    assert close_call.closest_in_group
    assert outcome(_truth(), _result("missing", "braked_wheels", gains=(50.0,))).relation == "closest"
    assert outcome(_truth(), _result("missing", "kingpin_friction", gains=(50.0,))).relation == "related"
    assert outcome(_truth(), _result("unexplained")).target_met
    assert not outcome(_truth(steps=3.0), _result("adequate")).target_met
    assert outcome(_truth(steps=2.0), _result("adequate")).target_met
    assert outcome(_truth(None, None, "null"), _result("adequate")).relation == "correct"


def test_an_unexplained_verdict_reports_the_strongly_evidenced_nearest_candidate():
    """An unexplained verdict with a candidate above the BIC threshold (named but not the whole story) keeps that
    candidate as the nearest, with the error it leaves; one with no strong evidence has none."""
    row = outcome(_truth("top_mount_windup"), _result("unexplained", gains=(496.1, 20.0)))
    assert row.said == "unexplained" and row.target_met
    assert row.nearest == "c0" and row.nearest_after_over_floor == pytest.approx(0.3 / 0.16)
    assert row.explained_fraction == 0.5
    weak = outcome(_truth("top_mount_windup"), _result("unexplained", gains=(4.0,)))
    assert weak.nearest == "none" and weak.nearest_after_over_floor is None


def test_a_small_case_runs(tmp_path):
    """One rival on one file: made by the handwheel-driven truth at its own tolerance, logged, written, read back
    and diagnosed; the hidden size is the one asked for (within the search's tolerance) and the truth names no
    candidate as its form."""
    design = _design()
    (spec,) = outclass_specs(load_parameters(), design)
    result = run_case(DEFAULT_PATH, design, spec.name, tmp_path / "files", tmp_path / "t.json", tmp_path / "d.json")
    import json

    truth = json.loads((tmp_path / "t.json").read_text())
    assert truth["hidden"] == "top_mount_windup" and truth["closest"] is None
    assert truth["steps"] == pytest.approx(4.0, rel=0.1)
    assert truth["rtol"] == 1e-9
    assert (tmp_path / "files" / "unladen__ground.csv").exists()
    row = outcome(truth, result)
    assert row.relation in ("closest", "related", "unrelated", "unexplained", "adequate")


def test_config_grids():
    """The pipeline's design: the small grid has each rival once plus the nulls; the full grid (the switch) has each
    rival at every size; every data set has its own seed, and nothing hidden is a candidate."""
    import yaml

    from pathlib import Path

    config = yaml.safe_load((Path(__file__).parents[2] / "config" / "config.yaml").read_text(encoding="utf-8"))
    params = load_parameters()
    for full in (False, True):
        section = {**config["outclass"], "full_grid": full}
        design = OutclassDesign.from_config(section, config["benchmark"])
        grid = section["full" if full else "small"]
        specs = outclass_specs(params, design)
        assert len(specs) == len(section["rivals"]) * len(grid["steps"]) + grid["nulls"]
        assert len({s.seed for s in specs}) == len(specs)
        assert all(s.hidden in OUTCLASS_RIVALS for s in specs if s.kind == "rival")
