"""Gather a sweep's point records into one table and the numbers a design study quotes.

The summary answers, for whatever axes the sweep has:

* design point: the point nearest the base car on every axis, with its figures of merit;
* sensitivity: for each axis, the figures of merit at its lowest and highest value with
  every other axis held at the design point (free-rolling and, where computed, braked);
* assistance: which designs need more than the threshold torque at the handwheel, and,
  along the map's y axis, the value at which the torque crosses the threshold.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..parameters import Parameters
from .declaration import Sweep, parameter_bounds
from .design import base_value

# Relative tolerance for "this grid value is the base car's value".
ON_DESIGN_RTOL = 1e-3
SUMMARY_MERITS = ("peak_torque_Nm", "plateau_torque_Nm", "lock_torque_Nm", "reversal_drop_Nm")


def read_points(paths, sweep: Sweep) -> list[dict[str, Any]]:
    """Point records (JSON files written by run_point, or batch files written by run_batch) in the sweep's order,
    each given its index there."""
    order = {point.id: point.index for point in sweep.points}
    records = []
    for path in paths:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
        records.extend(doc["records"] if "records" in doc else [doc])  # a batch file holds its points' records
    for record in records:
        record["index"] = order.get(record["point"], -1)
    return sorted(records, key=lambda r: r["index"])


def _nan(x) -> float:
    return math.nan if x is None else float(x)


def column_name(key: str) -> str:
    unit = parameter_bounds(key)[3]
    return key if unit == "1" else f"{key}_{unit.replace(' ', '').replace('/', '_per_')}"


def point_quantity(record: dict, quantity: str) -> float:
    """A figure of merit of a record; the braked ones are named <quantity>_braked_Nm."""
    if quantity.endswith("_braked_Nm"):
        return _nan(record["braked"][quantity.replace("_braked_Nm", "_Nm")])
    return _nan(record["merits"][quantity])


def share_names(records: list[dict]) -> list[str]:
    names: dict[str, None] = {}
    for r in records:
        names.update(dict.fromkeys(k for k in r["merits"] if k.startswith("share_contrib_")))
    return list(names)


def sweep_table(sweep: Sweep, records: list[dict], threshold_Nm: float | None) -> dict[str, Any]:
    """Columns of figures/sweep_<name>.csv: one row per point."""
    keys = sweep.keys
    cols: dict[str, Any] = {"point": np.array([r["point"] for r in records]),
                            "index": np.array([r["index"] for r in records])}
    for key in keys:
        cols[column_name(key)] = np.array([_nan(r["values"].get(key)) for r in records])
    for q in SUMMARY_MERITS:
        cols[q] = np.array([point_quantity(r, q) for r in records])
    for name in share_names(records):
        short = name.replace("share_contrib_", "share_").removesuffix("_Nm")
        cols[short] = np.array([_nan(r["merits"].get(name)) for r in records])
    cols["sliding_start_rack_m"] = np.array([_nan(r["merits"]["sliding_start_rack_m"]) for r in records])
    cols["plateau_torque_braked_Nm"] = np.array([point_quantity(r, "plateau_torque_braked_Nm") for r in records])
    cols["peak_torque_braked_Nm"] = np.array([point_quantity(r, "peak_torque_braked_Nm") for r in records])
    cols["braked_factor"] = np.array([_nan(r["braked"]["factor"]) for r in records])
    cols["ground_offset_m"] = np.array([_nan(r["braked"]["ground_offset_m"]) for r in records])
    if threshold_Nm is not None:
        cols["needs_assistance"] = (cols["peak_torque_Nm"] > threshold_Nm).astype(int)
        cols["needs_assistance_braked"] = (cols["peak_torque_braked_Nm"] > threshold_Nm).astype(int)
    return cols


def axis_values(sweep: Sweep, records: list[dict], key: str) -> list[float]:
    if sweep.axes:
        return list(sweep.axes[key])
    return sorted({r["values"][key] for r in records if key in r["values"]})


def design_values(sweep: Sweep, params: Parameters, records: list[dict]) -> dict[str, dict[str, Any]]:
    """For each key: the base car's value, the sweep value nearest it, and whether they agree."""
    out = {}
    for key in sweep.keys:
        base = base_value(params, sweep.base_case, key)
        values = np.array(axis_values(sweep, records, key))
        nearest = float(values[np.argmin(np.abs(values - base))])
        on_design = math.isclose(nearest, base, rel_tol=ON_DESIGN_RTOL, abs_tol=1e-12)
        out[key] = {"base": base, "nearest": nearest, "on_design": on_design}
    return out


def matching(records: list[dict], fixed: dict[str, float]) -> list[dict]:
    return [r for r in records if all(r["values"].get(k) == v for k, v in fixed.items())]


def _merits_of(record: dict) -> dict[str, float]:
    out = {q: point_quantity(record, q) for q in SUMMARY_MERITS}
    out["plateau_torque_braked_Nm"] = point_quantity(record, "plateau_torque_braked_Nm")
    out["peak_torque_braked_Nm"] = point_quantity(record, "peak_torque_braked_Nm")
    out["tyre_share_Nm"] = out["plateau_torque_Nm"] * _nan(record["merits"].get("share_contrib_tyre_friction_Nm"))
    out["braked_factor"] = _nan(record["braked"]["factor"])
    out["rig_theory_plateau_torque_braked_Nm"] = _nan(record["braked"].get("rig_theory_plateau_torque_Nm"))
    out["rig_theory_braked_factor"] = _nan(record["braked"].get("rig_theory_factor"))
    out["ground_offset_m"] = _nan(record["braked"]["ground_offset_m"])
    return out


