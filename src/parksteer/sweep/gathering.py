"""Gathering a sweep's records streamed: the table written row by row in the sweep's order, and kept only what
the summary and the maps read (:func:`gather_points`), whatever the number of points."""

from __future__ import annotations

import json
import math
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..parameters import Parameters
from ..tables import format_number, write_csv_rows
from .aggregate import MapSlice, SliceCollector, design_values, map_held
from .declaration import Sweep
from .design import SweepError
from .records import SUMMARY_MERITS, batch_records, column_name, point_quantity, table_row
from .totals import Totals, above_entry


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
    collector = SliceCollector(sweep, map_held(sweep, design), [spec.quantity, "peak_torque_Nm"]) if spec else None
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
            for record in batch_records(path):
                index = sweep.locate(record["point"], record["values"])
                if index < 0:
                    unknown.append(record["point"])
                    continue
                if offsets[index] >= 0:
                    raise SweepError(f"{path}: point {record['point']} was gathered from another file already")
                record["index"] = index
                head, shares, tail = table_row(keys, record, threshold_Nm)
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
