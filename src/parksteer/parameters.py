"""The registry of quantities, and the parameter file (src/parksteer/data/parameters.toml, shipped as package data) that gives their values.

Every quantity has one key (``section.name``), one SI unit and one pair of physical bounds. The car's quantities
are listed here (:data:`SCHEMA`) and the file gives each its value and source as ``{value, unit, source}``; an
effect's own quantities (``<effect>.<name>``) are declared on the effect, with default and source, and join the
registry (:func:`registry`) when the effect is loaded (:func:`declare`); the run's vehicle speed
(``run.vehicle_speed``, :data:`VEHICLE_SPEED`), which several effects read, is declared here. Overrides (``--set``,
sweeps, diagnosis, the workflow's config) use the same keys, plus ``case.<name>`` for the active Table B1
case (:meth:`Parameters.with_overrides`). Any unknown key, missing key, wrong unit, non-physical value or
wheel loads that contradict the chassis statics are refused with a :class:`ParameterError` whose message is
one line naming the file and the key.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import tomllib
from dataclasses import dataclass, field
from collections.abc import Callable, Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

from .errors import UsageError, cannot_read
from .resources import data_file

DEFAULT_PATH = data_file("parameters.toml")

INF = math.inf


@dataclass(frozen=True)
class Quantity:
    """One quantity of the pipeline: its key, SI unit and physical bounds.

    ``key`` is ``section.name`` of the parameter file (``tyre.tyre_pressure``), ``case.<name>`` for a
    value of the active Table B1 case, or ``<effect>.<name>`` for a quantity only that effect has.
    ``default`` and ``source`` are given only by quantities declared in code (an effect's own, on the effect's
    class); every other quantity takes its value and source from the parameter file.

    ``free`` marks an effect's own strength as one a diagnosis fits, within the bounds, together with the calibrated
    parameters whenever the effect is in the model (``--effects=+FILE.py``), starting from its value (the default,
    or ``--set``); a quantity not free keeps the value it is given.
    """

    key: str
    unit: str
    lower: float = 0.0
    upper: float = INF
    lower_inclusive: bool = False  # most physical quantities here must be strictly positive
    upper_inclusive: bool = True
    is_list: bool = False
    description: str = ""
    why: str = ""  # the range of real cars behind the bounds, given with a refusal
    default: float | None = None
    source: str = ""
    free: bool = False

    @property
    def section(self) -> str:
        return self.key.partition(".")[0]

    @property
    def name(self) -> str:
        return self.key.partition(".")[2]

    def bounds_text(self) -> str:
        low = "[" if self.lower_inclusive else "("
        high = "]" if self.upper_inclusive else ")"
        return f"{low}{self.lower:g}, {self.upper:g}{high}"

    def within(self, value: float) -> bool:
        below = value < self.lower if self.lower_inclusive else value <= self.lower
        above = value > self.upper if self.upper_inclusive else value >= self.upper
        return not (below or above)

    def check(self, value: Any, where: str | None = None) -> float:
        """`value` as a float if it is a finite number within the bounds; else one-line ParameterError."""
        where = where or self.key
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(f"{where}: value {value!r} is not a number")
        value = float(value)
        if not math.isfinite(value):
            raise ParameterError(f"{where}: value {value} is not finite")
        if not self.within(value):
            why = f"; {self.why}" if self.why else ""
            raise ParameterError(
                f"{where}: value {value:g} {self.unit} is non-physical (allowed {self.bounds_text()}{why})"
            )
        return value


def _q(unit: str, lower: float = 0.0, upper: float = INF, **kw: Any) -> dict[str, Any]:
    return dict(unit=unit, lower=lower, upper=upper, **kw)


def _pos(unit: str, **kw: Any) -> dict[str, Any]:
    return _q(unit, **kw)


def _nonneg(unit: str, **kw: Any) -> dict[str, Any]:
    return _q(unit, lower_inclusive=True, **kw)


def _range(unit: str, lower: float, upper: float) -> dict[str, Any]:
    return _q(unit, lower, upper, lower_inclusive=True)


def _any(unit: str) -> dict[str, Any]:
    return _q(unit, -INF, INF, lower_inclusive=True)


# Unit and physical bounds of every key of the parameter file: the one home of both. The file must hold
# every key listed here, in the unit given here.
# Masses, inertias, stiffnesses and dampings have upper (and masses and inertias lower) bounds a road car cannot
# leave, each about ten times beyond the range of cars (the reason beside each): a value beyond is a wrong unit or
# a typo, and it is refused up front, naming file and key, instead of making the model too stiff to integrate
# (a tyre's radial stiffness of 1e15 N/m stops the integrator at 0.19 s) or meaningless.
ASSEMBLY_INERTIA = "a wheel, hub, brake and strut about its axes: 0.3-3 kg m^2"
_SCHEMA: dict[str, dict[str, dict[str, Any]]] = {
    "vehicle": {
        "gravity": _pos("m/s^2"),
        "unsprung_mass": _q("kg", 1.0, 2000.0,
            why="a front end's moving parts: 50-250 kg"),
        "chassis_roll_inertia": _q("kg m^2", 1.0, 1.0e5,
            why="a car body about its roll axis: 100-1000 kg m^2"),
        "chassis_roll_stiffness": _q("N m/rad", 0.0, 1.0e8,
            why="a road car's roll stiffness: 2e4-2e6 N m/rad"),
        "chassis_roll_damping": _q("N m s/rad", 0.0, 1.0e6, lower_inclusive=True,
            why="a car's roll damping: 1e3-1e5 N m s/rad"),
        "chassis_cg_z": _any("m"),
        "roll_axis_z": _any("m"),
    },
    "steering": {
        "rack_mass": _q("kg", 0.1, 100.0,
            why="a rack with its piston: 2-15 kg"),
        "rack_roll_inertia": _q("kg m^2", 0.0, 10.0, lower_inclusive=True,
            why="a rack about its axis: ~0.01 kg m^2"),
        "rack_friction_force": _range("N", 0.0, 1.0e5),
        "handwheel_to_rack_ratio": _pos("rad/m"),
        "roadwheel_to_rack_ratio": _pos("rad/m"),
        "column_torsional_stiffness": _q(
            "N m/rad", 0.0, 1.0e6, why="an EPS torsion bar is 100-3000 N m/rad, a plain column shaft 1e4-1e5"),
        "column_torsional_damping": _q("N m s/rad", 0.0, 1.0e5, lower_inclusive=True,
            why="Appendix B gives 200 N m s/rad"),
        "hooke_joint_angle": _range("rad", 0.0, 1.2),
        "hooke_joint_phase": _range("rad", -10.0, 10.0),
        "steering_assembly_cg_outboard": _any("m"),
        "steering_assembly_mass": _q("kg", 1.0, 500.0,
            why="wheel, hub, brake and strut: 20-80 kg"),
        "steering_assembly_inertia_x": _q("kg m^2", 1.0e-3, 100.0, why=ASSEMBLY_INERTIA),
        "steering_assembly_inertia_y": _q("kg m^2", 1.0e-3, 100.0, why=ASSEMBLY_INERTIA),
        "steering_assembly_inertia_z": _q("kg m^2", 1.0e-3, 100.0, why=ASSEMBLY_INERTIA),
        "rack_axis_z": _range("m", -2.0, 2.0),
        "friction_smoothing": _range("s/m", 1.0, 1.0e6),
    },
    "geometry": {
        "castor_angle": _range("rad", -0.5, 0.5),
        "kingpin_inclination": _range("rad", -0.5, 0.5),
        "mechanical_trail": _any("m"),
        "kingpin_top_y": _pos("m"),
        "kingpin_top_z": _any("m"),
        "wheel_centre_z": _any("m"),
        "ground_z": _any("m"),
    },
    "tyre": {
        # a car tyre's inflation pressure: 0.1 to 10 bar (gauge); below, the tyre is flat and equation (2) fails
        "tyre_pressure": _range("Pa", 1.0e4, 1.0e6),
        "friction_coefficient": _range("1", 0.0, 3.0),
        "reference_pressure": _range("Pa", 1.0e4, 1.0e6),
        "pressure_index": _range("1", 0.0, 3.0),
        "radial_stiffness": _q("N/m", 1.0e4, 1.0e7, why="a car tyre's vertical stiffness is 1.5e5-4e5 N/m, a "
                                                           "truck's about 1e6 N/m"),
        "radial_damping": _q("N s/m", 0.0, 1.0e6, lower_inclusive=True,
            why="Appendix B's 1e5 is already heavy"),
        "carcass_torsional_stiffness": _range("N m/rad", 1.0, 1.0e6),
        "carcass_torsional_damping": _range("N m s/rad", 0.0, 1.0e4),
        "tread_ring_mass": _q("kg", 0.01, 100.0,
            why="a tyre's tread and belts: 2-10 kg"),
        "tread_ring_yaw_inertia": _q("kg m^2", 1.0e-3, 100.0,
            why="the same about the steer axis: 0.1-1 kg m^2"),
    },
    "rig": {
        "friction_test_force": _pos("N"),
        "friction_test_load": _pos("N"),
        "rolling_radius": _pos("m"),
        "loads": _pos("N", is_list=True),
        "fig4_pressures": _pos("Pa", is_list=True),
        "fig3_pressure_range": _pos("Pa", is_list=True),
        "fig4_offset_range": _nonneg("m", is_list=True),
    },
    "input": {
        "handwheel_lock_angle": _pos("rad"),
        "time_to_right_lock": _pos("s"),
        "time_right_to_left_lock": _pos("s"),
        "time_left_lock_to_centre": _pos("s"),
        "reversal_rounding_time": _nonneg("s"),
    },
    "spacers": {
        "extra_offsets": _pos("m", is_list=True),
    },
    "synthetic": {
        "sample_rate": _pos("Hz"),
        "logger_bits": _range("1", 1.0, 24.0),
        "full_scale_handwheel_angle": _pos("rad"),
        "full_scale_rack": _pos("m"),
        "full_scale_torque": _pos("N m"),
        "full_scale_load": _pos("N"),
        "noise_handwheel_angle": _nonneg("rad"),
        "noise_rack": _nonneg("m"),
        "noise_torque": _nonneg("N m"),
        "noise_load": _nonneg("N"),
        "logger_seed": _nonneg("1"),
        "hand_speed_variation": _range("1", 0.0, 0.9),
        "hand_components": _range("1", 0.0, 20.0),
        "hand_frequency_range": _pos("Hz", is_list=True),
        "hand_knots_per_stroke": _pos("1", upper=8.0),
        "hand_seed": _nonneg("1"),
    },
}

_CASE_SCHEMA: dict[str, dict[str, Any]] = {
    "chassis_mass": _q("kg", 10.0, 2.0e4,
        why="the front axle's share of a body: 300-1500 kg for a car"),
    "chassis_cg_y": _any("m"),
    "wheel_centre_y": _pos("m"),
    "load_left": _pos("N"),
    "load_right": _pos("N"),
    "extra_offset": _nonneg("m"),
}

CASE = "case"  # the override section of the active case's values (``case.load_left``)

SCHEMA: dict[str, dict[str, Quantity]] = {
    section: {name: Quantity(f"{section}.{name}", **spec) for name, spec in entries.items()}
    for section, entries in _SCHEMA.items()
}
CASE_SCHEMA: dict[str, Quantity] = {name: Quantity(f"{CASE}.{name}", **spec) for name, spec in _CASE_SCHEMA.items()}

# Quantities declared in code by effects (key <effect>.<name>), joined when the effect is loaded.
_DECLARED: dict[str, Quantity] = {}
# Functions that load what declares quantities (the model's effect registry adds one when it is imported), each
# called once, the first time a key is not found: a key of an effect not loaded yet is found all the same.
_DECLARERS: list[Callable[[], object]] = []


def add_declarer(load: Callable[[], object]) -> None:
    """Register `load`, called once when a key is first not found, to declare quantities (load effects)."""
    _DECLARERS.append(load)


def _declared(key: str) -> Quantity | None:
    if key not in _DECLARED and _DECLARERS:
        while _DECLARERS:
            _DECLARERS.pop(0)()
    return _DECLARED.get(key)

# Keys of earlier versions, each now one quantity of the file: refused with a pointer to the key.
RENAMED: dict[str, str] = {
    "tyre_friction.friction_coefficient": "tyre.friction_coefficient",
    "tyre_friction.tyre_pressure": "tyre.tyre_pressure",
    "tyre_friction.reference_pressure": "tyre.reference_pressure",
    "tyre_friction.pressure_index": "tyre.pressure_index",
    "tyre_friction.smoothing": "steering.friction_smoothing",
    "rack_friction.friction_force": "steering.rack_friction_force",
    "rack_friction.smoothing": "steering.friction_smoothing",
    "carcass_compliance.torsional_stiffness": "tyre.carcass_torsional_stiffness",
    "carcass_compliance.torsional_damping": "tyre.carcass_torsional_damping",
    "hooke_joint.joint_angle": "steering.hooke_joint_angle",
    "hooke_joint.phase": "steering.hooke_joint_phase",
    "column_friction.smoothing": "steering.friction_smoothing",
    "kingpin_friction.smoothing": "steering.friction_smoothing",
    "rack_stiction.smoothing": "steering.friction_smoothing",
    "turn_slip.vehicle_speed": "run.vehicle_speed",
}


# The parameter file's keys and ``case.*`` (fixed at import, looked up for every value).
FILE_AND_CASE_KEYS: Mapping[str, Quantity] = MappingProxyType(
    {**{q.key: q for table in SCHEMA.values() for q in table.values()}, **{q.key: q for q in CASE_SCHEMA.values()}})


def registry() -> dict[str, Quantity]:
    """Every known key: the parameter file's, ``case.*``, and those declared by loaded effects."""
    return {**FILE_AND_CASE_KEYS, **_DECLARED}


