"""A vehicle file: what describes one car, read through the parameter registry and checked by statics.

A vehicle file (``data/vehicles/<name>.toml``) holds only the car: its masses and inertias (``[vehicle]``), the
steering gear (``[steering]``), the suspension geometry (``[geometry]``), the tyre (``[tyre]``), the handwheel
lock (``[input] handwheel_lock_angle``) and one or more load cases (``[cases.<name>]``: chassis mass and lateral
mass centre, half track, static wheel loads). Every entry is ``{value, unit, source}`` under the keys, units and
bounds of :mod:`parksteer.parameters`. What the paper's tyre rig, spacers, synthetic logger and test procedure need
(``[rig]``, ``[spacers]``, ``[synthetic]``, the cycle's timing) is not asked for; it comes from the base parameter
file, and the file may still override any key of it (a candidate effect's friction guess, for instance).

At load time the car is checked as a car, each refusal one line naming the file and the key: the wheel loads
against the masses (:func:`parksteer.parameter_entries.check_statics`), the unsprung mass against the parts the model
moves, the heights in order (king-pin top above the wheel centre above the ground), the king-pin top inboard of
the wheel centre and meeting the ground on its own side, and the road-wheel lock within :data:`MAX_LOCK_STEER_RAD`.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path
from typing import Any

from ..boost_table import KMH, BoostTableError, entries
from ..errors import UsageError, cannot_read
from ..parameter_entries import (PROVENANCE, PROVENANCES, check_entry, check_provenance, check_statics, check_table,
                                 provenance_key)
from ..model.numeric.assist import ASSIST_EFFECTS, assist_of
from ..parameters import (CASE_SCHEMA, DEFAULT_PATH, SCHEMA, VEHICLE_SPEED, ParameterError, Parameters, load_parameters,
                          quantity)

# Keys every vehicle file must give: everything the model takes from the car itself.
REQUIRED: tuple[str, ...] = (
    *(f"vehicle.{k}" for k in SCHEMA["vehicle"] if k != "gravity"),
    *(f"steering.{k}" for k in SCHEMA["steering"] if k != "friction_smoothing"),
    *(f"geometry.{k}" for k in SCHEMA["geometry"]),
    *(f"tyre.{k}" for k in SCHEMA["tyre"]),
    "input.handwheel_lock_angle",
)

# The model's steering arm is linear (road-wheel steer = roadwheel_to_rack_ratio x rack), which stands for a real
# rack-and-arm linkage only well short of the arm's dead point; road cars lock at 0.5-0.8 rad (30-45 degrees) at
# the inner wheel. One radian (57 degrees) refuses a lock the linear linkage cannot stand for, and no road car's.
MAX_LOCK_STEER_RAD = 1.0

# The unsprung mass in the statics is the mass the model moves besides the chassis: both steering assemblies,
# both tread rings and the rack. The masses are printed to 0.1 kg; half a kilogram covers five roundings.
UNSPRUNG_TOLERANCE_KG = 0.5


# ``[assist]`` of a vehicle file: its ``type`` and the assist effect it names (ASSIST_EFFECTS). The entries
# ({value, unit, source}, the effect's quantities by name) go into that effect's section; the model layer, which
# knows the quantities, checks them (parksteer.model.numeric.assist.check_assist).
ASSIST_SECTION = "assist"

# ``[assist.boost]``: the boost table of an assist (parksteer.boost_table) and the units its entries take: the
# assist at the point of action (N m at the column or pinion, N at the rack), or the hydraulic valve's pressure (bar
# or Pa, read in Pa).
BOOST_SECTION = "boost"
BOOST_UNITS = {"torsion_bar_torque": ("N m",), "assist": ("N m", "N", "bar", "Pa"), "vehicle_speed": ("km/h", "m/s"),
               "gain_uncertainty": ("1",)}
# An identified table's ``gain_uncertainty`` (``parksteer assist identify``): the 95 % half-width of the table's
# common gain, relative. It is no quantity of the model (the law does not read it): the diagnosis reads it as
# params[BOOST_GAIN_UNCERTAINTY] (parksteer.diagnose.stages.baseline).
BOOST_GAIN_UNCERTAINTY = "boost.gain_uncertainty"
MAX_GAIN_UNCERTAINTY = 0.5
BOOST_ASSIST_UNITS = {"column": ("N m",), "pinion": ("N m",), "rack": ("N",), "hydraulic": ("bar", "Pa")}
BAR_PA = 1.0e5

MAX_CREEPING_SPEED_KMH = VEHICLE_SPEED.upper * 3.6  # the run's vehicle speed's upper bound, 3 m/s: 10.8 km/h

# The effects specs of an assist sizing study (parksteer.sweep.assist_sizing, rule vehicle_assist_size): the car
# rolling at the study's speeds (turn_slip), without and with its assist.
CREEPING_EFFECTS = "+turn_slip"
ASSISTED_EFFECTS = {kind: f"{CREEPING_EFFECTS},+{name}" for kind, name in ASSIST_EFFECTS.items()}


def creeping_overrides(speed_kmh: float) -> dict:
    """The overrides of a run at `speed_kmh`: the run's vehicle speed (VEHICLE_SPEED), in m/s."""
    return {VEHICLE_SPEED.key: speed_kmh / 3.6}


