"""The logger CSV reader (parksteer.measure.readers.logger_csv): a logger's own names, units and dialect."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure.readers.logger_csv import LoggerCsvReader


def test_units_come_from_brackets_or_the_units_row():
    """'RackPos [mm]' and a units row under the header both give a channel's unit; a decimal comma reads."""
    raw = "Time;RackPos [mm];SteerTorque\ns;;N*m\n0,0;1,5;0,25\n0,02;2,5;0,5\n".encode()
    record = LoggerCsvReader().read(raw, "log.csv")
    assert [(s.name, s.unit) for s in record.sources] == [("Time", "s"), ("RackPos", "mm"), ("SteerTorque", "N*m")]
    assert np.array_equal(record.samples(record.sources[1]), [1.5, 2.5])
    assert record.line_numbers == [3, 4]


def test_quoted_header_and_numbers_lose_their_quotes():
    """A spreadsheet's quoted cells ("time_s", "0.01") read as the bare names and numbers; a delimiter inside
    quotes stays in its cell."""
    raw = b'"Time [s]","Rack, left [mm]"\n"0.00","1.5"\n"0.01", "2.5"\n'
    record = LoggerCsvReader().read(raw, "q.csv")
    assert [(s.name, s.unit) for s in record.sources] == [("Time", "s"), ("Rack, left", "mm")]
    assert np.array_equal(record.samples(record.sources[0]), [0.0, 0.01])
    assert np.array_equal(record.samples(record.sources[1]), [1.5, 2.5])


def test_accepts_any_file_and_refuses_what_is_not_text():
    """The reader of last resort: its sniff accepts anything; bytes that are not UTF-8 are refused by position."""
    reader = LoggerCsvReader()
    assert reader.sniff(b"\x00\xff") and reader.sniff(b"")
    with pytest.raises(UsageError, match=r"x\.csv: not UTF-8 text \(byte 1\)"):
        reader.read(b"a\xff", "x.csv")


def test_header_and_units_row_disagreeing_is_refused():
    """A unit in brackets and another in the units row: one line naming the column and both units."""
    with pytest.raises(UsageError, match=r"column 'RackPos': header says \[mm\] but the units row says 'm'"):
        LoggerCsvReader().read(b"Time;RackPos[mm]\ns;m\n0;1\n", "c.csv")
