"""Readers of measurement formats, one module each, found through :data:`READERS` (as scipy.integrate finds its
solvers through METHODS). Adding a format is one module with a class following :class:`~.base.Reader` and one
entry in the table.

- :mod:`.native_csv`: the native format (data/measurements/README.md);
- :mod:`.logger_csv`: a logger's or spreadsheet's text export (own names, units, dialect);
- :mod:`.mdf`: ASAM MDF through the optional asammdf;
- :mod:`.matlab`: MATLAB MAT-files (level 5) through scipy.io;
- :mod:`.can_log`: raw CAN logs (candump, ASC, BLF, TRC, MDF4 bus logging), decoded with a DBC.
"""

from __future__ import annotations

from .base import SNIFF_BYTES, Reader, Record, Source
from .can_log import CanLogReader
from .logger_csv import LoggerCsvReader
from .matlab import MatlabReader
from .mdf import MdfReader
from .native_csv import NativeCsvReader

# Asked in this order; the first whose sniff accepts a file reads it (the logger CSV reader accepts any file).
READERS: dict[str, type[Reader]] = {
    "can_log": CanLogReader,
    "mdf": MdfReader,
    "matlab": MatlabReader,
    "native_csv": NativeCsvReader,
    "logger_csv": LoggerCsvReader,
}


def reader_for(raw: bytes) -> Reader:
    """The reader of a file whose bytes are `raw`."""
    head = raw[:SNIFF_BYTES]
    for reader in READERS.values():
        if reader().sniff(head):
            return reader()
    raise AssertionError("the logger CSV reader accepts every file")  # READERS ends with it


__all__ = ["READERS", "Reader", "Record", "Source", "reader_for"]
