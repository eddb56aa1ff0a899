"""Load and validate the parameter file (data/parameters.toml).

The file is human-readable TOML; every entry is ``{value, unit, source}``. The schema
below names each key, the SI unit it must be written in and its physical bounds. Any
unknown key, missing key, wrong unit or non-physical value is refused with a
:class:`ParameterError` whose message is one line naming the file and the key.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import UsageError
from .resources import data_file

DEFAULT_PATH = data_file("parameters.toml")

INF = math.inf


@dataclass(frozen=True)
class Spec:
    """What one parameter must look like: its unit, its bounds, scalar or list."""

    unit: str
    lower: float = 0.0
    upper: float = INF
    is_list: bool = False
    lower_inclusive: bool = False  # most physical quantities here must be strictly positive


def _pos(unit: str, **kw: Any) -> Spec:
    return Spec(unit, **kw)


def _nonneg(unit: str, **kw: Any) -> Spec:
    return Spec(unit, lower=0.0, lower_inclusive=True, **kw)


def _any(unit: str) -> Spec:
    return Spec(unit, lower=-INF, upper=INF, lower_inclusive=True)


SCHEMA: dict[str, dict[str, Spec]] = {
    "vehicle": {
        "gravity": _pos("m/s^2"),
        "unsprung_mass": _pos("kg"),
        "chassis_roll_inertia": _pos("kg m^2"),
        "chassis_roll_stiffness": _pos("N m/rad"),
        "chassis_roll_damping": _nonneg("N m s/rad"),
        "chassis_cg_z": _any("m"),
        "roll_axis_z": _any("m"),
    },
    "steering": {
        "rack_mass": _pos("kg"),
        "rack_roll_inertia": _nonneg("kg m^2"),
        "rack_friction_force": _nonneg("N"),
        "handwheel_to_rack_ratio": _pos("rad/m"),
        "roadwheel_to_rack_ratio": _pos("rad/m"),
        "column_torsional_stiffness": _pos("N m/rad"),
        "column_torsional_damping": _nonneg("N m s/rad"),
        "hooke_joint_angle": Spec("rad", lower=0.0, upper=1.2, lower_inclusive=True),
        "hooke_joint_phase": _any("rad"),
        "steering_assembly_cg_outboard": _any("m"),
        "steering_assembly_mass": _pos("kg"),
        "steering_assembly_inertia_x": _pos("kg m^2"),
        "steering_assembly_inertia_y": _pos("kg m^2"),
        "steering_assembly_inertia_z": _pos("kg m^2"),
        "rack_axis_z": _any("m"),
        "friction_smoothing": _pos("s/m"),
    },
    "geometry": {
        "castor_angle": Spec("rad", lower=-0.5, upper=0.5, lower_inclusive=True),
        "kingpin_inclination": Spec("rad", lower=-0.5, upper=0.5, lower_inclusive=True),
        "mechanical_trail": _any("m"),
        "kingpin_top_y": _pos("m"),
        "kingpin_top_z": _any("m"),
        "wheel_centre_z": _any("m"),
        "ground_z": _any("m"),
    },
    "tyre": {
        "tyre_pressure": _pos("Pa"),
        "friction_coefficient": _nonneg("1", upper=3.0),
        "reference_pressure": _pos("Pa"),
        "pressure_index": _nonneg("1", upper=3.0),
        "radial_stiffness": _pos("N/m"),
        "radial_damping": _nonneg("N s/m"),
        "carcass_torsional_stiffness": _pos("N m/rad"),
        "carcass_torsional_damping": _nonneg("N m s/rad"),
        "tread_ring_mass": _pos("kg"),
        "tread_ring_yaw_inertia": _pos("kg m^2"),
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
        "logger_bits": Spec("1", lower=1.0, upper=24.0, lower_inclusive=True),
        "full_scale_handwheel_angle": _pos("rad"),
        "full_scale_rack": _pos("m"),
        "full_scale_torque": _pos("N m"),
        "full_scale_load": _pos("N"),
        "noise_handwheel_angle": _nonneg("rad"),
        "noise_rack": _nonneg("m"),
        "noise_torque": _nonneg("N m"),
        "noise_load": _nonneg("N"),
        "logger_seed": _nonneg("1"),
        "hand_speed_variation": _nonneg("1", upper=0.9),
        "hand_components": _nonneg("1", upper=20.0),
        "hand_frequency_range": _pos("Hz", is_list=True),
        "hand_knots_per_stroke": _pos("1", upper=8.0),
        "hand_seed": _nonneg("1"),
    },
}

CASE_SCHEMA: dict[str, Spec] = {
    "chassis_mass": _pos("kg"),
    "chassis_cg_y": _any("m"),
    "wheel_centre_y": _pos("m"),
    "load_left": _pos("N"),
    "load_right": _pos("N"),
    "extra_offset": _nonneg("m"),
}

ENTRY_KEYS = {"value", "unit", "source"}


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
        """``params["tyre.friction_coefficient"]`` or ``params["cases.unladen.load_left"]``."""
        parts = dotted.split(".")
        if parts[0] == "cases" and len(parts) == 3:
            return self.case(parts[1])[parts[2]]
        if len(parts) != 2 or parts[0] not in self.sections or parts[1] not in self.sections[parts[0]]:
            raise KeyError(dotted)
        return self.sections[parts[0]][parts[1]]

    def case(self, name: str) -> dict[str, float]:
        if name not in self.cases:
            known = ", ".join(sorted(self.cases))
            raise ParameterError(f"{self.path}: unknown case {name!r} (known: {known})")
        return dict(self.cases[name])

    def source(self, dotted: str) -> str:
        return self.sources[dotted]

    @property
    def case_names(self) -> list[str]:
        """Case names in file order (unladen first)."""
        return list(self.cases)


def _check_value(path: Path, key: str, spec: Spec, entry: Any) -> Any:
    where = f"{path}: {key}"
    if not isinstance(entry, dict):
        raise ParameterError(f"{where}: expected {{value, unit, source}}, got {type(entry).__name__}")
    missing = ENTRY_KEYS - entry.keys()
    if missing:
        raise ParameterError(f"{where}: missing {', '.join(sorted(missing))}")
    extra = entry.keys() - ENTRY_KEYS
    if extra:
        raise ParameterError(f"{where}: unknown field {', '.join(sorted(extra))}")
    if entry["unit"] != spec.unit:
        raise ParameterError(f"{where}: unit {entry['unit']!r} where {spec.unit!r} is required")
    if not isinstance(entry["source"], str) or not entry["source"].strip():
        raise ParameterError(f"{where}: source must be a non-empty string")
    raw = entry["value"]
    values = raw if spec.is_list else [raw]
    if spec.is_list and (not isinstance(raw, list) or not raw):
        raise ParameterError(f"{where}: expected a non-empty list of numbers")
    out = []
    for v in values:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ParameterError(f"{where}: value {v!r} is not a number")
        v = float(v)
        if not math.isfinite(v):
            raise ParameterError(f"{where}: value {v} is not finite")
        below = v < spec.lower if spec.lower_inclusive else v <= spec.lower
        if below or v > spec.upper:
            low = "[" if spec.lower_inclusive else "("
            raise ParameterError(
                f"{where}: value {v:g} {spec.unit} is non-physical (allowed {low}{spec.lower:g}, {spec.upper:g}])"
            )
        out.append(v)
    return tuple(out) if spec.is_list else out[0]


def _check_table(path: Path, prefix: str, table: Any, schema: dict[str, Spec], sources: dict[str, str]) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise ParameterError(f"{path}: {prefix}: expected a table")
    unknown = sorted(table.keys() - schema.keys())
    if unknown:
        raise ParameterError(f"{path}: {prefix}.{unknown[0]}: unknown key")
    missing = [k for k in schema if k not in table]
    if missing:
        raise ParameterError(f"{path}: {prefix}.{missing[0]}: missing value")
    out = {}
    for key, spec in schema.items():
        out[key] = _check_value(path, f"{prefix}.{key}", spec, table[key])
        sources[f"{prefix}.{key}"] = table[key]["source"]
    return out


def load_parameters(path: str | Path = DEFAULT_PATH) -> Parameters:
    """Read and validate a parameter file; raise :class:`ParameterError` on any defect."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ParameterError(f"{path}: cannot read ({exc.strerror})") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None

    sources: dict[str, str] = {}
    known_top = set(SCHEMA) | {"cases"}
    unknown = sorted(doc.keys() - known_top)
    if unknown:
        raise ParameterError(f"{path}: {unknown[0]}: unknown key")
    sections = {}
    for name, schema in SCHEMA.items():
        if name not in doc:
            raise ParameterError(f"{path}: {name}: missing section")
        sections[name] = _check_table(path, name, doc[name], schema, sources)

    cases_doc = doc.get("cases")
    if not isinstance(cases_doc, dict) or not cases_doc:
        raise ParameterError(f"{path}: cases: missing section")
    cases = {name: _check_table(path, f"cases.{name}", table, CASE_SCHEMA, sources) for name, table in cases_doc.items()}
    return Parameters(path=path, sections=sections, cases=cases, sources=sources)
