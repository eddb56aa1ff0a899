"""The numbers a design study quotes from a sweep's point records (results/sweep_<name>.json), and its map slice.

The records are read by :mod:`.records` (all in memory) or :mod:`.gathering` (streamed, with the table).

The summary answers, for whatever axes the sweep has:

* design point: the point nearest the base car on every axis, with its figures of merit;
* sensitivity: for each axis, the figures of merit at its lowest and highest value with
  every other axis held at the design point (free-rolling and, where computed, braked);
* assistance: which designs need more than the threshold torque at the handwheel, and,
  along the map's y axis, the value at which the torque crosses the threshold.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..parameters import Parameters
from .declaration import Sweep
from .design import base_value
from .keys import parameter_bounds
from .records import as_float, column_name, merits_of, point_quantity
from .totals import Totals

# Relative tolerance for "this grid value is the base car's value".
ON_DESIGN_RTOL = 1e-3


def axis_values(sweep: Sweep, key: str) -> list[float]:
    """The values the sweep gives `key`: its axis, or those of its declared points, sorted."""
    if sweep.axes:
        return list(sweep.axes[key])
    return sorted({p.values[key] for p in sweep.points if key in p.values})


def design_values(sweep: Sweep, params: Parameters) -> dict[str, dict[str, Any]]:
    """For each key: the base car's value, the sweep value nearest it, and whether they agree."""
    out = {}
    for key in sweep.keys:
        base = base_value(params, sweep.base_case, key)
        values = np.array(axis_values(sweep, key))
        nearest = float(values[np.argmin(np.abs(values - base))])
        on_design = math.isclose(nearest, base, rel_tol=ON_DESIGN_RTOL, abs_tol=1e-12)
        out[key] = {"base": base, "nearest": nearest, "on_design": on_design}
    return out


def matching(records: list[dict], fixed: dict[str, float]) -> list[dict]:
    return [r for r in records if all(r["values"].get(k) == v for k, v in fixed.items())]


def sensitivities(sweep: Sweep, records: list[dict], design: dict) -> dict[str, Any]:
    out = {}
    for key in sweep.keys:
        held = {k: d["nearest"] for k, d in design.items() if k != key}
        line = sorted(matching(records, held), key=lambda r: r["values"][key])
        if len(line) < 2:
            continue
        low, high = line[0], line[-1]
        entry = {"held": held, "values": [r["values"][key] for r in line],
                 "low": {"value": low["values"][key], "point": low["point"], **merits_of(low)},
                 "high": {"value": high["values"][key], "point": high["point"], **merits_of(high)},
                 "points": [{"value": r["values"][key], **merits_of(r)} for r in line]}
        for q in ("plateau_torque_Nm", "peak_torque_Nm", "plateau_torque_braked_Nm", "tyre_share_Nm"):
            lo, hi = entry["low"][q], entry["high"][q]
            entry[f"change_{q}"] = hi - lo
            entry[f"ratio_{q}"] = hi / lo if lo else math.nan
        out[key] = entry
    return out


def map_held(sweep: Sweep, design: dict) -> dict[str, float]:
    """The values the map holds the keys other than its x, y and panels at (its own, or the design point's)."""
    spec = sweep.map
    return {k: spec.hold.get(k, d["nearest"]) for k, d in design.items() if k not in (spec.x, spec.y, spec.panels)}


@dataclass
class MapSlice:
    """The map's held slice of a sweep (the points whose keys other than the map's x, y and panels are at the held
    values), in the sweep's order: each point's panel value, x, y (nan where a point has no such key) and the
    figures of merit `quantities` names; a few numbers a point instead of its record."""

    panel: np.ndarray
    x: np.ndarray
    y: np.ndarray
    quantities: dict[str, np.ndarray]

    @classmethod
    def of(cls, sweep: Sweep, records: Iterable[dict], held: dict[str, float], quantities) -> MapSlice:
        """The slice of `records`, all of them or the points gathered, each with its index, in any order."""
        collector = SliceCollector(sweep, held, quantities)
        for position, record in enumerate(records):
            collector.add(record, record.get("index", position))
        return collector.finish()


class SliceCollector:
    """MapSlice.of one record at a time: the held points' numbers in flat arrays, sorted by index at the end."""

    def __init__(self, sweep: Sweep, held: dict[str, float], quantities):
        self.spec, self.held, self.names = sweep.map, list(held.items()), list(dict.fromkeys(quantities))
        self.index = array("q")
        self.columns = {name: array("d") for name in ("panel", "x", "y", *self.names)}

    def add(self, record: dict, index: int) -> None:
        values = record["values"]
        if not all(values.get(k) == v for k, v in self.held):
            return
        spec, columns = self.spec, self.columns
        self.index.append(index)
        columns["panel"].append(as_float(values.get(spec.panels)) if spec.panels else math.nan)
        columns["x"].append(as_float(values.get(spec.x)))
        columns["y"].append(as_float(values.get(spec.y)))
        for name in self.names:
            columns[name].append(point_quantity(record, name))

    def finish(self) -> MapSlice:
        order = np.argsort(np.asarray(self.index, dtype=np.int64), kind="stable")
        column = {name: np.asarray(values, dtype=float)[order] for name, values in self.columns.items()}
        return MapSlice(column["panel"], column["x"], column["y"], {name: column[name] for name in self.names})