def quantity(key: str) -> Quantity:
    """The quantity of `key`; an unknown or renamed key is a one-line UsageError."""
    found = FILE_AND_CASE_KEYS.get(key) or _declared(key)
    if found is None:
        raise UsageError(unknown_key_message(key))
    return found


def unknown_key_message(key: str) -> str:
    if key in RENAMED:
        return f"{key}: unknown key; this quantity is {RENAMED[key]}"
    return f"{key}: unknown key (a key of the parameter file, case.<name>, or an effect's own quantity)"


def _is_number(value: Any) -> bool:
    """A real number as code writes one (int, float, a NumPy scalar), not a boolean, a string or None."""
    return not isinstance(value, bool) and isinstance(value, numbers.Real)


def declaration_problem(q: Quantity) -> str | None:
    """What is wrong with the declaration of `q` (an effect's own quantity, written in code), or None: a unit
    given as text, both bounds numbers and not NaN, the lower below the upper, finite bounds for a quantity a
    diagnosis fits (``free``: the fit may take any value between them), a default and a source."""
    if not isinstance(q.unit, str) or not q.unit.strip():
        return f"unit {q.unit!r}: give its SI unit as text, e.g. 'N m'"
    for side, bound in (("lower", q.lower), ("upper", q.upper)):
        if not _is_number(bound):
            return (f"{side} bound {bound!r} is not a number: give both bounds, the range the physics allows "
                    "(Quantity(key, unit, lower, upper, ...))")
        if math.isnan(bound):
            return f"{side} bound is NaN: give the range the physics allows"
    if not q.lower < q.upper:
        return f"bounds out of order: the lower bound {q.lower:g} must be below the upper {q.upper:g}"
    if q.free and not (math.isfinite(q.lower) and math.isfinite(q.upper)):
        return (f"free within {q.bounds_text()} {q.unit}: a quantity the diagnosis fits needs finite bounds, the "
                "range its physics allows (a friction's from 0)")
    if q.default is None or not isinstance(q.source, str) or not q.source.strip():
        return "a quantity declared in code needs a default and a source"
    if not _is_number(q.default):
        return f"default {q.default!r} is not a number"
    return None