def _read_assist(path: Path, table: Any, sections: dict, sources: dict) -> None:
    """``[assist]`` into the section of the effect its type names; each entry a finite {value, unit, source}."""
    if not isinstance(table, dict):
        raise ParameterError(f"{path}: assist: expected a table")
    kind = table.get("type")
    if not isinstance(kind, str) or kind not in ASSIST_EFFECTS:
        raise ParameterError(f"{path}: assist.type: {kind!r}, expected one of {', '.join(ASSIST_EFFECTS)}")
    name = ASSIST_EFFECTS[kind]
    values = {}
    for key, entry in table.items():
        if key == "type":
            continue
        if key == BOOST_SECTION:
            continue  # read below, once the gear's own values (efficiency, reduction) are known
        if key.startswith("boost_"):
            raise ParameterError(f"{path}: assist.{key}: a boost table is written as [assist.boost] (torsion_bar_torque, "
                                 "assist, optionally vehicle_speed)")
        if not isinstance(entry, dict) or set(entry) - {PROVENANCE} != {"value", "unit", "source"}:
            raise ParameterError(f"{path}: assist.{key}: expected {{ value, unit, source }} (and optionally "
                                 f"provenance, one of {', '.join(PROVENANCES)})")
        _check_text(f"{path}: assist.{key}", entry)
        provenance = check_provenance(f"{path}: assist.{key}", entry)
        value = entry["value"]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ParameterError(f"{path}: assist.{key}: value {value!r} is not a finite number")
        values[key] = float(value)
        sources[f"{name}.{key}"] = str(entry["source"])
        sources[f"{name}.{key}.unit"] = str(entry["unit"])
        if provenance is not None:
            sources[provenance_key(f"{name}.{key}")] = provenance
    if BOOST_SECTION in table:
        entry = table[BOOST_SECTION]
        values.update(_read_boost(path, kind, entry, name, sources, values))
        if isinstance(entry, dict) and "gain_uncertainty" in entry:
            section, _, field_name = BOOST_GAIN_UNCERTAINTY.partition(".")
            sections[section] = {field_name: _gain_uncertainty(path, entry["gain_uncertainty"])}
            sources[BOOST_GAIN_UNCERTAINTY] = str(entry["gain_uncertainty"].get("source", ""))
    if BOOST_SECTION in table:
        # the table is the boost curve: the gain's (or the valve slope's) straight line is not added to it
        line = "valve_slope" if kind == "hydraulic" else "gain"
        if values.get(line, 0.0) != 0.0 or values.get("speed_dependence", 0.0) != 0.0:
            what = ("a valve slope give the valve's characteristic twice; drop valve_slope and dead_band"
                    if kind == "hydraulic" else
                    "a gain (or its speed dependence) give the boost curve twice; drop gain, dead_band and "
                    "speed_dependence (the table's rows give the speeds)")
            raise ParameterError(f"{path}: assist: a boost table and {what}")
        values.setdefault(line, 0.0)
        sources.setdefault(f"{name}.{line}", "0: the boost table [assist.boost] gives the curve")
    sections[name] = values


