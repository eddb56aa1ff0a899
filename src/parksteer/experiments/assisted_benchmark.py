"""The assisted benchmark: diagnose records of an assisted car with a hand and a logger of their own.

The car is a vehicle file's with its assist (the Polo file's column assist by default), its base parameters moved
off the file's values as the in-class benchmark moves them. Each record's rack follows a hand of the variation
benchmark (:data:`parksteer.synthetic.variations.VARIATIONS`), its torsion-bar torque and motor current are the
assisted replay (:mod:`parksteer.synthetic.assisted`), and the variation's logger logs them with a 10-bit
torsion-bar torque on +-10 N m and a 12-bit current on +-100 A (noise TORQUE_NOISE_NM, CURRENT_NOISE_A). Cases:
nulls (``adequate`` right); hidden assist candidates sized in converter steps RMS of the torsion-bar torque (motor
friction, sensor offset, boost gain: named right; a rack friction off the file's: ``adequate`` right, its
calibrated interval's coverage reported); out-of-class changes
(:data:`parksteer.synthetic.assisted.OUT_OF_CLASS`), where naming an unrelated candidate beyond the
indistinguishable band is a confident wrong answer. Targets: NAMED_TARGET of hidden cases of at least
NAMED_MIN_STEPS steps named, NULL_ADEQUATE_TARGET of nulls adequate, no confident wrong answer. Results:
docs/assist_diagnosis.md.
"""

from __future__ import annotations

import functools
import json
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import UsageError
from ..measure.io import write_measurement
from ..model.symbolic.components import (Effect, discover_effects, resolve_effects, strength_parameter,
                                          with_effect_quantities)
from ..parameters import Parameters
from ..synthetic.assisted import OUT_OF_CLASS, AssistedLogger, assisted_clean, assisted_record
from ..synthetic.assisted_truth import HIDDEN_TRUTH
from ..synthetic.datasets import BASE_PERTURBATION, perturbed_base
from ..synthetic.size_search import SizeSearch, rms_difference, strength_for_rms
from ..measure.converter import quantisation_step
from ..synthetic.variations import variation_by_name
from .benchmark import BENCHMARK_SETTINGS
from .outclass import bic_margin
from ..diagnose.intake import Request, intake
from ..reporting.report import diagnosis_dict
from .rows import ROW_SUFFIX, read_case_files
from .variations import NAMED_MIN_STEPS, NAMED_TARGET, NULL_ADEQUATE_TARGET
from ..names import TORQUE

RACK_FRICTION = "steering.rack_friction_force"
# The rack friction is hidden as a force added to the base's, up to this (N); the out-of-class changes up to these
# (parksteer.synthetic.assisted.OUT_OF_CLASS, each its unit). An assist candidate's largest size is its strength
# quantity's upper bound (hidden_candidates).
RACK_FRICTION_LARGEST_N = 2000.0
OUT_OF_CLASS_LARGEST = {"motor_ripple": 0.5, "dead_band_change": 5.0}
# The package's effect modules: each assist candidate among them is hidden by the assisted benchmarks.
SHIPPED_EFFECTS = "parksteer.model.symbolic.effects."
# The channels' noise, relative to their parking range as the variation benchmark's (0.1 N m on a 12 N m peak: 0.8 %):
# 0.03 N m on a torsion bar's 3.5 N m, 0.25 A on a current's 27 A. With channels twice as clean (0.02 N m, 0.1 A)
# the nulls are adequate too (20 of 20), since the replay ensemble smooths at every knot spacing the rack data
# allow (parksteer.diagnose.ensemble.ensemble_plan): draws about one spline alone miss the smoothing's bias at the
# lock reversals, where the rack turns by less than its resolution, and leave 6 of 20 unexplained or missing.
TORQUE_NOISE_NM = 0.03
CURRENT_NOISE_A = 0.25
SEARCH = SizeSearch(iterations=4, tolerance=0.05, max_lag_s=0.0)


def hidden_candidates(registry: dict[str, Effect] | None = None) -> dict[str, tuple[str, float]]:
    """What the assisted benchmarks hide, by name: (the quantity set, the largest size searched, in its unit).

    The names and their order are the independent truth's rows
    (:data:`parksteer.synthetic.assisted_truth.HIDDEN_TRUTH`: each candidate's one row there); each but the rack
    friction is an assist candidate of `registry` (the library by default) and is sized by its strength quantity up
    to that quantity's upper bound. A row that names no assist candidate, or an assist candidate the package ships
    without a row, is refused in one line (a user's effect module without a row is diagnosed, not benchmarked)."""
    registry = discover_effects() if registry is None else registry
    table = {}
    for name in HIDDEN_TRUTH:
        if name == "rack_friction":
            table[name] = (RACK_FRICTION, RACK_FRICTION_LARGEST_N)
            continue
        if name not in registry or not registry[name].assist_candidate:
            raise UsageError(f"assisted benchmark: HIDDEN_TRUTH row {name!r} is not an assist candidate of the "
                             "library")
        strength = strength_parameter(registry[name])
        table[name] = (strength.key, strength.upper)
    rowless = [name for name, effect in registry.items() if effect.assist_candidate and name not in table
               and type(effect).__module__.startswith(SHIPPED_EFFECTS)]
    if rowless:
        raise UsageError(f"assisted benchmark: the shipped assist candidate {rowless[0]!r} has no row in HIDDEN_TRUTH "
                         "(parksteer.synthetic.assisted_truth: how the independent truth shows it)")
    return table