def threshold_crossings(sweep: Sweep, records: list[dict], design: dict, quantity: str, threshold: float,
                        map_slice: MapSlice | None = None) -> list[dict[str, Any]]:
    """Along the map's y axis, where `quantity` reaches `threshold` (linear interpolation), per panel and x value;
    from the map's slice of `records` (in the sweep's order), or `map_slice` where given (with `quantity`)."""
    spec = sweep.map
    if spec is None:
        return []
    if map_slice is None:
        map_slice = MapSlice.of(sweep, records, map_held(sweep, design), [quantity])
    panels = axis_values(sweep, spec.panels) if spec.panels else [None]
    lines: dict[tuple, list[int]] = {}  # (panel, x) -> its points' places in the slice, in the sweep's order
    panel_of = map_slice.panel.tolist() if spec.panels else [None] * len(map_slice.x)
    for place, key in enumerate(zip(panel_of, map_slice.x.tolist())):
        lines.setdefault(key, []).append(place)
    ys_all, qs_all = map_slice.y, map_slice.quantities[quantity]
    out = []
    for panel in panels:
        for x in axis_values(sweep, spec.x):
            line = sorted(lines.get((panel, x), []), key=lambda place: ys_all[place])
            ys = ys_all[np.asarray(line, dtype=np.int64)]
            qs = qs_all[np.asarray(line, dtype=np.int64)]
            crossing = math.nan
            above = np.flatnonzero(qs > threshold)
            if len(above) and above[0] > 0:
                i = above[0]
                crossing = float(ys[i - 1] + (threshold - qs[i - 1]) * (ys[i] - ys[i - 1]) / (qs[i] - qs[i - 1]))
            out.append({"panel": panel, "x": x, "crossing_y": crossing,
                        "all_above": bool(len(qs) and np.all(qs > threshold)),
                        "none_above": bool(not np.any(qs > threshold))})
    return out


def summarise(sweep: Sweep, params: Parameters, records: list[dict], totals: Totals | None = None,
              map_slice: MapSlice | None = None) -> dict[str, Any]:
    """The key numbers of a sweep (results/sweep_<name>.json), from its records in the sweep's order: all of them,
    or those gather_points keeps (the lines through the design point) with the totals it counts over all and the
    map's slice. The list of the points above the assistance threshold is then a StreamedList, to be written
    (tables.write_json) while gather_points' context is open."""
    if totals is None:
        totals = Totals.of(records, sweep.assistance.torque_Nm if sweep.assistance else None)
    design = design_values(sweep, params)
    design_fixed = {k: d["nearest"] for k, d in design.items()}
    found = matching(records, design_fixed)
    design_point = {"values": design_fixed, "on_design": all(d["on_design"] for d in design.values()),
                    "base": {k: d["base"] for k, d in design.items()}}
    if found:
        design_point.update(point=found[0]["point"], **merits_of(found[0]),
                            shares={k.replace("share_contrib_", "").removesuffix("_Nm"): v
                                    for k, v in found[0]["merits"].items() if k.startswith("share_contrib_")})
    summary: dict[str, Any] = {
        "sweep": sweep.name,
        "description": sweep.description,
        "full": sweep.full,
        "n_points": totals.n_points,
        "base_case": sweep.base_case,
        "effects": totals.effects,
        "surface": sweep.surface,
        "axes": {k: {"values": axis_values(sweep, k), "unit": parameter_bounds(k)[3],
                     "column": column_name(k), **design[k]} for k in sweep.keys},
        "design_point": design_point,
        "sensitivity": sensitivities(sweep, records, design),
        "braked_method": totals.braked_method,
        "peak_torque_range_Nm": list(totals.peak_range_Nm),
    }
    if sweep.assistance is not None:
        threshold = sweep.assistance.torque_Nm
        summary["assistance"] = {
            "threshold_Nm": threshold,
            "rim_force_N": sweep.assistance.rim_force_N,
            "rim_radius_m": sweep.assistance.rim_radius_m,
            "rim_force_source": sweep.assistance.rim_force_source,
            "rim_radius_source": sweep.assistance.rim_radius_source,
            "quantity": "peak_torque_Nm",
            "n_above": totals.n_above,
            "n_above_braked": totals.n_above_braked,
            "points_above": totals.points_above_in_order(),
            "crossings": threshold_crossings(sweep, records, design, "peak_torque_Nm", threshold, map_slice),
        }
        if sweep.map is not None:
            summary["assistance"]["crossing_axis"] = sweep.map.y
            summary["assistance"]["crossing_along"] = sweep.map.x
            summary["assistance"]["crossing_panels"] = sweep.map.panels
    if sweep.map is not None:
        summary["map"] = {"x": sweep.map.x, "y": sweep.map.y, "panels": sweep.map.panels,
                          "hold": {k: sweep.map.hold.get(k, design[k]["nearest"]) for k in design
                                   if k not in (sweep.map.x, sweep.map.y, sweep.map.panels)},
                          "quantity": sweep.map.quantity}
    return summary
