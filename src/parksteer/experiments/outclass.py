"""The out-of-class benchmark: diagnose records whose hidden effect is none of the candidates' forms.

The in-class benchmark (:mod:`parksteer.experiments.benchmark`) hides candidates in records made by the model the
diagnosis fits. Here the truth comes from elsewhere (:func:`parksteer.synthetic.outclass.make_outclass_dataset`):
a rival effect that is not a diagnosis candidate (gear efficiency, a tyre breakaway peak, a Maxwell carcass
branch, top-mount wind-up, a nonlinear linkage, rolling resistance), integrated handwheel-driven at a tighter
tolerance than the diagnosis's rack replay, and logged through a whole logger chain (anti-alias filter, channel
lag, 8-bit torque, quantised rack). The honest answers are the physically closest candidate (or one sharing its
physics, :func:`parksteer.synthetic.outclass.outclass_rivals`) or ``unexplained``. Each case is scored against
two targets: never ``adequate`` when the hidden effect is at least ADEQUATE_LIMIT_STEPS converter steps RMS,
and never a physically unrelated candidate named with a BIC margin over the runner-up beyond the
indistinguishable band (the diagnosis's own ``bic_indistinguishable``).
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import UsageError
from ..parameters import load_parameters
from ..synthetic.outclass import OutclassDesign, make_outclass_dataset, outclass_rivals, outclass_specs
from .benchmark import diagnose_written, paired_results
from .rows import OutclassRow

ADEQUATE_LIMIT_STEPS = 3.0  # a hidden effect this large (converter steps RMS) must not be called adequate


def case_names(design: OutclassDesign, params=None) -> list[str]:
    return [s.name for s in outclass_specs(params or load_parameters(), design)]


def run_case(parameters_path, design: OutclassDesign, name: str, folder, truth_path, diagnosis_path,
             on_diagnosis=None) -> dict:
    """Generate out-of-class data set `name`, write its files into `folder`, diagnose them from the files;
    `on_diagnosis` as :func:`~parksteer.experiments.benchmark.diagnose_written` takes it."""
    params = load_parameters(parameters_path)
    specs = {s.name: s for s in outclass_specs(params, design)}
    if name not in specs:
        raise UsageError(f"unknown out-of-class data set {name!r}")
    start = time.perf_counter()
    dataset = make_outclass_dataset(params, specs[name], design)
    records = [(case, surface, m) for m, (case, surface) in zip(dataset.measurements, specs[name].files)]
    return diagnose_written(params, records, folder, dataset.truth, truth_path, diagnosis_path, start,
                            on_diagnosis=on_diagnosis)


def bic_margin(result: dict) -> float | None:
    """The best candidate's BIC gain over the runner-up's (a candidate not refitted counts as gain 0)."""
    gains = sorted((c["delta_bic"] if c["delta_bic"] is not None else 0.0 for c in result["ranking"]), reverse=True)
    if not gains:
        return None
    return float(gains[0] - (gains[1] if len(gains) > 1 else 0.0))


def outcome(truth: dict, result: dict) -> OutclassRow:
    """How one diagnosis fares: what it said, how that relates to the rival's physics, and the two targets."""
    band = result["selection"]["thresholds"]["bic_indistinguishable"]
    named = result["effect"] if result["verdict"] == "missing" else None
    said = named or result["verdict"]
    closest, related = truth.get("closest"), set(truth.get("related") or ())
    if truth["kind"] == "null":
        relation = "correct" if said == "adequate" else ("false alarm" if named else "not adequate")
    elif named is None:
        relation = said  # adequate or unexplained
    elif named == closest:
        relation = "closest"
    elif named in related:
        relation = "related"
    else:
        relation = "unrelated"
    margin = bic_margin(result) if named else None
    steps = truth["steps"] or 0.0
    floor = result["noise_floor_Nm"]
    after = result["statistics"]["with_effect"]
    group = [s["effect"] for s in result["indistinguishable"]]
    confident_wrong = relation == "unrelated" and margin is not None and margin > band
    missed = truth["kind"] == "rival" and said == "adequate" and steps >= ADEQUATE_LIMIT_STEPS
    # The strongly evidenced candidate an unexplained verdict still reports as the nearest form the library has.
    top = result["ranking"][0] if result["ranking"] else None
    evidenced = top is not None and (top["delta_bic"] or 0.0) > result["selection"]["thresholds"]["bic_missing"]
    return OutclassRow(
        name=truth["name"],
        kind=truth["kind"],
        hidden=truth["hidden"] or "nothing",
        steps=truth.get("steps_requested") or 0.0,
        steps_actual=steps,
        closest=closest or "none",
        said=said,
        relation=relation,
        closest_in_group=bool(closest and (named == closest or (named and closest in group))),
        indistinguishable=" ".join(group),
        bic_margin=margin,
        best_delta_bic=max((c["delta_bic"] for c in result["ranking"] if c["delta_bic"] is not None),
                              default=None),
        explained_fraction=next((c.get("explained_fraction") for c in result["ranking"] if c["effect"] == named),
                                   None) if named else (top.get("explained_fraction") if evidenced else None),
        calibrated_over_floor=result["statistics"]["calibrated"]["weighted_rms_Nm"] / floor,
        after_over_floor=after["weighted_rms_Nm"] / floor if after else None,
        nearest=top["effect"] if evidenced else "none",
        nearest_after_over_floor=top["weighted_rms_after_Nm"] / floor if evidenced else None,
        confident_wrong=confident_wrong,
        adequate_at_3_steps=missed,
        target_met=not confident_wrong and not missed,
        wall_s=result["cost"].get("wall_s"),
    )


