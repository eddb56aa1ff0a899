"""The baseline benchmark: cars the model does not fit, their later records diagnosed absolutely and against the
car's healthy record.

Each car carries a quirk of its own in every record (:mod:`parksteer.synthetic.quirks` for a manual car,
:mod:`parksteer.synthetic.quirk_eps` for a column EPS whose vehicle file gives only the gear's data), one set of base
parameters (the benchmarks' perturbation, seeded by the car) and one quirk strength (a manual car's sized on its
healthy record to ``quirk_floors`` noise floors of torque RMS). Its healthy record becomes the baseline; each later
record, on its own hand and logger, is a null, hides a library effect (sized in noise floors of its torque channel)
or an out-of-class change, and is diagnosed twice: absolutely (a manual car with its parameter file, an assisted car
with the file ``parksteer assist identify`` writes from the healthy record), and against the baseline
(:func:`parksteer.diagnose.baseline.learn_baseline`, then ``diagnose(..., baseline=...)``), the side reading
``not run`` where the method is not there. Scored per car and side: hidden effects named (the bar 3 of 4), nulls
``adequate`` (all), out-of-class changes and every record free of confident wrong names. Nothing is tuned on the
model's own records. The cars and results: docs/diagnosis.md, "Cars the model does not fit".
"""

from __future__ import annotations

import json
import tempfile
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..diagnose.baseline_changed import changed_key
from ..diagnose.intake import Request, intake
from ..errors import UsageError
from ..parameters import Parameters
from ..reporting.report import diagnosis_dict
from ..synthetic.quirks import QUIRKS
from ..synthetic.variations import variation_by_name
from .baseline_cars import (ASSISTED_CONVERTERS, ASSISTED_HIDDEN, ASSISTED_OUT_OF_CLASS, MANUAL_CHANGED,
                            MANUAL_CONVERTERS, MANUAL_HIDDEN, AssistedCar, Car, Later, ManualCar)
from .benchmark import BENCHMARK_SETTINGS
from .outclass import bic_margin

NAMED_BAR = 0.75  # hidden effects named: 3 of 4
NAMED_MIN_FLOORS = 2.0
SIDES = ("absolute", "baseline")
# The baseline is learnt as a user would learn it: with the residual's signature, which gives the car's own form
# where the healthy record is unexplained (the benchmarks' diagnoses leave it out: it changes no verdict).
LEARN_SETTINGS = replace(BENCHMARK_SETTINGS, residual_signature=True)


@dataclass(frozen=True)
class BaselineDesign:
    cars: tuple[Car, ...] = field(default_factory=tuple)


def _check(car: Car) -> None:
    known_hidden = MANUAL_HIDDEN + MANUAL_CHANGED if car.kind == "manual" else ASSISTED_HIDDEN
    known_out = tuple(QUIRKS) if car.kind == "manual" else ASSISTED_OUT_OF_CLASS
    converters = MANUAL_CONVERTERS if car.kind == "manual" else ASSISTED_CONVERTERS
    where = f"config baseline.cars {car.name}"
    if car.kind not in ("manual", "assisted"):
        raise UsageError(f"{where}: kind {car.kind!r} is not manual or assisted")
    if car.kind == "manual" and car.quirk not in QUIRKS:
        raise UsageError(f"{where}: quirk {car.quirk!r} is not one of {', '.join(QUIRKS)}")
    if car.kind == "assisted" and car.quirk not in ("exp", "power"):
        raise UsageError(f"{where}: an assisted car's quirk is its map's form, exp or power, not {car.quirk!r}")
    for later in car.later:
        if later.what != "null" and later.what not in known_hidden + known_out:
            raise UsageError(f"{where}: later {later.what!r} is not null, one of {', '.join(known_hidden)} or "
                             f"{', '.join(known_out)}")
    records = [(car.healthy_hand, car.healthy_bits), *car.more_healthy, *((x.hand, x.bits) for x in car.later)]
    for hand, bits in records:
        variation_by_name(hand)
        if bits not in converters:
            raise UsageError(f"{where}: {bits} bits is not one of {', '.join(map(str, converters))}")


