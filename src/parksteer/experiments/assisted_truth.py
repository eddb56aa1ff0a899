"""The assisted benchmark on an independent truth: records the model's assist did not make, diagnosed with the files
an owner would have.

The records (:mod:`parksteer.synthetic.assisted_truth`) are a column EPS of its own over the manual replay of the
Polo file's car, its base parameters moved as the other benchmarks move them (``perturbed_base``), each case with a
hand, rate and rack of the variation benchmark (:data:`parksteer.synthetic.variations.VARIATIONS`), a torsion-bar
torque on one of the design's converters, a current in 0.05 A steps, and the rack logged or the handwheel angle only
(:func:`parksteer.measure.column.rack_from_angle`). The diagnosis is given the owner's file
(:func:`~.assisted_truth_owner.owner_vehicle_text`: the gear's data sheet and the map point by point, the rest at
the template's assumed defaults), or the file ``parksteer assist identify`` writes from a baseline null (the route
``identified`` of :data:`~.assisted_truth_owner.ROUTES`). Cases count as in :mod:`.assisted_benchmark`: nulls,
hidden effects of the truth sized in noise floors of the torsion-bar channel, and out-of-class forms (cogging, map
hysteresis, worm backlash, a friction growing with the motor's torque) that must never be named with confidence
unless related. The truth and the results: docs/assist_diagnosis.md, "An independent truth of an assisted car".
"""

from __future__ import annotations

import functools
import json
import math
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..diagnose.intake import Request, intake
from ..reporting.report import diagnosis_dict
from ..errors import UsageError
from ..measure.io import format_measurement, write_measurement
from ..parameters import Parameters, load_parameters
from ..synthetic.assisted_truth import (
    HIDDEN_TRUTH,
    OUT_OF_CLASS_TRUTH,
    Hidden,
    TruthLogger,
    manual_road,
    truth_record,
    with_hidden,
)
from ..synthetic.column_eps_layer import truth_clean
from ..synthetic.datasets import BASE_PERTURBATION, perturbed_base
from ..synthetic.size_search import rms_difference, strength_for_rms
from ..synthetic.variations import variation_by_name
from .benchmark import BENCHMARK_SETTINGS
from .assisted_benchmark import RACK_FRICTION, judged
from .assisted_truth_design import (
    NAMED_MIN_FLOORS,
    SEARCH,
    TIERS,
    largest_size,
    TruthCase,
    TruthDesign,
    case_names,
    case_seed,
    cases,
)
from .assisted_truth_owner import BASELINE_ROUTES, ROUTES, Owner, owner_file, template_default
from .rows import ROW_SUFFIX, read_case_files
from .variations import NAMED_TARGET, NULL_ADEQUATE_TARGET
from ..names import TORQUE


def _logger(design: TruthDesign, case: TruthCase) -> TruthLogger:
    base = variation_by_name(case.variation).logger
    bits, full_scale = case.converter
    return TruthLogger(sample_rate_hz=base.sample_rate_hz, rack_bits=base.rack_bits if case.tier == "rack" else 0,
                       rack_noise_m=base.rack_noise_m, torque_bits=bits, torque_full_scale_Nm=full_scale,
                       torque_noise_Nm=design.torque_noise_Nm, current_noise_A=design.current_noise_A, seed=case.seed)


def floor_Nm(logger: TruthLogger) -> float:
    """The torsion-bar channel's noise floor: its noise and its rounding (step / sqrt 12), root sum of squares."""
    return math.hypot(logger.torque_noise_Nm, logger.torque_step / math.sqrt(12.0))


def case_truth_and_record(params: Parameters, design: TruthDesign, case: TruthCase):
    """(truth, measurement) of `case` on the car of `params` (the base file's manual part)."""
    hand, _ = variation_by_name(case.variation).settings(case.seed)
    logger = _logger(design, case)
    base = perturbed_base(params, case.seed, BASE_PERTURBATION)
    road = manual_road(params, hand, design.case, base, rack_friction=case.hidden == "rack_friction")

    def reading(hidden: Hidden) -> np.ndarray:
        return truth_clean(road, design.boost, design.gear, logger, hidden)[TORQUE]

    hidden, strength, size = Hidden(), None, 0.0
    if case.kind != "null":
        reference = reading(Hidden())
        of = functools.cache(lambda s: reading(with_hidden(Hidden(), case.hidden, s)))
        target = case.floors * floor_Nm(logger)
        largest = largest_size(case.hidden)
        strength = strength_for_rms(of, target, largest * 1e-2, largest, SEARCH)
        hidden = with_hidden(Hidden(), case.hidden, strength)
        size = rms_difference(of(strength), reference) / floor_Nm(logger)
    clean = truth_clean(road, design.boost, design.gear, logger, hidden, params)
    record = truth_record(clean, logger, design.case)
    true_value = base[RACK_FRICTION] + strength if case.hidden == "rack_friction" else None
    related = OUT_OF_CLASS_TRUTH[case.hidden][2] if case.kind == "outclass" else ()
    truth = {"name": case.name, "tier": case.tier, "kind": case.kind, "variation": case.variation,
             "hidden": case.hidden, "floors_requested": case.floors, "floors": size, "strength": strength,
             "true_value": true_value, "torque_step_Nm": logger.torque_step, "floor_Nm": floor_Nm(logger),
             "related": list(related)}
    return truth, record