def aggregate(truth_paths, diagnosis_paths, design: OutclassDesign | None = None
              ) -> tuple[list[OutclassRow], dict]:
    """(one outcome per data set, the summary: confusion table, the target's misses, the closest-candidate table)."""
    rows = [outcome(truth, result)
            for truth, result in paired_results(truth_paths, diagnosis_paths, "out-of-class benchmark")]
    rivals = [r for r in rows if r.kind == "rival"]
    nulls = [r for r in rows if r.kind == "null"]
    confusion: dict[str, dict[str, int]] = {}
    for r in rows:
        confusion.setdefault(r.hidden, {})
        confusion[r.hidden][r.said] = confusion[r.hidden].get(r.said, 0) + 1
    count = {k: sum(r.relation == k for r in rivals) for k in ("closest", "related", "unrelated", "unexplained",
                                                                  "adequate")}
    summary = {
        "data_sets": len(rows),
        "rivals": len(rivals),
        "nulls": len(nulls),
        "relations": count,
        "confident_wrong": [r.name for r in rivals if r.confident_wrong],
        "adequate_at_3_steps": [r.name for r in rivals if r.adequate_at_3_steps],
        "target_met": all(r.target_met for r in rows),
        "null_adequate": sum(r.said == "adequate" for r in nulls),
        "cases": [{k: getattr(r, k) for k in ("name", "hidden", "steps_actual", "closest", "said", "relation", "bic_margin",
                                     "explained_fraction", "calibrated_over_floor", "after_over_floor", "nearest",
                                     "nearest_after_over_floor", "target_met")} for r in rows],
        "confusion": confusion,
        "closest_table": {k: {"closest": v["closest"] or "none", "related": list(v["related"]),
                              "reason": v["reason"]} for k, v in outclass_rivals().items()},
        "targets": {"adequate_limit_steps": ADEQUATE_LIMIT_STEPS, "bic_band": "the diagnosis's bic_indistinguishable"},
        "settings": None if design is None else {
            "rivals": list(design.rivals), "steps": list(design.steps), "nulls": design.nulls,
            "files": [list(f) for f in design.files], "rtol": design.rtol, "seed": design.seed,
            "logger": {k: getattr(design.logger, k) for k in design.logger.__dataclass_fields__},
        },
        "cost": {"diagnosis_wall_s_median": float(np.median([r.wall_s for r in rows if r.wall_s is not None]))
                 if rows else None},
    }
    return rows, summary