def declare(q: Quantity) -> Quantity:
    """Join a quantity declared in code (an effect's own, with default and source) to the registry; a declaration
    :func:`declaration_problem` finds wrong is a one-line UsageError naming the key."""
    if q.section in SCHEMA or q.section == CASE:
        raise UsageError(f"{q.key}: section {q.section} belongs to the parameter file; declare {q.section}.* there")
    problem = declaration_problem(q)
    if problem is not None:
        raise UsageError(f"{q.key}: {problem}")
    known = _DECLARED.get(q.key)
    # the same effect's file loaded again in one process (a suggested effect written again with its fitted values as
    # defaults) declares its quantities anew: the latest default, source and freedom win; another unit or bounds is a
    # clash
    if known is not None and (known.unit, known.lower, known.upper, known.lower_inclusive, known.upper_inclusive,
                              known.is_list) != (q.unit, q.lower, q.upper, q.lower_inclusive, q.upper_inclusive,
                                                 q.is_list):
        raise UsageError(f"{q.key}: declared twice with different unit or bounds ({known.unit} {known.bounds_text()}, "
                         f"then {q.unit} {q.bounds_text()}): another effect named {q.section!r} is loaded")
    if not (math.isfinite(q.default) and q.within(q.default)):
        raise UsageError(f"{q.key}: default {q.default:g} {q.unit} is outside its bounds {q.bounds_text()}")
    _DECLARED[q.key] = q
    return q

