"""How the variation benchmark's diagnoses fare: each case's outcome against its truth (:func:`outcome`), and the
summary over the grid, each target with its value and the variations that miss it (:func:`summarise`)."""

from __future__ import annotations

from collections import Counter

import numpy as np

from ..diagnose.settings import DEFAULT_SETTINGS
from ..synthetic.variations import variation_by_name
from .benchmark import paired_results
from .rows import VariationRow
from .variations import COVERAGE_TARGET, NAMED_MIN_STEPS, NAMED_TARGET, NULL_ADEQUATE_TARGET, VariationDesign

TARGETS = {"named": NAMED_TARGET, "null_adequate": NULL_ADEQUATE_TARGET, "coverage": COVERAGE_TARGET}


def _reported_intervals(result: dict) -> dict[str, dict]:
    """The 95 % intervals of the model the diagnosis reports: with the named effect when it says missing."""
    if result["verdict"] == "missing":
        entry = next((c for c in result["ranking"] if c["effect"] == result["effect"]), None)
        if entry is not None:
            return entry["parameters"]
    return result["calibrated"]


def outcome(truth: dict, result: dict) -> VariationRow:
    """How one diagnosis fares: what it said, whether the hidden effect was named, the reported intervals'
    coverage of the truth, and the calibrated (and with-effect) weighted error in noise floors."""
    hidden = truth["hidden"]
    missing = result["verdict"] == "missing"
    named_effect = result["effect"] if missing else None
    group = [s["effect"] for s in result["indistinguishable"]]
    values = dict(truth["base_overrides"])
    if hidden is not None:
        values[truth["strength_key"]] = truth["strength"]
    if named_effect is not None and named_effect != hidden:
        entry = next((c for c in result["ranking"] if c["effect"] == named_effect), None)
        if entry is not None:
            values[entry["strength_parameter"]] = 0.0  # a named effect that was not hidden is truly absent
    covered = {k: bool(v["ci95"][0] <= values[k] <= v["ci95"][1])
               for k, v in _reported_intervals(result).items() if k in values and v.get("ci95") is not None}
    floor = result["noise_floor_Nm"]
    after = result["statistics"]["with_effect"]
    # the diagnosis's own warning that the hidden effect's signature is mostly a calibrated parameter's direction
    flag = next((c for c in result.get("confounded", []) if c["effect"] == hidden), None)
    confounded = flag["confounded_with"] if flag else None
    separating = (flag or {}).get("separating_measurement")  # where present (the confound tests on)
    return VariationRow(
        name=truth["name"],
        variation=truth["variation"],
        replicate=truth["replicate"],
        hidden=hidden or "nothing",
        steps=truth["steps_requested"] or 0.0,
        steps_actual=truth["steps"] or 0.0,
        steps_observable=truth.get("steps_observable") or 0.0,
        verdict=result["verdict"],
        effect=named_effect or "",
        indistinguishable=" ".join(group),
        named=bool(hidden is not None and missing and (named_effect == hidden or hidden in group)),
        false_alarm=bool(hidden is None and missing),
        hidden_confounded_with=confounded or "",
        hidden_separated_by=f"{separating['case']}/{separating['surface']}" if separating else "",
        torque_lag_s=variation_by_name(truth["variation"]).logger.torque_lag_s,
        # the lag the diagnosis found (the mean over the files: one logger)
        torque_lag_found_s=float(np.mean([f.get("torque_lag_s", 0.0) for f in result.get("files", [])] or [0.0])),
        calibrated_over_floor=result["statistics"]["calibrated"]["weighted_rms_Nm"] / floor,
        after_over_floor=after["weighted_rms_Nm"] / floor if after else None,
        covered=sum(covered.values()),
        intervals=len(covered),
        not_covered=" ".join(sorted(k for k, ok in covered.items() if not ok)),
        wall_s=result["cost"].get("wall_s"),
    )


def spread(values: list[float]) -> dict | None:
    """Median, least and largest of `values` (None if there are none)."""
    return {"median": float(np.median(values)), "min": min(values), "max": max(values)} if values else None


def _rate(k: int, n: int) -> float | None:
    return k / n if n else None


