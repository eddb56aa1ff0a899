"""The MATLAB MAT-file reader (parksteer.measure.readers.matlab): one file and one row of the READERS table, and a
MAT export of a record reads as the same record as its text export."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from scipy.io import savemat

from parksteer.errors import UsageError
from parksteer.measure.importers import load_record
from parksteer.measure.readers import READERS, reader_for
from parksteer.measure.readers.matlab import MatlabReader

EXAMPLE = Path(__file__).resolve().parents[2] / "data" / "measurements" / "example_unladen.csv"


def _mat(path: Path, **variables) -> Path:
    savemat(path, variables)
    return path


def test_a_mat_export_reads_as_the_same_record_as_the_text_file(tmp_path):
    """The example record's channels saved under a logger's names (time in s, rack in mm, torque in N m) and
    read through a channel map: the same samples in SI as the native CSV, to the rounding of the mm conversion."""
    native = load_record(EXAMPLE)
    c = native.columns
    mat = _mat(tmp_path / "run.mat", Time=c["time_s"], RackPos=1000 * c["rack_m"],
               SteerTorque=c["handwheel_torque_Nm"])
    got = load_record(mat, "RackPos[mm]=rack_m,SteerTorque[N*m]=handwheel_torque_Nm", case="unladen",
                      surface="ground")
    assert reader_for(mat.read_bytes()).name == "MATLAB MAT-file"
    np.testing.assert_array_equal(got.columns["time_s"], c["time_s"])
    np.testing.assert_allclose(got.columns["rack_m"], c["rack_m"], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(got.columns["handwheel_torque_Nm"], c["handwheel_torque_Nm"])


def test_a_mat_file_without_a_time_vector_is_refused_naming_its_vectors(tmp_path):
    """No variable named like time: one line naming the file and the vectors it has."""
    mat = _mat(tmp_path / "run.mat", RackPos=np.arange(5.0), SteerTorque=np.ones(5))
    with pytest.raises(UsageError, match=r"run\.mat: no time vector .*its vectors: RackPos, SteerTorque"):
        MatlabReader().read(mat.read_bytes(), mat)


def test_a_version_7_3_or_damaged_file_is_refused_in_one_line(tmp_path):
    """An HDF5 (-v7.3) MAT-file is named as such with the way out; a damaged level-5 file: 'cannot read as'."""
    with pytest.raises(UsageError, match=r"new\.mat: cannot read as MATLAB MAT-file \(version 7\.3.*-v7\)"):
        MatlabReader().read(b"MATLAB 7.3 MAT-file, Platform: GLNXA64" + bytes(100), Path("new.mat"))
    buffer = io.BytesIO()
    savemat(buffer, {"t": np.arange(4.0)})
    with pytest.raises(UsageError, match=r"bad\.mat: cannot read as MATLAB MAT-file") as caught:
        MatlabReader().read(buffer.getvalue()[:150], Path("bad.mat"))
    assert "\n" not in str(caught.value)


def test_the_reader_is_one_row_of_the_table():
    """Adding the format took one module and one entry of READERS: it sits after MDF, before the text readers."""
    assert list(READERS) == ["bus_log", "can_log", "mdf", "matlab", "native_csv", "logger_csv"]
    assert READERS["matlab"] is MatlabReader
