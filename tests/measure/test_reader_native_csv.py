"""The native CSV reader (parksteer.measure.readers.native_csv): which files it claims and what it reads."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure.readers.native_csv import NativeCsvReader

EXAMPLE = Path(__file__).resolve().parents[2] / "data" / "measurements" / "example_unladen.csv"


def test_claims_a_native_header_and_no_logger_export():
    """Sniff: native names over numbers is the native format; a logger name, a units row or binary data is not."""
    reader = NativeCsvReader()
    assert reader.sniff(b"# case: unladen\ntime_s,rack_m,handwheel_torque_Nm\n0,0,0.1\n")
    assert reader.sniff(b'\xef\xbb\xbf"time_s";"rack_m"\r\n"0";"0,001"\r\n')  # BOM, semicolons, quoted cells
    assert not reader.sniff(b"Time;RackPos;SteerTorque\n0;0;0\n")
    assert not reader.sniff(b"time_s,rack_m\ns,mm\n0,1\n")  # a units row is the logger reader's
    assert not reader.sniff(b"MDF     4.10    " + bytes(48))


def test_reads_the_example_record_column_by_column_on_its_own_time_base():
    """The shipped example: its six native columns with no unit (SI by name), its metadata, one line number per
    data row, and a column's samples exactly the numbers written in the file."""
    raw = EXAMPLE.read_bytes()
    record = NativeCsvReader().read(raw, EXAMPLE)
    names = [s.name for s in record.sources]
    assert names[:3] == ["time_s", "rack_m", "handwheel_torque_Nm"]
    assert all(s.unit is None for s in record.sources)
    assert record.metadata["case"] == "unladen" and record.shared_time_base and record.is_text
    rows = [line for line in raw.decode().splitlines() if line and not line.startswith("#")][1:]
    assert len(record.line_numbers) == len(rows) == 901
    rack = record.samples(record.sources[1])
    assert np.array_equal(rack, [float(row.split(",")[1]) for row in rows])


def test_a_bad_cell_is_refused_naming_column_row_and_line(tmp_path):
    """A word in a number cell: one line naming file, column, row and file line (read when the column is used)."""
    path = tmp_path / "bad.csv"
    raw = b"# case: unladen\ntime_s,rack_m\n0,0\n0.1,x\n"
    record = NativeCsvReader().read(raw, path)
    with pytest.raises(UsageError, match=r"bad\.csv: column 'rack_m', row 2 \(line 4\): 'x' is not a number"):
        record.samples(record.sources[1])
