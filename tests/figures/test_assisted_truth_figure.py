"""figures/diag_assisted_truth: the rows of the assisted truth's jobs scored per tier and drawn, the same bytes
whichever way the jobs split the cases."""

from __future__ import annotations

import json

from parksteer.experiments.assisted_truth import ROW_SUFFIX
from parksteer.figures.assisted_truth import gather_assisted_truth_figure


def _row(name, tier, kind, hidden="nothing", floors=0.0, verdict="adequate", effect="", **extra):
    row = {"name": name, "route": "map", "tier": tier, "kind": kind, "variation": "pauses", "hidden": hidden,
           "floors": floors, "floors_requested": floors or None, "strength": None, "torque_step_Nm": 0.005,
           "verdict": verdict, "effect": effect, "indistinguishable": "", "calibrated_over_floor": 1.0,
           "wall_s": 1.0, "generation_s": 0.1}
    row.update(extra)
    return row


ROWS = [
    _row("rack__a__null", "rack", "null"),
    _row("rack__b__null", "rack", "null", verdict="missing", effect="rack_stiction", calibrated_over_floor=1.05),
    _row("rack__c__friction", "rack", "hidden", "assist_motor_friction", 4.0, "missing", "column_friction",
         named=True, calibrated_over_floor=1.2),
    _row("rack__d__small", "rack", "hidden", "boost_gain_error", 1.0, "adequate", named=False),
    _row("rack__e__cogging", "rack", "outclass", "cogging", 3.0, "missing", "rack_stiction", relation="unrelated",
         bic_margin=40.0, confident=True, confident_wrong=True, calibrated_over_floor=1.3),
    _row("angle__a__null", "angle", "null"),
    _row("angle__e__hysteresis", "angle", "outclass", "boost_hysteresis", 3.0, "unexplained", relation="unexplained",
         bic_margin=None, confident=False, confident_wrong=False, calibrated_over_floor=2.0),
]


def _write(folder, names):
    folder.mkdir(parents=True)
    for row in ROWS:
        if row["name"] in names:
            (folder / f"{row['name']}{ROW_SUFFIX}").write_text(json.dumps([row]), encoding="utf-8")


def test_scores_per_tier_and_draws_the_same_bytes_however_the_jobs_split(tmp_path):
    """Per tier: a hidden record below 2 noise floors does not count towards the named rate, a null that names an
    effect is a false alarm, an out-of-class record named with a BIC margin beyond the band and unrelated is a
    confident wrong answer; one job or two give the same figure, table and numbers."""
    names = [r["name"] for r in ROWS]
    outputs = []
    for label, split in (("one", [names]), ("two", [names[:3], names[3:]])):
        folders = []
        for k, part in enumerate(split):
            folder = tmp_path / label / f"job{k}"
            _write(folder, part)
            folders.append(folder)
        out = tmp_path / label
        summary = gather_assisted_truth_figure(folders, names, None, "data/vehicles/polo_vi.toml", out / "f.svg",
                                               out / "f.csv", out / "f.json")
        outputs.append([(out / f).read_bytes() for f in ("f.svg", "f.csv", "f.json")])
    assert outputs[0] == outputs[1]
    rack, angle = summary["routes"]["map"]["rack"], summary["routes"]["map"]["angle"]
    assert rack["targets"]["named"]["count"] == [1, 1]
    assert rack["targets"]["null_adequate"]["count"] == [1, 2]
    assert rack["targets"]["confident_wrong_out_of_class"]["cases"] == ["rack__e__cogging"]
    assert angle["targets"]["null_adequate"]["count"] == [1, 1]
    assert angle["out_of_class_not_named"] == [1, 1]
    assert not summary["target_met"]
    assert b"wall_s" not in outputs[0][2]  # no machine times in the numbers the paper reads