def outcome(truth: dict, result: dict) -> dict:
    """How one diagnosis fares: named (hidden), adequate (nulls), confident and confident wrong (out of class)."""
    row = {k: truth[k] for k in ("name", "tier", "kind", "variation", "floors", "floors_requested", "strength",
                                 "torque_step_Nm")}
    row.update(judged(truth, result))
    return row


def _rate(rows, key, test, target):
    hit = sum(bool(test(r)) for r in rows)
    return {"value": hit / len(rows) if rows else None, "count": [hit, len(rows)], "target": target,
            "met": bool(rows and hit / len(rows) >= target)}


def summarise_tier(rows: list[dict]) -> dict:
    hidden = [r for r in rows if r["kind"] == "hidden" and r["floors"] >= NAMED_MIN_FLOORS * 0.95]
    nulls = [r for r in rows if r["kind"] == "null"]
    outclass = [r for r in rows if r["kind"] == "outclass"]
    wrong = [r["name"] for r in outclass if r["confident_wrong"]]
    targets = {"named": _rate(hidden, "named", lambda r: r["named"], NAMED_TARGET),
               "null_adequate": _rate(nulls, "verdict", lambda r: r["verdict"] == "adequate", NULL_ADEQUATE_TARGET),
               "confident_wrong_out_of_class": {"value": len(wrong), "cases": wrong, "target": 0, "met": not wrong}}
    return {"records": len(rows), "targets": targets, "target_met": all(t["met"] for t in targets.values()),
            "named_by_hidden": {h: [sum(r["named"] for r in hidden if r["hidden"] == h),
                                    sum(r["hidden"] == h for r in hidden)]
                                for h in dict.fromkeys(r["hidden"] for r in hidden)},
            "missed": [{k: r[k] for k in ("name", "floors", "verdict", "effect", "indistinguishable")}
                       for r in hidden if not r["named"]],
            "false_alarms": [{k: r[k] for k in ("name", "verdict", "effect", "calibrated_over_floor")}
                             for r in nulls if r["verdict"] != "adequate"],
            "out_of_class": [{k: r[k] for k in ("name", "floors", "verdict", "effect", "relation", "bic_margin",
                                                 "confident")} for r in outclass],
            "out_of_class_not_named": [sum(not r["effect"] for r in outclass), len(outclass)],
            "rack_friction_covered": [sum(r.get("covered", False) for r in rows if r["hidden"] == "rack_friction"),
                                      sum(r["hidden"] == "rack_friction" for r in rows)],
            "null_over_floor": {"min": min(r["calibrated_over_floor"] for r in nulls),
                                "max": max(r["calibrated_over_floor"] for r in nulls)} if nulls else None}


def summarise(rows: list[dict], design: TruthDesign = TruthDesign()) -> dict:
    """The targets per route and tier (a row's ``route``), and the truth's description."""
    out = {"records": len(rows), "named_min_floors": NAMED_MIN_FLOORS, "truth": describe(design), "routes": {}}
    for route in dict.fromkeys(r["route"] for r in rows):
        out["routes"][route] = {tier: summarise_tier([r for r in rows if r["route"] == route and r["tier"] == tier])
                                for tier in design.tiers if any(r["tier"] == tier for r in rows)}
    out["target_met"] = all(t["target_met"] for tiers in out["routes"].values() for t in tiers.values())
    walls = [r["wall_s"] for r in rows if r["wall_s"] is not None]
    out["diagnosis_wall_s_median"] = float(np.median(walls)) if walls else None
    return out


def describe(design: TruthDesign) -> dict:
    b, g = design.boost, design.gear
    return {"map": {"form": b.form, "dead_band_Nm": b.dead_band_Nm, "scale": b.scale, "exponent": b.exponent,
                    "width_Nm": b.width_Nm, "points_Nm": list(design.map_points_Nm)},
            "gear": {k: getattr(g, k) for k in g.__dataclass_fields__},
            "torque_steps_Nm": [TruthLogger(torque_bits=b_, torque_full_scale_Nm=f).torque_step
                                for b_, f in design.torque_converters],
            "torque_noise_Nm": design.torque_noise_Nm, "current_noise_A": design.current_noise_A,
            "owner_file": {"motor_friction_Nm": template_default("motor_friction_torque"),
                           "friction_speed_rad_s": template_default("friction_speed"),
                           "friction_smoothing_s_per_m": float(load_parameters()["steering.friction_smoothing"])}}


def baseline_record(params: Parameters, design: TruthDesign, tier: str):
    """The tier's baseline record: a null of the truth's car on ``design.baseline_variation`` (the record an
    owner logs first, from which a route may identify the assist), its seed apart from every case's."""
    case = TruthCase(f"{tier}__baseline", tier, "null", design.baseline_variation, None, None,
                     design.torque_converters[-1], case_seed(design, design.baseline_variation) + 77)
    return case_truth_and_record(params, design, case)[1]