# The car's speed while it steers: one quantity of the run that every effect depending on it reads (the rolling
# tyre's turn slip, the electric assist's speed-dependent boost curve), set once per run (`parksteer simulate
# --speed-kmh`, the sizing study: parksteer.vehicle.creeping_overrides). It describes the run, not the car, so
# neither the parameter file nor a vehicle file gives it, and a run without such an effect has it neither in its
# parameter vector nor in its header; it is declared here, with its default 0 (standstill, the paper's test), in
# the lowest layer, which the model, the sweeps and the measurements (whose speed channel is vehicle_speed_mps)
# all reach.
VEHICLE_SPEED = declare(Quantity(
    "run.vehicle_speed", "m/s", 0.0, 3.0, lower_inclusive=True, default=0.0,
    description="the car's speed while it steers (constant over the run)",
    source="input of the run: 0 = standstill (the paper), up to 3 m/s (10.8 km/h) of creeping"))

ENTRY_KEYS = {"value", "unit", "source"}
# An entry may also declare how its value was obtained (``provenance``): "measured" (a data sheet, a published
# value, a measurement of this car), "identified" (fitted from this car's records: ``parksteer assist identify``)
# or "assumed" (a typical value, a numerical choice). Where it declares none, the value counts as assumed
# (Parameters.provenance); the diagnosis replays an assumed value of the assist at its band's ends
# (parksteer.diagnose.stages.assumed) and holds an identified one's products.
PROVENANCE = "provenance"
PROVENANCES = ("measured", "identified", "assumed")