def design_from_config(section: dict | None) -> BaselineDesign:
    """The design of config/config.yaml's ``baseline`` section (``cars``: each a car's fields, ``later`` a list of
    :class:`Later`'s fields)."""
    cars = []
    for entry in (section or {}).get("cars", []):
        entry = dict(entry)
        later = tuple(Later(**dict(x)) for x in entry.pop("later", []))
        more = tuple((str(x["hand"]), int(x["bits"])) for x in entry.pop("more_healthy", []))
        car = Car(later=later, more_healthy=more, **entry)
        _check(car)
        cars.append(car)
    names = [c.name for c in cars]
    if len(set(names)) != len(names):
        raise UsageError("config baseline.cars: two cars share a name")
    return BaselineDesign(tuple(cars))


def car_by_name(design: BaselineDesign, name: str) -> Car:
    for car in design.cars:
        if car.name == name:
            return car
    raise UsageError(f"baseline benchmark: no car {name!r}")


# --- diagnoses and scores ------------------------------------------------------------------------------------


def judged(truth: dict, result: dict) -> dict:
    """One diagnosis's answer and how it fares: named (a hidden effect, or in its group), adequate, confident (a
    name beyond the BIC band, `band` the one it was judged with) and confident wrong (a confident name that is not
    the hidden effect)."""
    missing = result["verdict"] == "missing"
    named = result["effect"] if missing else None
    group = [s["effect"] for s in result.get("indistinguishable", [])]
    margin = bic_margin(result) if named else None
    band = result["selection"]["thresholds"]["bic_indistinguishable"]
    confident = bool(named and margin is not None and margin > band)
    right = truth["kind"] == "hidden" and named is not None and (named == truth["hidden"] or truth["hidden"] in group)
    return {"verdict": result["verdict"], "effect": named or "", "indistinguishable": " ".join(group),
            "named": bool(right), "confident": confident, "confident_wrong": confident and not right,
            "changed_value": changed_key(named) is not None,
            "bic_margin": margin, "band": band,
            "over_floor": result["statistics"]["calibrated"]["weighted_rms_Nm"] / result["noise_floor_Nm"]}


def baseline_api():
    """(learn_baseline, True) where the baseline method is there, else (None, False)."""
    try:
        from ..diagnose.baseline import learn_baseline
    except ImportError:
        return None, False
    return learn_baseline, True


def run_car(params: Parameters, car: Car, vehicle_path=None, progress=None) -> dict:
    """Every record of `car` made, written, read back and diagnosed on both sides: {car, healthy, rows}."""
    learn, available = baseline_api()
    say = progress or (lambda line: None)
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        maker = ManualCar(params, car) if car.kind == "manual" else AssistedCar(params, car, vehicle_path, folder)
        healthy = folder / "healthy.csv"
        maker.write(healthy, maker.healthy)
        more = [folder / f"healthy_{i + 1}.csv" for i in range(len(maker.more_healthy))]
        for path, record in zip(more, maker.more_healthy):
            maker.write(path, record)
        if car.kind == "manual":
            absolute_params, absolute_effects = params, None
        else:
            from .assisted_truth_owner import Owner, identified_route

            (folder / "owner.toml").write_text(maker.owner_path.read_text(encoding="utf-8"), encoding="utf-8")
            found = identified_route(Owner(maker.owner, maker.assist, maker.effects), healthy, folder)
            absolute_params, absolute_effects = found.params, found.effects

        def taken(paths, p, effects, settings=BENCHMARK_SETTINGS, command="diagnose"):
            return intake(Request(paths, p, effects, settings=settings, command=command))

        def absolute(paths):
            return diagnosis_dict(taken(paths, absolute_params, absolute_effects).diagnose())

        started = time.perf_counter()
        baseline, learnt = None, None
        if available:
            owner = params if car.kind == "manual" else maker.owner
            effects = None if car.kind == "manual" else maker.effects
            vehicle = None if car.kind == "manual" else maker.owner_path
            records = taken([healthy, *more], owner, effects, LEARN_SETTINGS, "baseline")
            baseline = learn(records.files, records.params, records.effects, records.settings, vehicle=vehicle)
            learnt = time.perf_counter() - started
        healthy_result = absolute([healthy])
        out = {"car": car.name, "kind": car.kind, "quirk": car.quirk, "tier": car.tier,
               "quirk_floors": maker.quirk_floors, "baseline_method": "run" if available else "not run",
               "healthy": {"verdict": healthy_result["verdict"], "effect": healthy_result["effect"] or "",
                           "over_floor": healthy_result["statistics"]["calibrated"]["weighted_rms_Nm"]
                           / healthy_result["noise_floor_Nm"]},
               "learn_wall_s": learnt, "rows": []}
        if car.kind == "assisted":
            out["back_efficiency"] = maker.gear.back_efficiency
        if baseline is not None:
            named = baseline.relative_to
            named = named() if callable(named) else named
            out["learnt"] = {"verdict": named["verdict"], "form": named["form"],
                             "threshold_over_floor": named["threshold"]["over_floor"],
                             "threshold_lead_per_sample": named["threshold"]["lead_per_sample"],
                             "threshold_method": named["threshold"]["method"], "records": 1 + len(more)}
        for index, later in enumerate(car.later, start=1):
            truth, record = maker.later(later, index)
            path = folder / f"{later.name}.csv"
            maker.write(path, record)
            row = {"car": car.name, "name": later.name, "kind": later.kind, "hidden": later.what,
                   "hand": later.hand, "bits": later.bits, "tier": car.tier, "floors_requested": later.floors,
                   "floors": truth["floors"], "strength": truth["strength"], "floor_Nm": truth["floor_Nm"],
                   "absolute": judged(truth, absolute([path]))}
            if baseline is not None:
                owner = params if car.kind == "manual" else maker.owner
                effects = None if car.kind == "manual" else maker.effects
                result = diagnosis_dict(taken([path], owner, effects).diagnose(baseline=baseline))
                row["baseline"] = judged(truth, result)
            else:
                row["baseline"] = None
            out["rows"].append(row)
            say(f"{car.name} {later.name}: absolute {row['absolute']['verdict']}"
                + (f", baseline {row['baseline']['verdict']}" if row["baseline"] else ", baseline not run"))
    return out


