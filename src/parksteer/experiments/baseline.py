"""The baseline benchmark: cars the model does not fit, their later records diagnosed absolutely and against the
car's healthy record.

Each car carries a quirk of its own in every record (:mod:`parksteer.synthetic.quirks`: a manual car's rack friction
that depends on position and direction, a second universal joint out of phase, a tyre moment of Dahl's shape, a
tie-rod compliance that stiffens; :mod:`parksteer.synthetic.quirk_eps`: a column EPS whose worm, saturation, corner
and sensor filter have forms of their own, eta_b drawn from its published band, its vehicle file giving only the
gear's data). One car has one set of base parameters (the benchmarks' perturbation of the file's, seeded by the
car) and one quirk strength (a manual car's sized on its healthy record to ``quirk_floors`` noise floors of torque
RMS). Its healthy record becomes the baseline; each later record, on its own hand and logger (rate, converter of 10
bits to 0.005 N m steps, rack logged or, for an assisted car, the handwheel angle only), is a null, hides a library
effect (sized in noise floors of its torque channel, RMS change of the logged torque) or an out-of-class change
(another quirk; the motor's cogging), and is diagnosed twice:

- absolutely: a manual car's with its parameter file, an assisted car's with the file ``parksteer assist identify``
  writes from the healthy record (the owner's best without a baseline);
- against the baseline (:func:`parksteer.diagnose.baseline.learn_baseline` on the healthy record, then
  ``diagnose(..., baseline=...)``), where the method is there; otherwise the side reads ``not run``.

Scored per car and side: hidden effects named (the effect, or in its reported group; the bar 3 of 4), nulls
``adequate`` (all), out-of-class changes never named with confidence (a BIC margin beyond the indistinguishable band),
and no confident wrong name on any record. The thresholds of "as the baseline" are the method's, from the spread of
the healthy data; nothing here is tuned on the model's own records.
"""

from __future__ import annotations

import json
import re
import tempfile
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..diagnose.problem import load_files
from ..diagnose.report import diagnosis_dict
from ..diagnose.select import diagnose
from ..errors import UsageError
from ..measure.io import write_measurement
from ..parameters import Parameters
from ..synthetic.datasets import SizeSearch, perturbed_base, rms_difference, strength_for_rms
from ..synthetic.quirks import QUIRKS, ManualLogger, manual_road, quirk_record, quirk_strength
from ..synthetic.variations import VARIATIONS, variation_by_name
from .benchmark import BASE_PERTURBATION, BENCHMARK_SETTINGS
from .outclass import bic_margin

MANUAL_HIDDEN = ("column_friction", "rack_stiction", "kingpin_friction", "rack_damping")
ASSISTED_HIDDEN = ("assist_motor_friction", "torsion_bar_offset", "boost_gain_error")
ASSISTED_OUT_OF_CLASS = ("cogging",)
# torque converters by bits: (full scale N m); 10 bits to steps of 0.005 N m
MANUAL_CONVERTERS = {10: 25.0, 12: 20.48, 14: 40.96}
ASSISTED_CONVERTERS = {10: 10.0, 11: 10.24, 12: 10.24}
MANUAL_TORQUE_NOISE_NM = 0.02
NAMED_BAR = 0.75  # hidden effects named: 3 of 4
NAMED_MIN_FLOORS = 2.0
MORE_HEALTHY_INDEX = 50  # the further healthy records' seeds follow the later records' (index 1 on)
SEARCH = SizeSearch(iterations=4, tolerance=0.05, max_lag_s=0.0)
SEARCH_DT_S = 0.01
SIDES = ("absolute", "baseline")
# The baseline is learnt as a user would learn it: with the residual's signature, which gives the car's own form
# where the healthy record is unexplained (the benchmarks' diagnoses leave it out: it changes no verdict).
LEARN_SETTINGS = replace(BENCHMARK_SETTINGS, residual_signature=True)


@dataclass(frozen=True)
class Later:
    """A later record: `what` is ``null``, a hidden library effect or an out-of-class change; its hand (a variation
    of :data:`~parksteer.synthetic.variations.VARIATIONS`), torque converter bits, size in noise floors."""

    what: str
    hand: str
    bits: int
    floors: float = 0.0

    @property
    def kind(self) -> str:
        if self.what == "null":
            return "null"
        return "hidden" if self.what in MANUAL_HIDDEN + ASSISTED_HIDDEN else "outclass"

    @property
    def name(self) -> str:
        size = f"_{self.floors:g}" if self.kind != "null" else ""
        return f"{self.what}{size}__{self.hand}__t{self.bits}"