def largest_size(name: str, hidden: dict[str, tuple[str, float]]) -> float:
    """The largest size the size search tries for `name`: a hidden candidate's (`hidden`, :func:`hidden_candidates`)
    or an out-of-class change's."""
    return hidden[name][1] if name in hidden else OUT_OF_CLASS_LARGEST[name]


@dataclass(frozen=True)
class AssistedDesign:
    """Which hands (variations), what is hidden at which sizes (converter steps RMS), how many nulls, the seed (the
    car is the `params` given to :func:`run`)."""

    case: str = "kerb"
    null_replicates: int = 2  # each null hand twice, with other seeds (20 nulls: a 95 % rate is one miss)
    null_variations: tuple[str, ...] = ("rest_after_stop", "mid_stroke_end", "pauses", "rate_8pc_50Hz",
                                        "rate_3pc_200Hz", "rack_8bit_torque_12bit", "uneven_strokes",
                                        "lock_overshoot", "rack_16bit_torque_10bit", "angle_channel")
    hidden_variations: tuple[str, ...] = ("rest_after_stop", "pauses", "uneven_strokes", "lock_overshoot")
    steps: tuple[float, ...] = (2.0, 4.0)
    out_of_class: tuple[tuple[str, float], ...] = (("motor_ripple", 3.0), ("motor_ripple", 6.0),
                                                    ("dead_band_change", 3.0), ("dead_band_change", 6.0),
                                                    ("torsion_bar_stiffness", 0.5))
    out_of_class_variations: tuple[str, ...] = ("rest_after_stop", "uneven_strokes")
    seed: int = 2025


@dataclass(frozen=True)
class AssistedCase:
    name: str
    kind: str  # null, hidden, outclass
    variation: str
    hidden: str | None
    steps: float | None  # converter steps RMS asked for (torsion_bar_stiffness: its relative change)
    seed: int


def cases(design: AssistedDesign) -> list[AssistedCase]:
    out = []
    for replicate in range(design.null_replicates):
        for i, v in enumerate(design.null_variations):
            out.append(AssistedCase(f"{v}__r{replicate}__null", "null", v, None, None,
                                    design.seed + 1000 * replicate + 10 * i))
    for i, v in enumerate(design.hidden_variations):
        for effect in hidden_candidates():
            for steps in design.steps:
                out.append(AssistedCase(f"{v}__{effect}_{steps:g}", "hidden", v, effect, steps,
                                        design.seed + 10 * design.null_variations.index(v)))
    for v in design.out_of_class_variations:
        for kind, size in design.out_of_class:
            out.append(AssistedCase(f"{v}__{kind}_{size:g}", "outclass", v, kind, size,
                                    design.seed + 10 * design.null_variations.index(v)))
    return out


def case_names(design: AssistedDesign = AssistedDesign()) -> list[str]:
    """The names of the cases of `design`, in the order run() runs them (and the outputs list them)."""
    return [case.name for case in cases(design)]


def _logger(variation, seed: int) -> AssistedLogger:
    """The variation's logger (its rate, rack converter and noise) with the assisted car's torque and current
    channels (TORQUE_NOISE_NM, CURRENT_NOISE_A), seeded as the variation's."""
    base = variation.logger
    return AssistedLogger(sample_rate_hz=base.sample_rate_hz, rack_bits=base.rack_bits, rack_noise_m=base.rack_noise_m,
                          torque_noise_Nm=TORQUE_NOISE_NM, current_noise_A=CURRENT_NOISE_A, seed=seed)