def run(params: Parameters, base_path: str | Path, design: TruthDesign = TruthDesign(), only=None,
        progress=None) -> tuple[list, dict]:
    """Make, write, read back and diagnose every case of `design` (or those named in `only`) for each route of
    the design; (rows, summary). `params` is the base vehicle file's (`base_path`), whose manual car the truth
    drives."""
    unknown = [r for r in design.routes if r not in ROUTES]
    if unknown:
        raise UsageError(f"assisted truth: no route {unknown[0]!r} (known: {', '.join(ROUTES)})")
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        owner = owner_file(base_path, design, folder)
        given: dict[tuple[str, str], Owner] = {}

        def file_for(route: str, tier: str) -> Owner:
            if (route, tier) not in given:
                baseline = None
                if route in BASELINE_ROUTES:
                    baseline = Path(folder) / f"baseline_{tier}.csv"
                    _write(baseline, baseline_record(params, design, tier), owner.params)
                given[route, tier] = ROUTES[route](owner, baseline, folder)
            return given[route, tier]

        for case in cases(design):
            if only and case.name not in only:
                continue
            start = time.perf_counter()
            truth, record = case_truth_and_record(params, design, case)
            path = Path(folder) / f"{case.name}.csv"
            _write(path, record, owner.params)
            made = time.perf_counter()
            for route in design.routes:
                file = file_for(route, case.tier)
                began = time.perf_counter()
                taken = intake(Request([path], file.params, file.effects, settings=BENCHMARK_SETTINGS))
                result = diagnosis_dict(taken.diagnose())
                result["cost"]["wall_s"] = time.perf_counter() - began
                row = outcome(truth, result)
                row["route"] = route
                row["generation_s"] = made - start
                rows.append(row)
                if progress is not None:
                    progress(row)
    return rows, summarise(rows, design)


def _write(path: Path, record, params: Parameters) -> None:
    """Write `record`: the native format with a rack; an angle-only record (a bus log's channels under their
    native names, no rack) as its text, which the import layer reads and derives the rack of."""
    if "rack_m" in record.columns:
        write_measurement(path, record, params)
    else:
        path.write_text(format_measurement(record), encoding="utf-8")


def run_batch(params: Parameters, base_path, names: list[str], folder, design: TruthDesign = TruthDesign()) -> None:
    """Run the cases `names` (one job of the rule diag_assisted_truth_batch); each case's rows (one a route) to
    <folder>/<name>.row.json. A case is made from its own seed: the same rows whichever job runs it."""
    from ..tables import atomic_path

    known = set(case_names(design))
    unknown = [n for n in names if n not in known]
    if unknown:
        raise UsageError(f"assisted truth: no case {unknown[0]!r}")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rows, _ = run(params, base_path, design, only=set(names))
    for name in names:
        mine = [r for r in rows if r["name"] == name]
        with atomic_path(folder / f"{name}{ROW_SUFFIX}") as scratch:
            scratch.write_text(json.dumps(mine), encoding="utf-8")


def read_rows(folders, names: list[str]) -> list[dict]:
    """The rows run_batch wrote of the cases `names`, in that order; a case with no rows, or rows in two folders,
    is refused in one line."""
    return [row for rows in read_case_files(folders, names, "assisted truth") for row in rows]


def design_from_config(section: dict | None) -> TruthDesign:
    """The design of config/config.yaml's ``assisted_truth`` section (its keys the design's fields; ``boost`` and
    ``gear`` as mappings of the map's and the gear's fields)."""
    section = dict(section or {})
    design = TruthDesign()
    boost = replace(design.boost, **section.pop("boost", {}))
    gear = replace(design.gear, **section.pop("gear", {}))
    tuples = {"map_points_Nm", "tiers", "null_variations", "hidden_variations", "hidden", "floors",
              "out_of_class_variations", "routes"}
    fields = {k: tuple(v) if k in tuples else v for k, v in section.items()}
    if "torque_converters" in fields:
        fields["torque_converters"] = tuple((int(b), float(f)) for b, f in fields["torque_converters"])
    if "out_of_class" in fields:
        fields["out_of_class"] = tuple((str(n), float(s)) for n, s in fields["out_of_class"])
    design = replace(design, boost=boost, gear=gear, **fields)
    checks = (("tiers", design.tiers, TIERS), ("hidden", design.hidden, tuple(HIDDEN_TRUTH)),
              ("out_of_class", [n for n, _ in design.out_of_class], tuple(OUT_OF_CLASS_TRUTH)),
              ("routes", design.routes, tuple(ROUTES)))
    for key, given, known in checks:
        bad = [g for g in given if g not in known]
        if bad:
            raise UsageError(f"config assisted_truth.{key}: {bad[0]!r} is not one of {', '.join(known)}")
    for v in (*design.null_variations, *design.hidden_variations, *design.out_of_class_variations):
        case_seed(design, v)
    return design


__all__ = ["baseline_record", "case_truth_and_record", "design_from_config", "outcome", "read_rows", "run",
           "run_batch", "summarise"]