@dataclass(frozen=True)
class Car:
    """A car: ``manual`` with a quirk of :data:`~parksteer.synthetic.quirks.QUIRKS` at `quirk_floors`, or ``assisted``
    with a map of form `quirk` (``exp`` or ``power``); its healthy record's hand and bits, its later records, its
    tier (assisted: rack logged or angle only) and seed."""

    name: str
    kind: str
    quirk: str
    healthy_hand: str
    healthy_bits: int
    later: tuple[Later, ...]
    quirk_floors: float = 5.0
    tier: str = "rack"
    case: str = "unladen"
    seed: int = 0
    more_healthy: tuple[tuple[str, int], ...] = ()  # further healthy records (hand, bits) the baseline learns from


@dataclass(frozen=True)
class BaselineDesign:
    cars: tuple[Car, ...] = field(default_factory=tuple)


def _seed(car: Car, hand: str, index: int) -> int:
    names = [v.name for v in VARIATIONS]
    return car.seed + 100 * index + names.index(hand)


def _check(car: Car) -> None:
    known_hidden = MANUAL_HIDDEN if car.kind == "manual" else ASSISTED_HIDDEN
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


# --- a manual car --------------------------------------------------------------------------------------------


def _manual_logger(hand: str, bits: int, seed: int) -> ManualLogger:
    base = variation_by_name(hand).logger
    return ManualLogger(sample_rate_hz=base.sample_rate_hz, rack_bits=base.rack_bits, rack_noise_m=base.rack_noise_m,
                        torque_bits=bits, torque_full_scale_Nm=MANUAL_CONVERTERS[bits],
                        torque_noise_Nm=MANUAL_TORQUE_NOISE_NM, seed=seed)


class ManualCar:
    """A manual car's records: the car's base and quirk strength fixed on its healthy record."""

    def __init__(self, params: Parameters, car: Car):
        self.params, self.car = params, car
        self.base = perturbed_base(params, car.seed, BASE_PERTURBATION)
        self.quirk = QUIRKS[car.quirk]
        hand, logger = self._hand_logger(car.healthy_hand, car.healthy_bits, 0)
        road = manual_road(params, hand, car.case, self.base)
        self.strength, change = quirk_strength(params, road, self.quirk, car.quirk_floors * logger.floor_Nm, car.case)
        self.healthy = quirk_record(road, self.quirk, self.strength, logger, car.case)
        self.quirk_floors = change / logger.floor_Nm
        self.more_healthy = [self.later(Later("null", hand_name, bits), MORE_HEALTHY_INDEX + i)[1]
                             for i, (hand_name, bits) in enumerate(car.more_healthy)]

    def _hand_logger(self, hand_name: str, bits: int, index: int):
        seed = _seed(self.car, hand_name, index)
        hand, _ = variation_by_name(hand_name).settings(seed)
        return hand, _manual_logger(hand_name, bits, seed)

    def later(self, later: Later, index: int):
        """(truth, record) of a later record."""
        from ..model.symbolic.components import discover_effects, strength_parameter

        hand, logger = self._hand_logger(later.hand, later.bits, index)
        truth = {"kind": later.kind, "hidden": None if later.kind == "null" else later.what, "related": [],
                 "floors": 0.0, "strength": None}
        road = manual_road(self.params, hand, self.car.case, self.base)
        unchanged = road
        if later.kind == "hidden":
            quantity = strength_parameter(discover_effects()[later.what], self.params)
            effects = f"+{later.what}"

            def logged(s: float):
                if s == 0.0:
                    return self.quirk.logged(coarse, self.strength)[1]
                moved = manual_road(self.params, hand, self.car.case, {**self.base, quantity.key: s}, effects,
                                    dt_s=SEARCH_DT_S)
                return self.quirk.logged(moved, self.strength)[1]

            coarse = manual_road(self.params, hand, self.car.case, self.base, dt_s=SEARCH_DT_S)
            s = strength_for_rms(logged, later.floors * logger.floor_Nm, quantity.upper * 1e-3, quantity.upper, SEARCH)
            road = manual_road(self.params, hand, self.car.case, {**self.base, quantity.key: s}, effects)
            size = rms_difference(self.quirk.logged(road, self.strength)[1],
                                  self.quirk.logged(unchanged, self.strength)[1])
            truth.update(strength=s, floors=size / logger.floor_Nm)
        elif later.kind == "outclass":  # another quirk on top of the car's own
            other = QUIRKS[later.what]
            extra, change = quirk_strength(self.params, road, other, later.floors * logger.floor_Nm, self.car.case)
            truth.update(strength=extra, floors=change / logger.floor_Nm)
        record = quirk_record(road, self.quirk, self.strength, logger, self.car.case)
        if later.kind == "outclass":
            rack, torque = other.logged(road, extra)
            both = replace(road, rack_m=rack, torque_Nm=torque)
            record = quirk_record(both, self.quirk, self.strength, logger, self.car.case)
        truth["floor_Nm"] = logger.floor_Nm
        return truth, record

    def write(self, path: Path, record) -> None:
        write_measurement(path, record, self.params)

    def files(self, paths):
        return load_files(paths, self.params)