def summarise(rows: list[VariationRow], design: VariationDesign | None = None) -> dict:
    """Per variation and over the grid: named rate, nulls called adequate, interval coverage, the nulls' error in
    noise floors; each target with its value and whether it holds, and every variation whose own rate misses."""
    table, misses = [], []
    for name in dict.fromkeys(r.variation for r in rows):
        entry, missed = _variation_entry(name, [r for r in rows if r.variation == name])
        table.append(entry)
        misses.extend(missed)
    by_hidden = {effect: _hidden_entry([r for r in rows if r.hidden == effect and r.steps >= NAMED_MIN_STEPS])
                 for effect in dict.fromkeys(r.hidden for r in rows if r.hidden != "nothing")}
    total = _counts(rows)
    lagged = [r for r in rows if r.torque_lag_s > 0.0]
    targets = {key: {"value": _rate(k, n), "count": [k, n], "target": TARGETS[key],
                     "met": bool(n and k / n >= TARGETS[key])} for key, (k, n) in total.items()}
    null_floors = [r.calibrated_over_floor for r in rows if r.hidden == "nothing"]
    named_after = [r.after_over_floor for r in rows if r.named and r.after_over_floor is not None]
    walls = [r.wall_s for r in rows if r.wall_s is not None]
    return {
        "records": len(rows),
        "targets": targets,
        "target_met": all(t["met"] for t in targets.values()),
        "misses": misses,
        "named_min_steps": NAMED_MIN_STEPS,
        "by_hidden": by_hidden,
        "sources": _miss_sources(rows, lagged),
        "torque_lag_found_s": {"by_variation": _lags_found(lagged)},
        "variations": table,
        "null_over_floor": {"min": min(null_floors), "max": max(null_floors)} if null_floors else None,
        "named_after_over_floor": {"min": min(named_after), "max": max(named_after)} if named_after else None,
        "false_alarms": sum(r.false_alarm for r in rows),
        "thresholds": {"adequate_rms_factor": DEFAULT_SETTINGS.adequate_rms_factor,
                       "missing_rms_ceiling": DEFAULT_SETTINGS.missing_rms_ceiling},
        "settings": None if design is None else _design_settings(design),
        "cost": {"diagnosis_wall_s_median": float(np.median(walls)) if walls else None,
                 "diagnosis_wall_s_total": float(np.sum(walls)) if walls else None},
    }


def _counts(rs: list[VariationRow]) -> dict[str, tuple[int, int]]:
    """(successes, trials) of each target over the rows `rs`."""
    hidden = [r for r in rs if r.hidden != "nothing" and r.steps >= NAMED_MIN_STEPS]
    nulls = [r for r in rs if r.hidden == "nothing"]
    return {"named": (sum(r.named for r in hidden), len(hidden)),
            "null_adequate": (sum(r.verdict == "adequate" for r in nulls), len(nulls)),
            "coverage": (sum(r.covered for r in rs), sum(r.intervals for r in rs))}


def _variation_entry(name: str, rs: list[VariationRow]) -> tuple[dict, list[dict]]:
    """One variation's row of the summary, and the targets its own rates miss."""
    nulls = [r for r in rs if r.hidden == "nothing"]
    named = [r for r in rs if r.named]
    entry: dict = {"variation": name, "records": len(rs)}
    misses = []
    for key, (k, n) in _counts(rs).items():
        entry[key] = _rate(k, n)
        entry[f"{key}_count"] = [k, n]
        if n and k / n < TARGETS[key]:
            misses.append({"variation": name, "target": key, "value": k / n, "count": [k, n]})
    entry["false_alarms"] = sum(r.false_alarm for r in nulls)
    entry["missed"] = [{"hidden": r.hidden, "steps": r.steps, "said": r.verdict, "effect": r.effect,
                        "confounded_with": r.hidden_confounded_with}
                       for r in rs if r.hidden != "nothing" and not r.named]
    missed_keys = [k for r in rs for k in r.not_covered.split()]
    entry["not_covered"] = {k: missed_keys.count(k) for k in sorted(set(missed_keys))}
    entry["null_over_floor"] = [r.calibrated_over_floor for r in nulls]
    entry["named_after_over_floor"] = [r.after_over_floor for r in named if r.after_over_floor is not None]
    walls = [r.wall_s for r in rs if r.wall_s is not None]
    entry["wall_s_median"] = float(np.median(walls)) if walls else None
    return entry, misses


