"""The ASAM MDF reader (parksteer.measure.readers.mdf): channels with their units and own time stamps."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure.readers import READERS, reader_for
from parksteer.measure.readers.mdf import MdfReader


def _mdf_bytes(tmp_path: Path, version: str = "4.10") -> bytes:
    asammdf = pytest.importorskip("asammdf")
    t50, t100 = np.arange(100) * 0.02, np.arange(200) * 0.01
    mdf = asammdf.MDF(version=version)
    mdf.append([asammdf.Signal(np.sin(t50), t50, name="SteerTorque", unit="N*m")])
    mdf.append([asammdf.Signal(1000 * np.cos(t100), t100, name="RackPos", unit="mm")])
    path = Path(mdf.save(tmp_path / "log", overwrite=True))
    mdf.close()
    return path.read_bytes()


@pytest.mark.parametrize("version", ["4.10", "3.30"])
def test_channels_keep_their_units_and_their_own_time_stamps(tmp_path, version):
    """Two channel groups at 50 and 100 Hz: each channel with its unit, samples and time stamps; the master
    channels are not channels; no shared time base; the format named in the metadata."""
    raw = _mdf_bytes(tmp_path, version)
    assert MdfReader().sniff(raw[:64])
    record = MdfReader().read(raw, tmp_path / "log.mf4")
    by_name = {s.name: s for s in record.sources}
    assert set(by_name) == {"SteerTorque", "RackPos"}
    assert by_name["RackPos"].unit == "mm" and len(by_name["RackPos"].timestamps) == 200
    assert np.allclose(by_name["SteerTorque"].values, np.sin(np.arange(100) * 0.02))
    assert not record.shared_time_base and not record.is_text
    assert record.metadata == {"format": "ASAM MDF"}


def test_asammdf_is_imported_only_to_read_an_mdf_file(tmp_path):
    """The optional dependency stays out of a text read: reading a CSV through the table imports no asammdf."""
    import subprocess

    path = tmp_path / "t.csv"
    path.write_text("time_s,rack_m\n0,0\n1,0.01\n", encoding="utf-8")
    code = ("import sys; from pathlib import Path; from parksteer.measure.readers import reader_for; "
            f"raw = Path({str(path)!r}).read_bytes(); reader_for(raw).read(raw, Path('t.csv')); "
            "print('asammdf' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False"


def test_a_damaged_file_is_refused_in_one_line(tmp_path):
    """MDF magic and nothing sound after it: 'cannot read as ASAM MDF' naming the file."""
    pytest.importorskip("asammdf")
    with pytest.raises(UsageError, match=r"bad\.mf4: cannot read as ASAM MDF"):
        MdfReader().read(b"MDF     4.10    " + bytes(48), Path("bad.mf4"))


def test_the_table_finds_the_reader_of_each_format(tmp_path):
    """READERS in order (the bus-log reader only for a file given with its bus): raw CAN logs by their first
    lines, MDF by its magic, the native format by its header, anything else the logger reader."""
    assert list(READERS) == ["bus_log", "can_log", "mdf", "matlab", "native_csv", "logger_csv"]
    assert reader_for(b"(1700000000.000000) can0 09F#0011223344556677\n").name == "CAN bus log"
    assert reader_for(b"LOGG\x90\x00\x00\x00").name == "CAN bus log"
    assert reader_for(b"MDF     4.10    ").name == "ASAM MDF"
    assert reader_for(b"time_s,rack_m\n0,0\n").name == "native CSV"
    assert reader_for(b"Time;RackPos\ns;mm\n").name == "logger CSV"