# --- an assisted car -----------------------------------------------------------------------------------------


def owner_gear_text(base_text: str, gear) -> str:
    """The owner's vehicle file: `base_text` (a column-assisted car's) with its ``[assist]`` the gear's data sheet
    only (reduction, eta_f, torque constant, current limit as motor torque, rotor inertia, torsion-bar stiffness);
    the map and everything else at the template's assumed values: the baseline identifies them."""
    from ..model.numeric.assist import assist_template

    sheet = "data sheet of the quirk car's gear (parksteer.synthetic.quirk_eps)"
    given = {"torsion_bar_stiffness": (gear.torsion_bar_stiffness, sheet), "reduction_ratio": (gear.reduction, sheet),
             "efficiency": (gear.efficiency, sheet), "torque_constant": (gear.torque_constant_Nm_per_A, sheet),
             "motor_torque_limit": (gear.torque_constant_Nm_per_A * gear.current_limit_A,
                                    sheet + ": current limit x k_t"),
             "motor_inertia": (gear.motor_inertia_kg_m2, sheet)}
    cut = re.search(r"^(# Power assistance.*\n)?\[assist\]", base_text, flags=re.M)
    if cut is None:
        raise UsageError("owner's file: the base vehicle file has no [assist] section")
    return base_text[:cut.start()] + assist_template("column", given)


class AssistedCar:
    """An assisted car's records (:mod:`parksteer.synthetic.quirk_eps`) and its owner's gear-only file."""

    MAPS = {"exp": {"form": "exp", "dead_band_Nm": 0.3, "scale": 0.9, "width_Nm": 1.1},
            "power": {"form": "power", "dead_band_Nm": 0.4, "scale": 3.9, "exponent": 1.8}}
    UPPER = {"assist_motor_friction": 0.3, "torsion_bar_offset": 1.0, "boost_gain_error": 1.0, "cogging": 0.5}

    def __init__(self, params: Parameters, car: Car, vehicle_path, folder: Path):
        from ..model.numeric.assist import effects_with_assist
        from ..model.symbolic.components import resolve_effects
        from ..synthetic.assisted_truth import TruthGear, TruthMap
        from ..synthetic.quirk_eps import EpsQuirk, drawn_back_efficiency
        from ..vehicle import vehicle_from_text

        self.params, self.car = params, car
        self.base = perturbed_base(params, car.seed, BASE_PERTURBATION)
        self.gear = replace(TruthGear(), back_efficiency=drawn_back_efficiency(car.seed))
        self.boost = TruthMap(**self.MAPS[car.quirk])
        self.eps = EpsQuirk()
        self.owner_path = folder / f"{car.name}_owner.toml"
        text = owner_gear_text(Path(vehicle_path).read_text(encoding="utf-8"), self.gear)
        self.owner_path.write_text(text, encoding="utf-8")
        self.owner = vehicle_from_text(text, self.owner_path)
        spec = effects_with_assist(None, self.owner)
        self.assist, self.effects = spec.lstrip("+"), resolve_effects(spec)
        self.healthy = self._record(car.healthy_hand, car.healthy_bits, 0, None, 0.0)[1]
        self.quirk_floors = None
        self.more_healthy = [self._record(hand_name, bits, MORE_HEALTHY_INDEX + i, None, 0.0)[1]
                             for i, (hand_name, bits) in enumerate(car.more_healthy)]

    def _logger(self, hand: str, bits: int, seed: int):
        from ..synthetic.assisted_truth import TruthLogger

        base = variation_by_name(hand).logger
        return TruthLogger(sample_rate_hz=base.sample_rate_hz, rack_bits=base.rack_bits if self.car.tier == "rack"
                           else 0, rack_noise_m=base.rack_noise_m, torque_bits=bits,
                           torque_full_scale_Nm=ASSISTED_CONVERTERS[bits], torque_noise_Nm=0.03,
                           current_noise_A=0.25, seed=seed)

    def _record(self, hand_name: str, bits: int, index: int, what: str | None, floors: float):
        from ..synthetic.assisted_truth import Hidden, manual_road as eps_road, truth_record, with_hidden
        from ..synthetic.quirk_eps import quirk_eps_clean
        from .assisted_truth import floor_Nm

        seed = _seed(self.car, hand_name, index)
        hand, _ = variation_by_name(hand_name).settings(seed)
        logger = self._logger(hand_name, bits, seed)
        road = eps_road(self.params, hand, self.car.case, self.base)
        hidden, strength, size = Hidden(), None, 0.0
        if what is not None:
            def reading(s: float):
                return quirk_eps_clean(road, self.boost, self.gear, self.eps, logger,
                                       with_hidden(Hidden(), what, s))["handwheel_torque_Nm"]

            strength = strength_for_rms(reading, floors * floor_Nm(logger), self.UPPER[what] * 1e-2,
                                        self.UPPER[what], SEARCH)
            hidden = with_hidden(Hidden(), what, strength)
            size = rms_difference(reading(strength), reading(0.0)) / floor_Nm(logger)
        clean = quirk_eps_clean(road, self.boost, self.gear, self.eps, logger, hidden, self.params)
        truth = {"strength": strength, "floors": size, "floor_Nm": floor_Nm(logger)}
        return truth, truth_record(clean, logger, self.car.case, source="synthetic: parksteer.synthetic.quirk_eps")

    def later(self, later: Later, index: int):
        truth, record = self._record(later.hand, later.bits, index, None if later.kind == "null" else later.what,
                                     later.floors)
        truth.update(kind=later.kind, hidden=None if later.kind == "null" else later.what, related=[])
        return truth, record

    def write(self, path: Path, record) -> None:
        from .assisted_truth import _write

        _write(path, record, self.owner)

    def files(self, paths, params=None):
        return load_files(paths, params or self.owner, assist=self.assist)