def _count(rows, test) -> list[int]:
    return [sum(bool(test(r)) for r in rows), len(rows)]


def score(rows: list[dict], side: str) -> dict | None:
    """One side's score over `rows` (None where the side was not run): the counts and whether each bar holds."""
    if any(r[side] is None for r in rows):
        return None
    hidden = [r for r in rows if r["kind"] == "hidden" and r["floors"] >= NAMED_MIN_FLOORS * 0.95]
    nulls = [r for r in rows if r["kind"] == "null"]
    outclass = [r for r in rows if r["kind"] == "outclass"]
    named = _count(hidden, lambda r: r[side]["named"])
    adequate = _count(nulls, lambda r: r[side]["verdict"] == "adequate")
    # an out-of-class change read with confidence as a calibrated value that moved is its own column: a change
    # found (the owner learns that value moved), never a library effect named
    out_named = _count(outclass, lambda r: r[side]["confident"] and not r[side].get("changed_value"))
    out_changed = _count(outclass, lambda r: r[side]["confident"] and r[side].get("changed_value"))
    wrong = [r["name"] for r in rows if r[side]["confident_wrong"] and r["kind"] != "outclass"]
    bars = {"named": not hidden or named[0] >= NAMED_BAR * named[1],
            "nulls_adequate": adequate[0] == adequate[1],
            "out_of_class_not_confident": out_named[0] == 0,
            "no_confident_wrong": not wrong}
    return {"named": named, "nulls_adequate": adequate, "out_of_class_confident": out_named,
            "out_of_class_changed_value": out_changed,
            "confident_wrong": wrong, "bars": bars, "met": all(bars.values())}


def summarise(cars: list[dict]) -> dict:
    """Per car and side the score, and over all cars."""
    out = {"named_bar": NAMED_BAR, "named_min_floors": NAMED_MIN_FLOORS, "cars": {}}
    rows = [r for c in cars for r in c["rows"]]
    for c in cars:
        out["cars"][c["car"]] = {"kind": c["kind"], "quirk": c["quirk"], "tier": c["tier"],
                                 "quirk_floors": c["quirk_floors"], "healthy": c["healthy"],
                                 "back_efficiency": c.get("back_efficiency"),
                                 "baseline_method": c["baseline_method"], "learnt": c.get("learnt"),
                                 **{side: score(c["rows"], side) for side in SIDES}}
    out["all"] = {side: score(rows, side) for side in SIDES}
    out["baseline_method"] = "run" if all(c["baseline_method"] == "run" for c in cars) else "not run"
    return out


def write_car(result: dict, path) -> None:
    from ..tables import atomic_path

    with atomic_path(path) as scratch:
        scratch.write_text(json.dumps(result), encoding="utf-8")


def read_cars(paths) -> list[dict]:
    return [json.loads(Path(p).read_text(encoding="utf-8")) for p in paths]


__all__ = ["BaselineDesign", "Car", "Later", "car_by_name", "design_from_config", "judged", "read_cars", "run_car",
           "score", "summarise", "write_car"]