def sensitivities(sweep: Sweep, records: list[dict], design: dict) -> dict[str, Any]:
    out = {}
    for key in sweep.keys:
        held = {k: d["nearest"] for k, d in design.items() if k != key}
        line = sorted(matching(records, held), key=lambda r: r["values"][key])
        if len(line) < 2:
            continue
        low, high = line[0], line[-1]
        entry = {"held": held, "values": [r["values"][key] for r in line],
                 "low": {"value": low["values"][key], "point": low["point"], **_merits_of(low)},
                 "high": {"value": high["values"][key], "point": high["point"], **_merits_of(high)},
                 "points": [{"value": r["values"][key], **_merits_of(r)} for r in line]}
        for q in ("plateau_torque_Nm", "peak_torque_Nm", "plateau_torque_braked_Nm", "tyre_share_Nm"):
            lo, hi = entry["low"][q], entry["high"][q]
            entry[f"change_{q}"] = hi - lo
            entry[f"ratio_{q}"] = hi / lo if lo else math.nan
        out[key] = entry
    return out


def threshold_crossings(sweep: Sweep, records: list[dict], design: dict, quantity: str, threshold: float
                        ) -> list[dict[str, Any]]:
    """Along the map's y axis, where `quantity` reaches `threshold` (linear interpolation), per panel and x value."""
    spec = sweep.map
    if spec is None:
        return []
    held = {k: spec.hold.get(k, d["nearest"]) for k, d in design.items() if k not in (spec.x, spec.y, spec.panels)}
    panels = axis_values(sweep, records, spec.panels) if spec.panels else [None]
    out = []
    for panel in panels:
        fixed = dict(held, **({spec.panels: panel} if spec.panels else {}))
        for x in axis_values(sweep, records, spec.x):
            line = sorted(matching(records, dict(fixed, **{spec.x: x})), key=lambda r: r["values"][spec.y])
            ys = np.array([r["values"][spec.y] for r in line])
            qs = np.array([point_quantity(r, quantity) for r in line])
            crossing = math.nan
            above = np.flatnonzero(qs > threshold)
            if len(above) and above[0] > 0:
                i = above[0]
                crossing = float(ys[i - 1] + (threshold - qs[i - 1]) * (ys[i] - ys[i - 1]) / (qs[i] - qs[i - 1]))
            out.append({"panel": panel, "x": x, "crossing_y": crossing,
                        "all_above": bool(len(qs) and np.all(qs > threshold)),
                        "none_above": bool(not np.any(qs > threshold))})
    return out


def summarize(sweep: Sweep, params: Parameters, records: list[dict]) -> dict[str, Any]:
    """The key numbers of a sweep (results/sweep_<name>.json)."""
    design = design_values(sweep, params, records)
    design_fixed = {k: d["nearest"] for k, d in design.items()}
    found = matching(records, design_fixed)
    design_point = {"values": design_fixed, "on_design": all(d["on_design"] for d in design.values()),
                    "base": {k: d["base"] for k, d in design.items()}}
    if found:
        design_point.update(point=found[0]["point"], **_merits_of(found[0]),
                            shares={k.replace("share_contrib_", "").removesuffix("_Nm"): v
                                    for k, v in found[0]["merits"].items() if k.startswith("share_contrib_")})
    summary: dict[str, Any] = {
        "sweep": sweep.name,
        "description": sweep.description,
        "full": sweep.full,
        "n_points": len(records),
        "base_case": sweep.base_case,
        "effects": records[0]["effects"] if records else [],
        "surface": sweep.surface,
        "axes": {k: {"values": axis_values(sweep, records, k), "unit": parameter_bounds(k)[3],
                     "column": column_name(k), **design[k]} for k in sweep.keys},
        "design_point": design_point,
        "sensitivity": sensitivities(sweep, records, design),
        "braked_method": records[0]["braked"]["method"] if records else "",
        "peak_torque_range_Nm": [min(point_quantity(r, "peak_torque_Nm") for r in records),
                                 max(point_quantity(r, "peak_torque_Nm") for r in records)] if records else [],
    }
    if sweep.assistance is not None:
        threshold = sweep.assistance.torque_Nm
        above = [r for r in records if point_quantity(r, "peak_torque_Nm") > threshold]
        above_braked = [r for r in records if point_quantity(r, "peak_torque_braked_Nm") > threshold]
        summary["assistance"] = {
            "threshold_Nm": threshold,
            "rim_force_N": sweep.assistance.rim_force_N,
            "rim_radius_m": sweep.assistance.rim_radius_m,
            "rim_force_source": sweep.assistance.rim_force_source,
            "rim_radius_source": sweep.assistance.rim_radius_source,
            "quantity": "peak_torque_Nm",
            "n_above": len(above),
            "n_above_braked": len(above_braked),
            "points_above": [{"point": r["point"], "values": r["values"],
                              "peak_torque_Nm": point_quantity(r, "peak_torque_Nm")} for r in above],
            "crossings": threshold_crossings(sweep, records, design, "peak_torque_Nm", threshold),
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