# --- diagnoses and scores ------------------------------------------------------------------------------------


def judged(truth: dict, result: dict) -> dict:
    """One diagnosis's answer and how it fares: named (a hidden effect, or in its group), adequate, confident (a
    name beyond the BIC band) and confident wrong (a confident name that is not the hidden effect)."""
    missing = result["verdict"] == "missing"
    named = result["effect"] if missing else None
    group = [s["effect"] for s in result.get("indistinguishable", [])]
    margin = bic_margin(result) if named else None
    band = result["selection"]["thresholds"]["bic_indistinguishable"]
    confident = bool(named and margin is not None and margin > band)
    right = truth["kind"] == "hidden" and named is not None and (named == truth["hidden"] or truth["hidden"] in group)
    return {"verdict": result["verdict"], "effect": named or "", "indistinguishable": " ".join(group),
            "named": bool(right), "confident": confident, "confident_wrong": confident and not right,
            "bic_margin": margin,
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
            from .assisted_truth import Owner, identified_route

            (folder / "owner.toml").write_text(maker.owner_path.read_text(encoding="utf-8"), encoding="utf-8")
            found = identified_route(Owner(maker.owner, maker.assist, maker.effects), healthy, folder)
            absolute_params, absolute_effects = found.params, found.effects

        def files(paths, p):
            return maker.files(paths) if car.kind == "manual" else maker.files(paths, p)

        def absolute(paths):
            return diagnosis_dict(diagnose(files(paths, absolute_params), absolute_params, absolute_effects,
                                           settings=BENCHMARK_SETTINGS))

        started = time.perf_counter()
        baseline, learnt = None, None
        if available:
            owner = params if car.kind == "manual" else maker.owner
            effects = None if car.kind == "manual" else maker.effects
            vehicle = None if car.kind == "manual" else maker.owner_path
            baseline = learn(files([healthy, *more], owner), owner, effects, LEARN_SETTINGS, vehicle=vehicle)
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
                result = diagnosis_dict(diagnose(files([path], owner), owner, effects, settings=BENCHMARK_SETTINGS,
                                                 baseline=baseline))
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
    out_named = _count(outclass, lambda r: r[side]["confident"])
    wrong = [r["name"] for r in rows if r[side]["confident_wrong"] and r["kind"] != "outclass"]
    bars = {"named": not hidden or named[0] >= NAMED_BAR * named[1],
            "nulls_adequate": adequate[0] == adequate[1],
            "out_of_class_not_confident": out_named[0] == 0,
            "no_confident_wrong": not wrong}
    return {"named": named, "nulls_adequate": adequate, "out_of_class_confident": out_named,
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


__all__ = ["ASSISTED_HIDDEN", "MANUAL_HIDDEN", "BaselineDesign", "Car", "Later", "car_by_name", "design_from_config",
           "judged", "owner_gear_text", "read_cars", "run_car", "score", "summarise", "write_car"]
