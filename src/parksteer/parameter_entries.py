"""The entries of a parameter or vehicle file, ``{value, unit, source}`` (and an optional ``provenance``), checked
against the quantities' table (:mod:`parksteer.quantities`): an entry (:func:`check_entry`), a table of entries
(:func:`check_table`) and each case's wheel loads against the chassis statics (:func:`check_statics`), every
refusal one :class:`~parksteer.quantities.ParameterError` line naming the file and the key."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .quantities import RENAMED, ParameterError, Quantity

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


def check_entry(path: Path, key: str, spec: Quantity, entry: Any) -> Any:
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


def check_table(path: Path, prefix: str, table: Any, schema: dict[str, Quantity], sources: dict[str, str]
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
        out[key] = check_entry(path, f"{prefix}.{key}", spec, table[key])
        sources[f"{prefix}.{key}"] = table[key]["source"]
        if PROVENANCE in table[key]:
            sources[provenance_key(f"{prefix}.{key}")] = table[key][PROVENANCE]
    return out


def check_statics(path: Path, sections: dict[str, dict[str, Any]], cases: dict[str, dict[str, float]]) -> None:
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