def case_truth_and_record(params: Parameters, design: AssistedDesign, case: AssistedCase, assist: str,
                          references: dict | None = None):
    """(truth, measurement) of `case`: its hidden strength found by the secant search on the clean torque.
    `references` keeps the clean torque of each (variation, seed) a hidden or out-of-class case is sized against,
    for the next case of the same variation in the same process (the same hand, base and assist: the same run)."""
    variation = variation_by_name(case.variation)
    hand, _ = variation.settings(case.seed)
    logger = _logger(variation, case.seed)
    step = quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
    base = perturbed_base(params, case.seed, BASE_PERTURBATION)
    spec, key, strength, out_of_class = assist, None, None, None

    def torque(effects: str, overrides: dict, change=None) -> np.ndarray:
        return assisted_clean(params, hand, effects, design.case, overrides=overrides, out_of_class=change,
                              dt_s=0.01)[TORQUE]

    references = {} if references is None else references

    def reference() -> np.ndarray:  # the nulls are not sized: no reference run
        if (case.variation, case.seed) not in references:
            references[case.variation, case.seed] = torque(assist, base)
        return references[case.variation, case.seed]

    hidden = hidden_candidates()
    if case.kind == "hidden":
        key = hidden[case.hidden][0]
        if case.hidden == "rack_friction":
            of = functools.cache(lambda s: torque(assist, {**base, key: base[key] + s}))
        else:
            spec = f"{assist},+{case.hidden}"
            of = functools.cache(lambda s: torque(spec, {**base, key: s}))
        largest = largest_size(case.hidden, hidden)
        strength = strength_for_rms(of, case.steps * step, largest * 1e-2, largest, SEARCH)
        size = rms_difference(of(strength), reference()) / step
    elif case.kind == "outclass":
        if case.hidden == "torsion_bar_stiffness":
            strength = case.steps
        else:
            of = lambda s: torque(assist, base, (case.hidden, s) if s > 0 else None)  # noqa: E731
            largest = largest_size(case.hidden, hidden)
            strength = strength_for_rms(of, case.steps * step, largest * 1e-2, largest, SEARCH)
        out_of_class = (case.hidden, strength)
        size = rms_difference(torque(assist, base, out_of_class), reference()) / step
    else:
        size = 0.0
    overrides = dict(base)
    if key is not None:
        overrides[key] = base[key] + strength if case.hidden == "rack_friction" else strength
    clean = assisted_clean(params, hand, spec, design.case, overrides=overrides, out_of_class=out_of_class)
    record = assisted_record(clean, logger, design.case)
    related = OUT_OF_CLASS[case.hidden][2] if case.kind == "outclass" else ()
    truth = {"name": case.name, "kind": case.kind, "variation": case.variation, "hidden": case.hidden,
             "steps_requested": case.steps, "steps": size, "strength_key": key, "strength": strength,
             "true_value": overrides.get(key) if key else None, "base_overrides": base, "related": list(related)}
    return truth, record


def judged(truth: dict, result: dict) -> dict:
    """A diagnosis's answer on an assisted record and how it fares: the verdict, the effect named and its group, the
    calibrated error over the floor; named (a hidden candidate, or adequate with the rack friction's interval
    holding the truth), and for an out-of-class change its relation, BIC margin, confident and confident wrong.
    Shared by the assisted benchmark and the one on an independent truth (their rows add what their records are)."""
    missing = result["verdict"] == "missing"
    named = result["effect"] if missing else None
    group = [s["effect"] for s in result["indistinguishable"]]
    row = {"hidden": truth["hidden"] or "nothing", "verdict": result["verdict"], "effect": named or "",
           "indistinguishable": " ".join(group),
           "calibrated_over_floor": result["statistics"]["calibrated"]["weighted_rms_Nm"] / result["noise_floor_Nm"],
           "wall_s": result["cost"].get("wall_s")}
    if truth["kind"] == "hidden":
        if truth["hidden"] == "rack_friction":  # in the model: found by the calibration (its interval reported)
            ci = result["calibrated"][RACK_FRICTION].get("ci95")
            row["named"] = result["verdict"] == "adequate"
            row["covered"] = ci is not None and ci[0] <= truth["true_value"] <= ci[1]
        else:
            row["named"] = missing and (named == truth["hidden"] or truth["hidden"] in group)
    elif truth["kind"] == "outclass":
        margin = bic_margin(result) if named else None
        band = result["selection"]["thresholds"]["bic_indistinguishable"]
        related = set(truth["related"])
        confident = bool(named and margin is not None and margin > band)
        row["relation"] = ("related" if named in related else "unrelated") if named else result["verdict"]
        row["bic_margin"] = margin
        row["confident"] = confident
        row["confident_wrong"] = confident and named not in related
    return row


def outcome(truth: dict, result: dict) -> dict:
    """How one diagnosis fares (module docstring): named, adequate (nulls), confident wrong (out of class)."""
    row = {"name": truth["name"], "kind": truth["kind"], "variation": truth["variation"]}
    judgement = judged(truth, result)
    row["hidden"] = judgement.pop("hidden")
    row.update({"steps": truth["steps"], "steps_requested": truth["steps_requested"], **judgement})
    return row