def _check_text(where: str, entry: dict) -> None:
    """An entry's unit and source are text (a number or a table there is a slip of the hand)."""
    for field_name in ("unit", "source"):
        if field_name in entry and not isinstance(entry[field_name], str):
            raise ParameterError(f"{where}: {field_name} {_toml_text(entry[field_name])} is not a string")


def _toml_text(value: Any) -> str:
    """`value` as the file wrote it (``true``, ``"0.9"``), for a message."""
    return json.dumps(value) if isinstance(value, (bool, str)) else repr(value)


def _numbers(where: str, values: Any, row: str = "") -> list[float]:
    """A list of numbers from a vehicle file: each a TOML integer or float, not a boolean or a string (``true`` or
    ``"0.9"``, which float() would take); one-line ParameterError naming the row and the point otherwise."""
    if not isinstance(values, list) or not values:
        raise ParameterError(f"{where}: {row}expected a list of numbers")
    for k, value in enumerate(values, 1):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(f"{where}: {row}point {k}: {_toml_text(value)} is not a number")
    return [float(v) for v in values]


def _gain_uncertainty(path: Path, entry: dict) -> float:
    """``[assist.boost] gain_uncertainty``: a relative half-width in [0, MAX_GAIN_UNCERTAINTY]."""
    value = entry["value"]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= MAX_GAIN_UNCERTAINTY:
        raise ParameterError(f"{path}: assist.boost.gain_uncertainty: value {value!r}, expected a relative "
                             f"half-width from 0 to {MAX_GAIN_UNCERTAINTY:g}")
    return float(value)


def _read_boost(path: Path, kind: str, table: Any, name: str, sources: dict,
                gear: dict[str, float]) -> dict[str, float]:
    """``[assist.boost]``: the boost table (:mod:`parksteer.boost_table`) as the effect's scalar entries (its
    ``gain_uncertainty`` is read apart, :func:`_gain_uncertainty`). An electric assist's ``assist`` may say
    ``at = "motor"``: its values are the motor's torque (N m), carried to the point of action through eta N (the
    ``efficiency`` and ``reduction_ratio`` of [assist], `gear`, else the effect's defaults)."""
    where = f"{path}: assist.boost"
    if not isinstance(table, dict) or not {"torsion_bar_torque", "assist"} <= set(table) or not set(table) <= set(
            BOOST_UNITS):
        raise ParameterError(f"{where}: expected torsion_bar_torque, assist and optionally vehicle_speed and gain_uncertainty")
    read: dict[str, list] = {}
    for key, entry in table.items():
        if not isinstance(entry, dict) or not {"value", "unit"} <= set(entry) or not set(entry) <= {
                "value", "unit", "source", *(("at",) if key == "assist" else ())}:
            raise ParameterError(f"{where}.{key}: expected {{ value, unit, source }}"
                                 + (" and optionally at" if key == "assist" else ""))
        units = BOOST_UNITS[key] if key != "assist" else BOOST_ASSIST_UNITS[kind]
        _check_text(f"{where}.{key}", entry)
        if key == "assist" and "at" in entry:
            points = ("motor", kind) if kind != "hydraulic" else ()
            if entry["at"] not in points:
                raise ParameterError(f"{where}.assist.at: {entry['at']!r}, expected "
                                     + (" or ".join(map(repr, points)) if points else
                                        "nothing (a valve's table is its pressure)"))
            units = ("N m",) if entry["at"] == "motor" else units
        if entry["unit"] not in units:
            raise ParameterError(f"{where}.{key}: unit {entry['unit']!r}, expected {' or '.join(map(repr, units))}")
        if key == "gain_uncertainty":
            continue
        read[key] = entry["value"]
        sources[f"{name}.boost.{key}"] = str(entry.get("source", ""))
    speeds = read.get("vehicle_speed")
    torques = _numbers(f"{where}.torsion_bar_torque", read["torsion_bar_torque"])
    if speeds is None:
        if isinstance(read["assist"], list) and any(isinstance(row, list) for row in read["assist"]):
            raise ParameterError(f"{where}.assist: rows for several vehicle speeds need vehicle_speed, one per row")
        rows = [_numbers(f"{where}.assist", read["assist"])]
    else:
        speeds = _numbers(f"{where}.vehicle_speed", speeds)
        if not isinstance(read["assist"], list) or not all(isinstance(row, list) for row in read["assist"]):
            raise ParameterError(f"{where}.assist: expected one list of numbers per vehicle speed")
        rows = [_numbers(f"{where}.assist", row, f"row {r}, ") for r, row in enumerate(read["assist"], 1)]
    try:
        scale = BAR_PA if table["assist"]["unit"] == "bar" else 1.0
        if table["assist"].get("at") == "motor":
            scale = motor_to_point_of_action(name, gear)
        rows = [[float(a) * scale for a in row] for row in rows]
        if speeds is not None:
            scale = KMH if table["vehicle_speed"]["unit"] == "km/h" else 1.0
            speeds = [v * scale for v in speeds]
        out = entries(torques, speeds, rows)
    except BoostTableError as exc:
        raise ParameterError(f"{where}: {exc}") from None
    source = f"derived: [assist.boost] ({sources[f'{name}.boost.assist']})"
    if table["assist"].get("at") == "motor":
        source += f" (motor torque x eta N = {motor_to_point_of_action(name, gear):g})"
    for key in out:
        sources[f"{name}.{key}"] = source
    return out