def check_provenance(where: str, entry: dict) -> str | None:
    """An entry's declared provenance (None when it declares none); anything but :data:`PROVENANCES` is refused."""
    if PROVENANCE not in entry:
        return None
    value = entry[PROVENANCE]
    if value not in PROVENANCES:
        raise ParameterError(f"{where}: provenance {value!r}, expected one of {', '.join(PROVENANCES)}")
    return value


def provenance_key(dotted: str) -> str:
    """Where a quantity's declared provenance is kept beside its source (``Parameters.sources``)."""
    return f"{dotted}.{PROVENANCE}"

# Tolerances of the statics cross-check, from the printing precision of Table B1: wheel loads are printed to
# 1 N (so their sum is good to 1 N, two roundings of 0.5 N) and y_cm to 0.1 mm (so the chassis weight's moment
# is good to m g 0.05 mm, plus the 1 N of the load difference at the half track). The spacer cases print loads
# to 0.1 N; the same tolerance covers them. The shipped cases meet it with room: their sums are within 0.05 N
# of (chassis_mass + unsprung_mass) g and the loads put y_cm within 0.03 mm of the printed value.
LOAD_SUM_TOLERANCE_N = 1.0
CG_Y_PRINT_TOLERANCE_M = 0.5e-4
# A run's overrides (--set, a sweep point) may move the loads off the printed statics a little (a study of one
# load), but loads more than a tenth off the front-end weight are a typo or a wrong unit: the body would not be
# in vertical equilibrium and a wheel load can come out negative. Such an override is refused.
OVERRIDE_LOAD_FRACTION = 0.10


class ParameterError(UsageError):
    """A parameter file that does not satisfy the schema; the message is one line."""