def summarise(rows: list[dict]) -> dict:
    hidden = [r for r in rows if r["kind"] == "hidden" and r["steps"] >= NAMED_MIN_STEPS * 0.95]
    nulls = [r for r in rows if r["kind"] == "null"]
    outclass = [r for r in rows if r["kind"] == "outclass"]
    named, adequate = sum(r["named"] for r in hidden), sum(r["verdict"] == "adequate" for r in nulls)
    wrong = [r["name"] for r in outclass if r["confident_wrong"]]
    by_hidden = {h: [sum(r["named"] for r in hidden if r["hidden"] == h), sum(r["hidden"] == h for r in hidden)]
                 for h in dict.fromkeys(r["hidden"] for r in hidden)}
    targets = {
        "named": {"value": named / len(hidden) if hidden else None, "count": [named, len(hidden)],
                  "target": NAMED_TARGET, "met": bool(hidden and named / len(hidden) >= NAMED_TARGET)},
        "null_adequate": {"value": adequate / len(nulls) if nulls else None, "count": [adequate, len(nulls)],
                          "target": NULL_ADEQUATE_TARGET,
                          "met": bool(nulls and adequate / len(nulls) >= NULL_ADEQUATE_TARGET)},
        "confident_wrong_out_of_class": {"value": len(wrong), "cases": wrong, "target": 0, "met": not wrong},
    }
    walls = [r["wall_s"] for r in rows if r["wall_s"] is not None]
    return {"records": len(rows), "targets": targets, "target_met": all(t["met"] for t in targets.values()),
            "named_by_hidden": by_hidden, "named_min_steps": NAMED_MIN_STEPS,
            "missed": [{k: r[k] for k in ("name", "steps", "verdict", "effect", "indistinguishable")}
                       for r in hidden if not r["named"]],
            "rack_friction_covered": [sum(r.get("covered", False) for r in rows if r["hidden"] == "rack_friction"),
                                      sum(r["hidden"] == "rack_friction" for r in rows)],
            "false_alarms": [r["name"] for r in nulls if r["verdict"] != "adequate"],
            "out_of_class": [{k: r[k] for k in ("name", "steps", "verdict", "effect", "relation", "bic_margin")}
                             for r in outclass],
            "null_over_floor": {"min": min(r["calibrated_over_floor"] for r in nulls),
                                "max": max(r["calibrated_over_floor"] for r in nulls)} if nulls else None,
            "diagnosis_wall_s_median": float(np.median(walls)) if walls else None}


def run(params: Parameters, design: AssistedDesign = AssistedDesign(), only=None, progress=None) -> tuple[list, dict]:
    """Make, write, read back and diagnose every case of `design` (or those named in `only`); (rows, summary)."""
    params = with_effect_quantities(params)  # the assist's own quantities, with their assumed defaults
    from ..model.numeric.assist import effects_with_assist

    assist = effects_with_assist(None, params)
    effects = resolve_effects(assist)
    settings = BENCHMARK_SETTINGS
    rows = []
    references: dict = {}
    with tempfile.TemporaryDirectory() as folder:
        for case in cases(design):
            if only and case.name not in only:
                continue
            start = time.perf_counter()
            truth, record = case_truth_and_record(params, design, case, assist, references)
            path = Path(folder) / f"{case.name}.csv"
            write_measurement(path, record, params)
            made = time.perf_counter()
            result = diagnosis_dict(intake(Request([path], params, effects, settings=settings)).diagnose())
            result["cost"]["wall_s"] = time.perf_counter() - made
            row = outcome(truth, result)
            row["generation_s"] = made - start
            row["strength"] = truth["strength"]
            rows.append(row)
            if progress is not None:
                progress(row)
    return rows, summarise(rows)




def run_batch(params: Parameters, names: list[str], folder: str | Path, design: AssistedDesign = AssistedDesign()
              ) -> None:
    """Run the cases `names` of `design` (one job of the pipeline's rule diag_assisted_batch) and write each one's
    outcome row to <folder>/<name>.row.json. Each case is made from its own seed and diagnosed from its own file,
    so it gives the same row whichever job runs it and with whichever others."""
    from ..tables import atomic_path

    known = set(case_names(design))
    unknown = [name for name in names if name not in known]
    if unknown:
        raise UsageError(f"assisted benchmark: no case {unknown[0]!r}")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rows, _ = run(params, design, only=set(names))
    for row in rows:  # floats as repr: read back, the same numbers
        with atomic_path(folder / f"{row['name']}{ROW_SUFFIX}") as scratch:
            scratch.write_text(json.dumps(row), encoding="utf-8")


def read_rows(folders, names: list[str]) -> list[dict]:
    """The rows run_batch wrote into `folders` of the cases `names`, in that order; a case with no row, or with
    rows in two folders, is refused in one line."""
    return read_case_files(folders, names, "assisted benchmark")


__all__ = ["AssistedDesign", "case_names", "cases", "hidden_candidates", "outcome", "read_rows", "run", "run_batch",
           "summarise"]
