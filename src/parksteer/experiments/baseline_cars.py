"""The cars of the baseline benchmark (:mod:`.baseline`): their design (:class:`Car`, :class:`Later`) and their
records, a manual car's (:class:`ManualCar`: the quirk of :mod:`parksteer.synthetic.quirks` over the manual replay)
and an assisted car's (:class:`AssistedCar`: :mod:`parksteer.synthetic.quirk_eps`, with the owner's file of the
gear's data alone).

One car has one set of base parameters (the benchmarks' perturbation of the file's, seeded by the car) and one quirk
strength (a manual car's sized on its healthy record). A record's hand and noise are seeded by the car, its place
among the car's records and its hand's place in :data:`~parksteer.synthetic.variations.VARIATIONS`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import UsageError
from ..measure.io import write_measurement
from ..parameters import Parameters
from ..synthetic.datasets import perturbed_base
from ..synthetic.size_search import SizeSearch, rms_difference, strength_for_rms
from ..synthetic.quirks import QUIRKS, ManualLogger, manual_road, quirk_record, quirk_strength
from ..synthetic.variations import VARIATIONS, variation_by_name
from ..synthetic.datasets import BASE_PERTURBATION
from ..names import TORQUE

MANUAL_HIDDEN = ("column_friction", "rack_stiction", "kingpin_friction", "rack_damping")
# a change of a value the baseline calibrates (named right only as changed:<key>, diagnose.baseline_changed): the
# car's rack friction grown since its healthy record
MANUAL_CHANGED = ("changed:steering.rack_friction_force",)
CHANGED_MAX_FRACTION = 2.0  # the search's largest change of the value, as a fraction of the car's
ASSISTED_HIDDEN = ("assist_motor_friction", "torsion_bar_offset", "boost_gain_error")
ASSISTED_OUT_OF_CLASS = ("cogging",)
# torque converters by bits: (full scale N m); 10 bits to steps of 0.005 N m
MANUAL_CONVERTERS = {10: 25.0, 12: 20.48, 14: 40.96}
ASSISTED_CONVERTERS = {10: 10.0, 11: 10.24, 12: 10.24}
MANUAL_TORQUE_NOISE_NM = 0.02
MORE_HEALTHY_INDEX = 50  # the further healthy records' seeds follow the later records' (index 1 on)
SEARCH = SizeSearch(iterations=4, tolerance=0.05, max_lag_s=0.0)
SEARCH_DT_S = 0.01



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
        return "hidden" if self.what in MANUAL_HIDDEN + MANUAL_CHANGED + ASSISTED_HIDDEN else "outclass"

    @property
    def name(self) -> str:
        size = f"_{self.floors:g}" if self.kind != "null" else ""
        return f"{self.what.replace(':', '_')}{size}__{self.hand}__t{self.bits}"


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


def _seed(car: Car, hand: str, index: int) -> int:
    names = [v.name for v in VARIATIONS]
    return car.seed + 100 * index + names.index(hand)


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
        self.strength, change = quirk_strength(params, road, self.quirk, car.quirk_floors * logger.floor_Nm, car.case,
                                               overrides=self.base)
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
        if later.what in MANUAL_CHANGED:  # the calibrated value itself moved: value x (1 + s)
            key = later.what.split(":", 1)[1]
            was = float(self.base.get(key, self.params[key]))

            def changed(s: float):
                if s == 0.0:
                    return self.quirk.logged(coarse, self.strength)[1]
                moved = manual_road(self.params, hand, self.car.case, {**self.base, key: was * (1.0 + s)},
                                    dt_s=SEARCH_DT_S)
                return self.quirk.logged(moved, self.strength)[1]

            coarse = manual_road(self.params, hand, self.car.case, self.base, dt_s=SEARCH_DT_S)
            s = strength_for_rms(changed, later.floors * logger.floor_Nm, 1e-3, CHANGED_MAX_FRACTION, SEARCH)
            road = manual_road(self.params, hand, self.car.case, {**self.base, key: was * (1.0 + s)})
            size = rms_difference(self.quirk.logged(road, self.strength)[1],
                                  self.quirk.logged(unchanged, self.strength)[1])
            truth.update(strength=was * (1.0 + s), was=was, floors=size / logger.floor_Nm)
        elif later.kind == "hidden":
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
            extra, change = quirk_strength(self.params, road, other, later.floors * logger.floor_Nm, self.car.case,
                                           overrides=self.base)
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
                                       with_hidden(Hidden(), what, s))[TORQUE]

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


__all__ = ["ASSISTED_HIDDEN", "MANUAL_CHANGED", "MANUAL_HIDDEN", "AssistedCar", "Car", "Later", "ManualCar", "owner_gear_text"]
