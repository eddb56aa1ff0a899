"""The fields of a sweep declaration, each read and checked by its own reader (one line naming the file and the
field for every problem, :class:`~parksteer.sweep.design.SweepError`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from ..errors import UsageError, cannot_read
from .design import SweepError
from .keys import axis_values, check_conflicts, check_in_bounds, check_key, grid_value, read_number


# Figures of merit a map can show (written by parksteer.sweep.merit for every point).
MAP_QUANTITIES = (
    "peak_torque_Nm",
    "plateau_torque_Nm",
    "lock_torque_Nm",
    "reversal_drop_Nm",
    "plateau_torque_braked_Nm",
    "peak_torque_braked_Nm",
)


# How a point compares its wheels braked: not at all, the post-hoc rig-theory estimate, or (any other value) a
# second simulation with that effect added at the top of its brake_fraction range.
BRAKED_NONE, BRAKED_RIG_THEORY = "none", "rig_theory"


BRAKE_PARAMETER = "brake_fraction"


@dataclass(frozen=True)
class MapSpec:
    """Which two axes a torque map spans, one panel per value of `panels`, the other axes held."""

    x: str
    y: str
    panels: str | None
    hold: dict[str, float]
    quantity: str


@dataclass(frozen=True)
class AssistanceThreshold:
    """The handwheel torque above which a design is taken to need power assistance: rim force x rim radius."""

    rim_force_N: float
    rim_radius_m: float
    rim_force_source: str
    rim_radius_source: str

    @property
    def torque_Nm(self) -> float:
        return self.rim_force_N * self.rim_radius_m


def read_declaration(path: Path) -> dict:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SweepError(cannot_read(path, exc)) from None
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0] if str(exc) else "syntax error"
        raise SweepError(f"{path}: not valid YAML ({first})") from None
    if not isinstance(doc, dict):
        raise SweepError(f"{path}: expected a mapping of sweep fields")
    return doc


def read_axes(path: Path, field_name: str, raw: Any) -> dict[str, tuple[float, ...]]:
    where = f"{path}: {field_name}"
    if not isinstance(raw, dict) or not raw:
        raise SweepError(f"{where}: expected a mapping of parameter keys to values")
    axes = {}
    for key, values in raw.items():
        check_key(where, key)
        axes[key] = axis_values(f"{where}.{key}", key, values)
    check_conflicts(where, list(axes))
    return axes


def read_points(path: Path, raw: Any) -> list[dict[str, float]]:
    where = f"{path}: points"
    if not isinstance(raw, list) or not raw:
        raise SweepError(f"{where}: expected a non-empty list of points")
    out = []
    for i, entry in enumerate(raw):
        if not isinstance(entry, dict) or not entry:
            raise SweepError(f"{where}[{i}]: expected a mapping of parameter keys to values")
        values = {}
        for key, value in entry.items():
            check_key(f"{where}[{i}]", key)
            values[key] = check_in_bounds(f"{where}[{i}].{key}", key, grid_value(read_number(f"{where}[{i}].{key}", value)))
        check_conflicts(f"{where}[{i}]", list(values))
        out.append(values)
    seen = set()
    for i, values in enumerate(out):
        frozen = tuple(sorted(values.items()))
        if frozen in seen:
            raise SweepError(f"{where}[{i}]: repeated point")
        seen.add(frozen)
    return out


def read_threshold(path: Path, raw: Any) -> AssistanceThreshold:
    where = f"{path}: assistance"
    if not isinstance(raw, dict):
        raise SweepError(f"{where}: expected rim_force and rim_radius")
    unknown = sorted(set(raw) - {"rim_force", "rim_radius"})
    if unknown:
        raise SweepError(f"{where}.{unknown[0]}: unknown field (use rim_force, rim_radius)")
    out = {}
    for name, unit in (("rim_force", "N"), ("rim_radius", "m")):
        entry = raw.get(name)
        if not isinstance(entry, dict) or set(entry) != {"value", "unit", "source"}:
            raise SweepError(f"{where}.{name}: expected {{value, unit, source}}")
        if entry["unit"] != unit:
            raise SweepError(f"{where}.{name}: unit {entry['unit']!r} where {unit!r} is required")
        if not isinstance(entry["source"], str) or not entry["source"].strip():
            raise SweepError(f"{where}.{name}: source must be a non-empty string")
        value = read_number(f"{where}.{name}.value", entry["value"])
        if value <= 0:
            raise SweepError(f"{where}.{name}.value: {value:g} {unit} must be positive")
        out[name] = (value, entry["source"].strip())
    return AssistanceThreshold(out["rim_force"][0], out["rim_radius"][0], out["rim_force"][1], out["rim_radius"][1])


def read_map(path: Path, raw: Any, keys: list[str], axes: dict[str, tuple[float, ...]], points) -> MapSpec:
    where = f"{path}: map"
    if not isinstance(raw, dict):
        raise SweepError(f"{where}: expected a mapping with x, y and quantity")
    unknown = sorted(set(raw) - {"x", "y", "panels", "hold", "quantity"})
    if unknown:
        raise SweepError(f"{where}.{unknown[0]}: unknown field (use x, y, panels, hold, quantity)")
    for name in ("x", "y", "quantity"):
        if name not in raw:
            raise SweepError(f"{where}: needs {name}")
    for name in ("x", "y", "panels"):
        key = raw.get(name)
        if key is not None and key not in keys:
            raise SweepError(f"{where}.{name}: {key!r} is not a key of this sweep")
    used = [raw["x"], raw["y"]] + ([raw["panels"]] if raw.get("panels") else [])
    if len(set(used)) != len(used):
        raise SweepError(f"{where}: x, y and panels must be different keys")
    if raw["quantity"] not in MAP_QUANTITIES:
        raise SweepError(f"{where}.quantity: {raw['quantity']!r} is not one of {', '.join(MAP_QUANTITIES)}")
    hold_raw = raw.get("hold") or {}
    if not isinstance(hold_raw, dict):
        raise SweepError(f"{where}.hold: expected a mapping of keys to values")
    hold = {}
    for key, value in hold_raw.items():
        if key not in keys or key in used:
            raise SweepError(f"{where}.hold.{key}: not a key of this sweep outside x, y and panels")
        value = grid_value(read_number(f"{where}.hold.{key}", value))
        available = axes[key] if axes else sorted({p[key] for p in points if key in p})
        if value not in available:
            raise SweepError(f"{where}.hold.{key}: {value:g} is not a value of this sweep")
        hold[key] = value
    return MapSpec(raw["x"], raw["y"], raw.get("panels"), hold, raw["quantity"])


def check_effects(path: Path, effects: str | None) -> None:
    """The effects spec names effects that exist (resolved as `parksteer simulate --effects` would); null, the
    paper's five, needs no check and so does not import the symbolic model (sympy)."""
    if effects is None:
        return
    from ..model.symbolic.components import resolve_effects

    try:
        resolve_effects(effects)
    except UsageError as exc:
        raise SweepError(f"{path}: effects: {exc}") from None


