"""A raw CAN log decoded with the DBC its channel map carries (``--dbc``, ``--bus``): the table's entry for a file
given with a bus. Any file so given is read as a bus log (an MDF4 bus logging file included, which the MDF reader
would otherwise take), and one that is not a CAN log this tool reads is refused in one line
(:func:`~.can_log.read_bus_log`)."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

from .base import Record
from .can_log import CanLogReader, read_bus_log


class BusLogReader:
    """Reads a CAN log with the DBC and signals of `channels` (a :class:`~.can_log.BusMap`)."""

    name: ClassVar[str] = "CAN bus log, decoded with its DBC"
    suffixes: ClassVar[tuple[str, ...]] = CanLogReader.suffixes
    decodes_with_bus: ClassVar[bool] = True

    def __init__(self, channels) -> None:
        self.channels = channels

    def sniff(self, head: bytes) -> bool:
        return True  # given a bus, every file is read as a bus log or refused as none

    def read(self, raw: bytes, where: Path) -> Record:
        return read_bus_log(raw, where, self.channels)
