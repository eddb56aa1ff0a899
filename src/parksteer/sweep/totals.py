"""What a sweep's summary and maps take from every record, counted one record at a time (:class:`Totals`)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from ..tables import StreamedList
from .records import point_quantity


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