def read_braked(path: Path, raw: Any, effects: str | None, surface: str) -> tuple[str, tuple[str, ...] | None]:
    """The braked-wheel comparison: none, rig_theory, or an effect with a brake_fraction parameter."""
    where = f"{path}: braked"
    if not isinstance(raw, str) or not raw:
        raise SweepError(f"{where}: expected {BRAKED_NONE}, {BRAKED_RIG_THEORY} or an effect name")
    if raw == BRAKED_NONE:
        return raw, None
    if surface != "ground":
        raise SweepError(f"{where}: braked wheels are compared on the ground only (surface is {surface})")
    from ..model.symbolic.components import discover_effects, resolve_effects

    chosen = [e.name for e in resolve_effects(effects)]
    if "tyre_friction" not in chosen:
        raise SweepError(f"{where}: needs tyre_friction in the model, or there is no patch to drag")
    if raw == BRAKED_RIG_THEORY:
        return raw, None
    found = discover_effects()
    if raw not in found:
        raise SweepError(f"{where}: {raw!r} is neither {BRAKED_NONE}, {BRAKED_RIG_THEORY} nor an effect "
                         f"(known: {', '.join(sorted(found))})")
    if raw in chosen:
        raise SweepError(f"{where}: effect {raw} is already in the free-rolling model")
    if f"{raw}.{BRAKE_PARAMETER}" not in found[raw].uses:
        raise SweepError(f"{where}: effect {raw} has no {BRAKE_PARAMETER} parameter")
    return raw, tuple(sorted(chosen + [raw]))