def _hidden_entry(counted: list[VariationRow]) -> dict:
    """How one hidden effect fares over the grid, from its records hidden at NAMED_MIN_STEPS or more."""
    missed = [r for r in counted if not r.named]
    flagged = [r for r in missed if r.hidden_confounded_with]
    kept = [r.steps_observable / r.steps_actual for r in counted
            if r.steps_observable and r.steps_actual > 0.0]
    return {
        "named_count": [len(counted) - len(missed), len(counted)],
        "named": _rate(len(counted) - len(missed), len(counted)),
        "missed_flagged_confounded": len(flagged),
        "confounded_with": sorted({r.hidden_confounded_with for r in flagged}),
        # where the diagnosis said the flagged misses would show (with the confound tests on)
        "flagged_separated_by": dict(sorted(Counter(r.hidden_separated_by for r in flagged
                                                    if r.hidden_separated_by).items())),
        "missed_in": list(dict.fromkeys(r.variation for r in missed)),
        "named_in_all_of": [v for v in dict.fromkeys(r.variation for r in counted)
                            if all(r.named for r in counted if r.variation == v)],
        # the share of the hidden change a calibration cannot absorb (hidden_strength)
        "observable_fraction": spread(kept),
    }


def _miss_sources(rows: list[VariationRow], lagged: list[VariationRow]) -> dict:
    """Where the misses come from: records whose torque channel lags the rack (a logger error the diagnosis
    estimates, select.estimate_torque_lags), records whose hidden effect went unnamed while the diagnosis
    reported it confounded with a calibrated parameter, and the rest."""
    flagged = [r for r in rows if r not in lagged and r.hidden != "nothing" and not r.named
               and r.hidden_confounded_with]
    rest = [r for r in rows if r not in lagged and r not in flagged]
    sources = {name: {"records": len(rs), "coverage_count": [sum(r.covered for r in rs),
                                                             sum(r.intervals for r in rs)]}
               for name, rs in (("lagged_channel", lagged), ("confounded_unnamed", flagged), ("rest", rest))}
    counted = [r for r in rows if r.hidden != "nothing" and r.steps >= NAMED_MIN_STEPS]
    unflagged = [r for r in counted if r.named or not r.hidden_confounded_with]
    sources["named_where_not_flagged_confounded"] = [sum(r.named for r in unflagged), len(unflagged)]
    return sources


def _lags_found(lagged: list[VariationRow]) -> dict:
    """The lags found behind each lagged logger, on its nulls and where an effect was hidden too (a lag is
    searched only where the logger is known to have one: run_case)."""
    return {name: {"true_s": variation_by_name(name).logger.torque_lag_s,
                   "nulls_s": spread([r.torque_lag_found_s for r in lagged
                                      if r.variation == name and r.hidden == "nothing"]),
                   "hidden_s": spread([r.torque_lag_found_s for r in lagged
                                       if r.variation == name and r.hidden != "nothing"])}
            for name in dict.fromkeys(r.variation for r in lagged)}


def _design_settings(design: VariationDesign) -> dict:
    """The grid the summary is of, as the summary records it."""
    return {
        "variations": list(design.variations), "replicates": design.replicates, "hidden": list(design.hidden),
        "with_angle": [v for v in design.variations if variation_by_name(v).uses_angle],
        "hidden_with_angle": list(design.hidden_with_angle if design.hidden_with_angle is not None
                                  else design.hidden),
        "steps": list(design.steps), "files": [list(f) for f in design.files], "seed": design.seed,
        "what": {v: variation_by_name(v).what for v in design.variations},
    }


def aggregate(truth_paths, diagnosis_paths, design: VariationDesign | None = None
              ) -> tuple[list[VariationRow], dict]:
    """(one outcome per case, the summary of :func:`summarise`) from the cases' truth and diagnosis files."""
    rows = [outcome(truth, result)
            for truth, result in paired_results(truth_paths, diagnosis_paths, "variation benchmark")]
    return rows, summarise(rows, design)