def motor_to_point_of_action(name: str, gear: dict[str, float]) -> float:
    """eta N of the electric assist `name`: its ``efficiency`` and ``reduction_ratio`` as the file gives them
    (`gear`), else as the effect declares them."""
    from ..model.symbolic.components import shipped_quantities  # not for --help
    declared = shipped_quantities()
    value = lambda key: gear[key] if key in gear else quantity(f"{name}.{key}", declared).default  # noqa: E731
    return value("efficiency") * value("reduction_ratio")


def vehicle_name(path: str | Path) -> str:
    """A vehicle's name: its file's stem (``data/vehicles/small_hatch.toml`` -> ``small_hatch``)."""
    return Path(path).stem


def load_vehicle(path: str | Path, base: str | Path | Parameters = DEFAULT_PATH) -> Parameters:
    """The base parameters with the car of the vehicle file `path`: its values replace the base's, its cases
    replace the base's cases. Raises :class:`ParameterError` (one line, file and key) on any defect. A value of an
    effect's own quantity (``[ackermann] track_to_wheelbase``) is checked against the effect's declaration, and
    the parameters know the installed effects' quantities
    (:func:`parksteer.model.symbolic.components.with_effect_quantities`)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ParameterError(cannot_read(path, exc)) from None
    return vehicle_from_text(text, path, base)


def vehicle_from_text(text: str, path: str | Path, base: str | Path | Parameters = DEFAULT_PATH) -> Parameters:
    """:func:`load_vehicle` of the text `text`, named `path` in every message."""
    from ..model.symbolic.components import with_effect_quantities  # not for --help
    path = Path(path)
    base_params = base if isinstance(base, Parameters) else load_parameters(base)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None

    sections = {name: dict(values) for name, values in base_params.sections.items()}
    sources = {k: v for k, v in base_params.sources.items() if not k.startswith("cases.")}
    for key in REQUIRED:
        section, _, name = key.partition(".")
        table = doc.get(section)
        if not isinstance(table, dict) or name not in table:
            raise ParameterError(f"{path}: {key}: missing value (a vehicle file gives every value of the car)")
    for section, table in doc.items():
        if section == ASSIST_SECTION:
            _read_assist(path, table, sections, sources)
            continue
        if section == "cases":
            continue
        if not isinstance(table, dict):
            raise ParameterError(f"{path}: {section}: expected a table")
        for name, entry in table.items():
            spec = _file_or_effect_quantity(path, section, name)
            sections.setdefault(section, {})[name] = check_entry(path, f"{section}.{name}", spec, entry)
            sources[f"{section}.{name}"] = entry["source"]
            if PROVENANCE in entry:
                sources[provenance_key(f"{section}.{name}")] = entry[PROVENANCE]
            else:  # the base file's declaration is not this entry's
                sources.pop(provenance_key(f"{section}.{name}"), None)

    cases_doc = doc.get("cases")
    if not isinstance(cases_doc, dict) or not cases_doc:
        raise ParameterError(f"{path}: cases: missing section (at least one load case, [cases.<name>])")
    cases = {name: check_table(path, f"cases.{name}", table, CASE_SCHEMA, sources)
             for name, table in cases_doc.items()}
    params = Parameters(path=path, sections=sections, cases=cases, sources=sources,
                        declared=with_effect_quantities(base_params).declared)
    check_car(params)
    return params


def _file_or_effect_quantity(path: Path, section: str, name: str):
    """The quantity of ``section.name``: a key of the parameter file, or an installed effect's own quantity (a car's
    value of it, e.g. ``ackermann.track_to_wheelbase``, declared on the effect)."""
    from ..model.symbolic.components import shipped_quantities  # not for --help
    if section in SCHEMA:
        spec = SCHEMA[section].get(name)
        if spec is None:
            raise ParameterError(f"{path}: {section}.{name}: unknown key")
        return spec
    try:
        return quantity(f"{section}.{name}", shipped_quantities())
    except UsageError:
        raise ParameterError(f"{path}: {section}.{name}: unknown key (a key of the parameter file, cases, or an "
                             "effect's own quantity)") from None


def check_car(params: Parameters) -> None:
    """Statics and sign checks of a car; one-line :class:`ParameterError` naming the file and the key."""
    from ..geometry import lock_steer_angle, steer_axis  # numpy: imported here, not by the command line's --help

    path, s = params.path, params.sections
    parts_kg = (2.0 * s["steering"]["steering_assembly_mass"] + 2.0 * s["tyre"]["tread_ring_mass"]
                + s["steering"]["rack_mass"])
    if abs(s["vehicle"]["unsprung_mass"] - parts_kg) > UNSPRUNG_TOLERANCE_KG:
        raise ParameterError(
            f"{path}: vehicle.unsprung_mass: {s['vehicle']['unsprung_mass']:g} kg, but the parts the model moves "
            f"(2 steering assemblies + 2 tread rings + rack) weigh {parts_kg:g} kg")
    check_statics(path, s, params.cases)
    g = s["geometry"]
    if not g["kingpin_top_z"] < g["wheel_centre_z"] < g["ground_z"]:
        raise ParameterError(
            f"{path}: geometry.wheel_centre_z: heights out of order (z down): need kingpin_top_z "
            f"{g['kingpin_top_z']:g} < wheel_centre_z {g['wheel_centre_z']:g} < ground_z {g['ground_z']:g} m")
    for name, case in params.cases.items():
        if g["kingpin_top_y"] >= case["wheel_centre_y"]:
            raise ParameterError(
                f"{path}: cases.{name}.wheel_centre_y: {case['wheel_centre_y']:g} m is not outboard of "
                f"geometry.kingpin_top_y {g['kingpin_top_y']:g} m")
        intercept_y = float(steer_axis(params, name, "right").ground_intercept()[1])
        if intercept_y <= 0.0:
            raise ParameterError(
                f"{path}: geometry.kingpin_inclination: the right king-pin axis meets the ground at y = "
                f"{intercept_y:.3f} m, across the centreline (case {name})")
    lock = lock_steer_angle(params)
    if lock >= MAX_LOCK_STEER_RAD:
        raise ParameterError(
            f"{path}: input.handwheel_lock_angle: {s['input']['handwheel_lock_angle']:g} rad steers the road "
            f"wheels {math.degrees(lock):.1f} deg at lock, beyond the linear linkage's {math.degrees(MAX_LOCK_STEER_RAD):.0f} deg "
            f"(check the lock and steering.handwheel_to_rack_ratio / roadwheel_to_rack_ratio)")