@dataclass(frozen=True)
class Parameters:
    """Validated parameter values in SI units, with the source of each."""

    path: Path
    sections: dict[str, dict[str, Any]]
    cases: dict[str, dict[str, float]]
    sources: dict[str, str] = field(repr=False)

    def __getitem__(self, dotted: str) -> Any:
        """``params["tyre.friction_coefficient"]`` or ``params["cases.unladen.load_left"]``.

        A quantity declared in code by a loaded effect (no file entry) reads its default.
        """
        parts = dotted.split(".")
        if parts[0] == "cases" and len(parts) == 3:
            return self.case(parts[1])[parts[2]]
        if len(parts) == 2 and parts[0] in self.sections and parts[1] in self.sections[parts[0]]:
            return self.sections[parts[0]][parts[1]]
        declared = _declared(dotted)
        if declared is not None:
            return declared.default
        raise KeyError(dotted)

    def value(self, key: str, case: str) -> float:
        """The value of any registry key, ``case.<name>`` read from the case `case`."""
        section, _, name = key.partition(".")
        if section == CASE:
            return self.case(case)[name]
        return self[key]

    def case(self, name: str) -> dict[str, float]:
        if name not in self.cases:
            known = ", ".join(sorted(self.cases))
            raise ParameterError(f"{self.path}: unknown case {name!r} (known: {known})")
        return dict(self.cases[name])

    def source(self, dotted: str) -> str:
        if dotted not in self.sources and _declared(dotted) is not None:
            return _DECLARED[dotted].source
        return self.sources[dotted]

    def provenance(self, dotted: str) -> str:
        """How the value of `dotted` was obtained, as its file declares it (:data:`PROVENANCES`); "assumed" where
        the file declares none or gives no entry (a quantity at its effect's default)."""
        return self.sources.get(provenance_key(dotted), "assumed")

    @property
    def case_names(self) -> list[str]:
        """Case names in file order (unladen first)."""
        return list(self.cases)

    def with_overrides(self, overrides: dict[str, float] | None, case: str | None = None) -> Parameters:
        """These values with `overrides` ({key: value}) applied, each checked against its quantity's bounds.

        ``case.<name>`` changes the case `case` (every case when None). A list quantity cannot be overridden.
        """
        if not overrides:
            return self
        sections = {k: dict(v) for k, v in self.sections.items()}
        cases = {k: dict(v) for k, v in self.cases.items()}
        if case is not None:
            self.case(case)
        for key, value in overrides.items():
            q = quantity(key)
            if q.is_list:
                raise UsageError(f"{key}: a list; it cannot be overridden by one value")
            value = q.check(value, where=key)
            if q.section == CASE:
                for name in ([case] if case is not None else list(cases)):
                    cases[name][q.name] = value
            else:
                sections.setdefault(q.section, {})[q.name] = value
        statics_keys = {"vehicle.gravity", "vehicle.unsprung_mass"} | {f"{CASE}.{n}" for n in
                                                                        ("chassis_mass", "load_left", "load_right")}
        changed = [key for key in overrides if key in statics_keys]
        if changed:
            g = sections["vehicle"]["gravity"]
            for name in ([case] if case is not None else list(cases)):
                c = cases[name]
                weight_N = (c["chassis_mass"] + sections["vehicle"]["unsprung_mass"]) * g
                total_N = c["load_left"] + c["load_right"]
                if abs(total_N - weight_N) > OVERRIDE_LOAD_FRACTION * weight_N:
                    raise UsageError(
                        f"{', '.join(changed)}: case {name}'s wheel loads sum to {total_N:.0f} N, but (chassis_mass + "
                        f"vehicle.unsprung_mass) g is {weight_N:.0f} N; set the loads and the mass together"
                    )
        return dataclasses.replace(self, sections=sections, cases=cases)


def _check_value(path: Path, key: str, spec: Quantity, entry: Any) -> Any:
    where = f"{path}: {key}"
    if not isinstance(entry, dict):
        raise ParameterError(f"{where}: expected {{value, unit, source}}, got {type(entry).__name__}")
    missing = ENTRY_KEYS - entry.keys()
    if missing:
        raise ParameterError(f"{where}: missing {', '.join(sorted(missing))}")
    extra = entry.keys() - ENTRY_KEYS - {PROVENANCE}
    if extra:
        raise ParameterError(f"{where}: unknown field {', '.join(sorted(extra))}")
    if entry["unit"] != spec.unit:
        raise ParameterError(f"{where}: unit {entry['unit']!r} where {spec.unit!r} is required")
    if not isinstance(entry["source"], str) or not entry["source"].strip():
        raise ParameterError(f"{where}: source must be a non-empty string")
    check_provenance(where, entry)
    raw = entry["value"]
    if spec.is_list:
        if not isinstance(raw, list) or not raw:
            raise ParameterError(f"{where}: expected a non-empty list of numbers")
        return tuple(spec.check(v, where) for v in raw)
    return spec.check(raw, where)


