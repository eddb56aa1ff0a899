"""A sweep's point records: reading them from point and batch files, their figures of merit, and their rows of
the sweep table (figures/sweep_<name>.csv)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..tables import format_number
from .declaration import Sweep
from .keys import parameter_bounds


SUMMARY_MERITS = ("peak_torque_Nm", "plateau_torque_Nm", "lock_torque_Nm", "reversal_drop_Nm")


def batch_records(path) -> list[dict[str, Any]]:
    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    return doc["records"] if "records" in doc else [doc]  # a batch file holds its points' records


def read_points(paths, sweep: Sweep) -> list[dict[str, Any]]:
    """Point records (JSON files written by run_point, or batch files written by run_batch) in the sweep's order,
    each given its index there, all in memory (gather_points streams them)."""
    records = [record for path in paths for record in batch_records(path)]
    for record in records:
        point = sweep.find(record["point"])
        record["index"] = point.index if point is not None else -1
    return sorted(records, key=lambda r: r["index"])


def as_float(x) -> float:
    return math.nan if x is None else float(x)


def column_name(key: str) -> str:
    unit = parameter_bounds(key)[3]
    return key if unit == "1" else f"{key}_{unit.replace(' ', '').replace('/', '_per_')}"


def point_quantity(record: dict, quantity: str) -> float:
    """A figure of merit of a record; the braked ones are named <quantity>_braked_Nm."""
    if quantity.endswith("_braked_Nm"):
        return as_float(record["braked"][quantity.replace("_braked_Nm", "_Nm")])
    return as_float(record["merits"][quantity])


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
        cols[column_name(key)] = np.array([as_float(r["values"].get(key)) for r in records])
    for q in SUMMARY_MERITS:
        cols[q] = np.array([point_quantity(r, q) for r in records])
    for name in share_names(records):
        short = name.replace("share_contrib_", "share_").removesuffix("_Nm")
        cols[short] = np.array([as_float(r["merits"].get(name)) for r in records])
    cols["sliding_start_rack_m"] = np.array([as_float(r["merits"]["sliding_start_rack_m"]) for r in records])
    cols["plateau_torque_braked_Nm"] = np.array([point_quantity(r, "plateau_torque_braked_Nm") for r in records])
    cols["peak_torque_braked_Nm"] = np.array([point_quantity(r, "peak_torque_braked_Nm") for r in records])
    cols["braked_factor"] = np.array([as_float(r["braked"]["factor"]) for r in records])
    cols["ground_offset_m"] = np.array([as_float(r["braked"]["ground_offset_m"]) for r in records])
    if threshold_Nm is not None:
        cols["needs_assistance"] = (cols["peak_torque_Nm"] > threshold_Nm).astype(int)
        cols["needs_assistance_braked"] = (cols["peak_torque_braked_Nm"] > threshold_Nm).astype(int)
    return cols


def merits_of(record: dict) -> dict[str, float]:
    out = {q: point_quantity(record, q) for q in SUMMARY_MERITS}
    out["plateau_torque_braked_Nm"] = point_quantity(record, "plateau_torque_braked_Nm")
    out["peak_torque_braked_Nm"] = point_quantity(record, "peak_torque_braked_Nm")
    out["tyre_share_Nm"] = out["plateau_torque_Nm"] * as_float(record["merits"].get("share_contrib_tyre_friction_Nm"))
    out["braked_factor"] = as_float(record["braked"]["factor"])
    out["rig_theory_plateau_torque_braked_Nm"] = as_float(record["braked"].get("rig_theory_plateau_torque_Nm"))
    out["rig_theory_braked_factor"] = as_float(record["braked"].get("rig_theory_factor"))
    out["ground_offset_m"] = as_float(record["braked"]["ground_offset_m"])
    return out


def table_row(keys: list[str], record: dict, threshold_Nm: float | None) -> tuple[str, dict[str, str], str]:
    """A record's row of the sweep table (as sweep_table and write_csv give it), in three parts: the cells before
    the share columns, the share cells by merit name, the cells after them."""
    head = [record["point"], format_number(record["index"])]
    head += [format_number(as_float(record["values"].get(key))) for key in keys]
    head += [format_number(point_quantity(record, q)) for q in SUMMARY_MERITS]
    shares = {k: format_number(as_float(v)) for k, v in record["merits"].items() if k.startswith("share_contrib_")}
    peak, peak_braked = point_quantity(record, "peak_torque_Nm"), point_quantity(record, "peak_torque_braked_Nm")
    tail = [format_number(as_float(record["merits"]["sliding_start_rack_m"])),
            format_number(point_quantity(record, "plateau_torque_braked_Nm")), format_number(peak_braked),
            format_number(as_float(record["braked"]["factor"])), format_number(as_float(record["braked"]["ground_offset_m"]))]
    if threshold_Nm is not None:
        tail += [format_number(int(peak > threshold_Nm)), format_number(int(peak_braked > threshold_Nm))]
    return ",".join(head), shares, ",".join(tail)
