"""Readers of measurement formats, one module each, found through :data:`READERS` (as scipy.integrate finds its
solvers through METHODS). Adding a format is one module with a class following :class:`~.base.Reader` and one
entry in the table.

- :mod:`.native_csv`: the native format (data/measurements/README.md);
- :mod:`.logger_csv`: a logger's or spreadsheet's text export (own names, units, dialect);
- :mod:`.mdf`: ASAM MDF through the optional asammdf;
- :mod:`.matlab`: MATLAB MAT-files (level 5) through scipy.io;
- :mod:`.bus_log`: a raw CAN log given with its bus (``--dbc``, ``--bus``), decoded with its DBC;
- :mod:`.can_log`: raw CAN logs (candump, ASC, BLF, TRC, MDF4 bus logging): their decoding, and the refusal of one
  given without a DBC.
"""

from __future__ import annotations

from .base import SNIFF_BYTES, Reader, Record, Source
from .bus_log import BusLogReader
from .can_log import CanLogReader
from .logger_csv import LoggerCsvReader
from .matlab import MatlabReader
from .mdf import MdfReader
from .native_csv import NativeCsvReader

# Asked in this order; the first whose sniff accepts a file reads it (the logger CSV reader accepts any file). A
# reader that `decodes_with_bus` is asked alone when the channel map carries a bus, and never otherwise.
READERS: dict[str, type[Reader]] = {
    "bus_log": BusLogReader,
    "can_log": CanLogReader,
    "mdf": MdfReader,
    "matlab": MatlabReader,
    "native_csv": NativeCsvReader,
    "logger_csv": LoggerCsvReader,
}


def reader_for(raw: bytes, channels=None) -> Reader:
    """The reader of a file whose bytes are `raw`, read with the channel map `channels` (a bus log's carries its
    bus: :class:`~.can_log.BusMap`)."""
    head = raw[:SNIFF_BYTES]
    bus = getattr(channels, "bus", None) is not None
    for reader in READERS.values():
        if getattr(reader, "decodes_with_bus", False) != bus:
            continue
        found = reader(channels) if bus else reader()
        if found.sniff(head):
            return found
    raise AssertionError("the logger CSV reader accepts every file")  # READERS ends with it


__all__ = ["READERS", "Reader", "Record", "Source", "reader_for"]