def _check_table(path: Path, prefix: str, table: Any, schema: dict[str, Quantity], sources: dict[str, str]
                 ) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise ParameterError(f"{path}: {prefix}: expected a table")
    unknown = sorted(table.keys() - schema.keys())
    if unknown:
        key = f"{prefix}.{unknown[0]}"
        hint = f"; this quantity is {RENAMED[key]}" if key in RENAMED else ""
        raise ParameterError(f"{path}: {key}: unknown key{hint}")
    missing = [k for k in schema if k not in table]
    if missing:
        raise ParameterError(f"{path}: {prefix}.{missing[0]}: missing value")
    out = {}
    for key, spec in schema.items():
        out[key] = _check_value(path, f"{prefix}.{key}", spec, table[key])
        sources[f"{prefix}.{key}"] = table[key]["source"]
        if PROVENANCE in table[key]:
            sources[provenance_key(f"{prefix}.{key}")] = table[key][PROVENANCE]
    return out


def _check_statics(path: Path, sections: dict[str, dict[str, Any]], cases: dict[str, dict[str, float]]) -> None:
    """Each case's wheel loads carry the car's front-end weight and balance the chassis's lateral moment."""
    g = sections["vehicle"]["gravity"]
    unsprung_kg = sections["vehicle"]["unsprung_mass"]
    for name, c in cases.items():
        weight_N = (c["chassis_mass"] + unsprung_kg) * g
        total_N = c["load_left"] + c["load_right"]
        if abs(total_N - weight_N) > LOAD_SUM_TOLERANCE_N:
            raise ParameterError(
                f"{path}: cases.{name}.load_left: wheel loads sum to {total_N:.1f} N, but (chassis_mass + "
                f"vehicle.unsprung_mass) g is {weight_N:.1f} N (tolerance {LOAD_SUM_TOLERANCE_N:g} N)"
            )
        # Moments about the centreline: the unsprung parts are symmetric, the chassis weight acts at y_cm.
        moment_Nm = (c["load_right"] - c["load_left"]) * c["wheel_centre_y"]
        chassis_Nm = c["chassis_mass"] * g * c["chassis_cg_y"]
        tolerance_Nm = LOAD_SUM_TOLERANCE_N * c["wheel_centre_y"] + c["chassis_mass"] * g * CG_Y_PRINT_TOLERANCE_M
        if abs(moment_Nm - chassis_Nm) > tolerance_Nm:
            implied_mm = 1000.0 * moment_Nm / (c["chassis_mass"] * g)
            raise ParameterError(
                f"{path}: cases.{name}.chassis_cg_y: {1000.0 * c['chassis_cg_y']:.1f} mm, but the wheel loads put "
                f"the chassis mass centre at {implied_mm:.1f} mm"
            )


def load_parameters(path: str | Path = DEFAULT_PATH) -> Parameters:
    """Read and validate a parameter file; raise :class:`ParameterError` on any defect."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ParameterError(cannot_read(path, exc)) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    text = text.removeprefix("\ufeff")  # a byte-order mark, as some editors write
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None

    sources: dict[str, str] = {}
    known_top = set(SCHEMA) | {"cases"}
    unknown = sorted(doc.keys() - known_top)
    if unknown:
        raise ParameterError(f"{path}: {unknown[0]}: unknown key (an effect's own quantities are declared on the "
                             "effect, see `parksteer effects`; change one with --set <effect>.<name>=<value>)")
    sections = {}
    for name, schema in SCHEMA.items():
        if name not in doc:
            raise ParameterError(f"{path}: {name}: missing section")
        sections[name] = _check_table(path, name, doc[name], schema, sources)

    cases_doc = doc.get("cases")
    if not isinstance(cases_doc, dict) or not cases_doc:
        raise ParameterError(f"{path}: cases: missing section")
    cases = {name: _check_table(path, f"cases.{name}", table, CASE_SCHEMA, sources) for name, table in cases_doc.items()}
    _check_statics(path, sections, cases)
    return Parameters(path=path, sections=sections, cases=cases, sources=sources)


# The checks by name, for other files made of the same entries (a vehicle file, parksteer.vehicle).
check_entry = _check_value
check_table = _check_table
check_statics = _check_statics
