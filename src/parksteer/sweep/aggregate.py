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
import tempfile
from array import array
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..parameters import Parameters
from ..tables import StreamedList, format_number, write_csv_rows
from .declaration import Sweep
from .design import SweepError
from .keys import parameter_bounds
from .design import base_value

# Relative tolerance for "this grid value is the base car's value".
ON_DESIGN_RTOL = 1e-3
SUMMARY_MERITS = ("peak_torque_Nm", "plateau_torque_Nm", "lock_torque_Nm", "reversal_drop_Nm")


def _batch_records(path) -> list[dict[str, Any]]:
    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    return doc["records"] if "records" in doc else [doc]  # a batch file holds its points' records


def read_points(paths, sweep: Sweep) -> list[dict[str, Any]]:
    """Point records (JSON files written by run_point, or batch files written by run_batch) in the sweep's order,
    each given its index there, all in memory (gather_points streams them)."""
    records = [record for path in paths for record in _batch_records(path)]
    for record in records:
        point = sweep.find(record["point"])
        record["index"] = point.index if point is not None else -1
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
        collector = _SliceCollector(sweep, held, quantities)
        for position, record in enumerate(records):
            collector.add(record, record.get("index", position))
        return collector.finish()


class _SliceCollector:
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
        columns["panel"].append(_nan(values.get(spec.panels)) if spec.panels else math.nan)
        columns["x"].append(_nan(values.get(spec.x)))
        columns["y"].append(_nan(values.get(spec.y)))
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
        design_point.update(point=found[0]["point"], **_merits_of(found[0]),
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


# ---------------------------------------------------------------------------- gathering, streamed


@dataclass
class Totals:
    """What the summary and the maps take from every record of a sweep, counted one record at a time."""

    threshold_Nm: float | None
    n_points: int = 0
    first_index: int = -1
    effects: list = field(default_factory=list)
    braked_method: str = ""
    peak_range_Nm: tuple = ()
    map_range: dict = field(default_factory=dict)  # map quantity -> (nanmin, nanmax) over every record
    keep_above: bool = True  # False: the points above the threshold are counted only (gather_points spills them)
    points_above: list = field(default_factory=list)  # (index, entry) of each point above the threshold
    above: Iterable | None = None  # or their entries in the sweep's order, read once (from gather_points' spill)
    n_above: int = 0
    n_above_braked: int = 0

    def add(self, record: dict) -> None:
        self.n_points += 1
        if self.first_index < 0 or record["index"] < self.first_index:
            self.first_index = record["index"]
            self.effects, self.braked_method = record["effects"], record["braked"]["method"]
        peak = point_quantity(record, "peak_torque_Nm")
        self.peak_range_Nm = (min(self.peak_range_Nm[0], peak), max(self.peak_range_Nm[1], peak)) \
            if self.peak_range_Nm else (peak, peak)
        for quantity, (low, high) in list(self.map_range.items()):
            value = point_quantity(record, quantity)
            if not math.isnan(value):
                self.map_range[quantity] = (min(low, value), max(high, value))
        if self.threshold_Nm is not None:
            if peak > self.threshold_Nm:
                self.n_above += 1
                if self.keep_above:
                    self.points_above.append((record["index"], above_entry(record, peak)))
            if point_quantity(record, "peak_torque_braked_Nm") > self.threshold_Nm:
                self.n_above_braked += 1

    def points_above_in_order(self) -> list | StreamedList:
        """The summary's entries of the points above the threshold, in the sweep's order."""
        if self.above is not None:
            return StreamedList(self.above)
        return [entry for _, entry in sorted(self.points_above, key=lambda item: item[0])]

    @classmethod
    def of(cls, records: list[dict], threshold_Nm: float | None, map_quantity: str | None = None) -> Totals:
        totals = cls(threshold_Nm, map_range={map_quantity: (math.inf, -math.inf)} if map_quantity else {})
        for record in records:
            totals.add(record)
        return totals


def above_entry(record: dict, peak_Nm: float) -> dict[str, Any]:
    """A point's entry in the summary's list of the points above the assistance threshold."""
    return {"point": record["point"], "values": record["values"], "peak_torque_Nm": peak_Nm}


def _row(keys: list[str], record: dict, threshold_Nm: float | None) -> tuple[str, dict[str, str], str]:
    """A record's row of the sweep table (as sweep_table and write_csv give it), in three parts: the cells before
    the share columns, the share cells by merit name, the cells after them."""
    head = [record["point"], format_number(record["index"])]
    head += [format_number(_nan(record["values"].get(key))) for key in keys]
    head += [format_number(point_quantity(record, q)) for q in SUMMARY_MERITS]
    shares = {k: format_number(_nan(v)) for k, v in record["merits"].items() if k.startswith("share_contrib_")}
    peak, peak_braked = point_quantity(record, "peak_torque_Nm"), point_quantity(record, "peak_torque_braked_Nm")
    tail = [format_number(_nan(record["merits"]["sliding_start_rack_m"])),
            format_number(point_quantity(record, "plateau_torque_braked_Nm")), format_number(peak_braked),
            format_number(_nan(record["braked"]["factor"])), format_number(_nan(record["braked"]["ground_offset_m"]))]
    if threshold_Nm is not None:
        tail += [format_number(int(peak > threshold_Nm)), format_number(int(peak_braked > threshold_Nm))]
    return ",".join(head), shares, ",".join(tail)


@dataclass
class Gathered:
    """What gather_points keeps of a sweep's records: those on a line through the design point along one key
    (the design point, the sensitivities; full records, in the sweep's order), the map's slice and the totals."""

    records: list[dict[str, Any]]
    map_slice: MapSlice | None
    totals: Totals


@contextmanager
def gather_points(paths, sweep: Sweep, params: Parameters, out_csv: str | Path, header, threshold_Nm: float | None
                  ) -> Iterator[Gathered]:
    """Read the point or batch files `paths` one at a time and write the sweep's table (the file sweep_table and
    write_csv give) to `out_csv`: each record's row goes to a scratch file as it is read, the rows are then
    copied in the sweep's order under the lines header(totals) gives. Yield what the summary and the maps read
    (:class:`Gathered`); the totals' list of the points above the threshold comes from a second scratch file,
    written in the sweep's order as the rows are copied, and can be read (written: tables.write_json) only
    within this context.

    A record's index in the sweep is found from its values and checked against its id (Sweep.locate), so the
    sweep may be loaded without its expansion (load_sweep(expand=False)): no point is regenerated unless one is
    missing (to name it). Memory: an 8-byte offset per point, the lines' records (a few per axis value), the map
    slice (7 numbers a point of it) and the batch file being read, whatever the number of points."""
    design = design_values(sweep, params)
    keys = sweep.keys
    design_fixed = {k: d["nearest"] for k, d in design.items()}
    spec = sweep.map
    collector = _SliceCollector(sweep, map_held(sweep, design), [spec.quantity, "peak_torque_Nm"]) if spec else None
    totals = Totals(threshold_Nm, map_range={spec.quantity: (math.inf, -math.inf)} if spec else {}, keep_above=False)
    n = sweep.n_points
    offsets = np.full(n, -1, dtype=np.int64)
    first_share: dict[str, tuple[int, int]] = {}  # merit name -> (index, position) where it first shows
    kept, unknown = [], []
    folder = Path(out_csv).parent or None
    end = 0  # of the spill, in bytes (a binary file: no text-mode tell() per record)
    with tempfile.TemporaryFile("w+b", dir=folder) as spill, \
            tempfile.TemporaryFile("w+", encoding="utf-8", dir=folder) as above:
        for path in paths:
            for record in _batch_records(path):
                index = sweep.locate(record["point"], record["values"])
                if index < 0:
                    unknown.append(record["point"])
                    continue
                if offsets[index] >= 0:
                    raise SweepError(f"{path}: point {record['point']} was gathered from another file already")
                record["index"] = index
                head, shares, tail = _row(keys, record, threshold_Nm)
                for position, name in enumerate(shares):
                    if name not in first_share or first_share[name] > (index, position):
                        first_share[name] = (index, position)
                # the row's parts, and after a tab (never in JSON text) the point's entry if above the threshold
                peak = point_quantity(record, "peak_torque_Nm")
                entry = "\t" + json.dumps(above_entry(record, peak)) \
                    if threshold_Nm is not None and peak > threshold_Nm else ""
                offsets[index] = end
                end += spill.write((json.dumps([head, shares, tail]) + entry + "\n").encode())
                totals.add(record)
                if sum(record["values"].get(k) != v for k, v in design_fixed.items()) <= 1:
                    kept.append(record)
                if collector is not None:
                    collector.add(record, index)
        missing = np.flatnonzero(offsets < 0)
        if len(missing) or unknown:
            first = sorted(sweep.id_at(int(i)) for i in missing) or sorted(unknown)
            raise SweepError(f"{sweep.path}: point files do not match the sweep (first difference: {first[0]})")
        shares = sorted(first_share, key=first_share.get)
        names = ["point", "index", *(column_name(k) for k in keys), *SUMMARY_MERITS,
                 *(name.replace("share_contrib_", "share_").removesuffix("_Nm") for name in shares),
                 "sliding_start_rack_m", "plateau_torque_braked_Nm", "peak_torque_braked_Nm", "braked_factor",
                 "ground_offset_m", *(("needs_assistance", "needs_assistance_braked") if threshold_Nm is not None
                                      else ())]
        nan = format_number(math.nan)

        def rows():
            for offset in offsets:
                spill.seek(int(offset))
                row, _, entry = spill.readline().decode().rstrip("\n").partition("\t")
                if entry:
                    above.write(entry + "\n")
                head, cells, tail = json.loads(row)
                yield ",".join([head, *(cells.get(name, nan) for name in shares), tail])

        write_csv_rows(out_csv, names, rows(), n, header(totals))
        above.seek(0)
        totals.above = (json.loads(line) for line in above)
        yield Gathered(sorted(kept, key=lambda r: r["index"]), collector.finish() if collector else None, totals)
