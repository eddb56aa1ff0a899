"""The import layer (parksteer.measure.importers.load_record): logger exports, MDF, the angle-only record, the
unit conversion, the plausibility checks and a corpus of malformed inputs, each refused in one line."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from parksteer.cli import main
from parksteer.errors import UsageError
from parksteer.measure.importers import load_rack_drive, load_record
from parksteer.measure.units import from_si, to_si
from parksteer.measure.text_table import read_table

CORPUS = Path(__file__).parent / "corpus"
DAQ_MAP = "RackPos[mm]=rack_m,SteerTorque[N*m]=handwheel_torque_Nm,SWA[deg]=handwheel_angle_rad"
FILL = ["--case", "unladen", "--surface", "ground"]


def _comma(value: float, decimals: int) -> str:
    return f"{value:.{decimals}f}".replace(".", ",")


@pytest.fixture(scope="module")
def cycle(params):
    """The unladen Section 4 cycle simulated by the model at 100 Hz (the paper's five effects)."""
    from parksteer.model.numeric.simulate import simulate

    c = simulate("unladen", params=params, output_dt_s=0.01).columns
    return {k: np.asarray(c[k]) for k in ("time_s", "rack_m", "handwheel_torque_Nm", "handwheel_angle_rad")}


@pytest.fixture(scope="module")
def daq_file(cycle, tmp_path_factory):
    """The cycle at 50 Hz as a DAQ exports it: semicolons, decimal comma, units row, BOM, CRLF, an extra channel;
    rack to 1e-4 mm, torque to 1e-4 N m, angle to 1e-4 deg."""
    c = {k: v[::2] for k, v in cycle.items()}
    lines = ["Time;RackPos;SteerTorque;SWA;VehSpeed", "s;mm;N*m;deg;km/h"]
    for t, x, T, a in zip(c["time_s"], c["rack_m"], c["handwheel_torque_Nm"], c["handwheel_angle_rad"]):
        lines.append(";".join([_comma(t, 3), _comma(1000 * x, 4), _comma(T, 4), _comma(math.degrees(a), 4), "0,0"]))
    path = tmp_path_factory.mktemp("daq") / "daq_export.csv"
    path.write_bytes(("\ufeff" + "\r\n".join(lines) + "\r\n").encode("utf-8"))
    return path, c


def test_daq_export_goes_through_compare_in_one_command(daq_file, capsys, tmp_path):
    """A DAQ export (Time;RackPos;SteerTorque;SWA;VehSpeed, units row, decimal comma, BOM, CRLF) of the simulated
    cycle is compared with the model by one command with no hand edit; the model fits its own cycle (RMS well
    under 0.5 N m) and the unknown channel is named in one note on stderr."""
    path, _ = daq_file
    plot = tmp_path / "compare.svg"
    assert main(["compare", str(path), "--map", DAQ_MAP, *FILL, "--json", "--plot", str(plot)]) == 0
    captured = capsys.readouterr()
    result = json.loads(captured.out)
    assert result["files"][0]["overall"]["rms"] < 0.5
    assert plot.exists()
    notes = [line for line in captured.err.splitlines() if "VehSpeed" in line]
    assert len(notes) == 1 and "ignored channel VehSpeed" in notes[0]


def test_daq_export_rack_and_angle_equal_the_simulation_to_the_export_rounding(daq_file, params):
    """Units converted by pint: mm to m and deg to rad give the simulated rack and angle back to the export's
    rounding (5e-5 mm, 5e-5 deg), on the record's own time base; the record says how its channels were mapped."""
    path, c = daq_file
    m = load_record(path, DAQ_MAP, case="unladen", surface="ground", params=params)
    assert np.max(np.abs(m.time_s - c["time_s"])) < 5e-4 + 1e-12
    assert np.max(np.abs(m.rack_m - c["rack_m"])) <= 5e-8 + 1e-12
    assert np.max(np.abs(m.columns["handwheel_angle_rad"] - c["handwheel_angle_rad"])) <= math.radians(5e-5) + 1e-12
    assert "RackPos[mm]=rack_m" in m.metadata["channel_map"]
    assert m.case == "unladen" and m.surface == "ground"


def test_angle_only_record_derives_the_rack_within_0_1_mm(cycle, params, tmp_path):
    """Physical fact: with no rack channel, handwheel angle less column twist through the Hooke joint and the
    ratio gives the rack the model ran, within 0.1 mm over the whole cycle (the column damping left out is the
    remainder); the angle stays in the record as its own SI signal, and the metadata says the rack was derived."""
    c = {k: v[::2] for k, v in cycle.items()}
    lines = ["# case: unladen", "# surface: ground", "Time [s]\tSWA [deg]\tSteerTorque [Nm]"]
    for t, T, a in zip(c["time_s"], c["handwheel_torque_Nm"], c["handwheel_angle_rad"]):
        lines.append(f"{t:.3f}\t{math.degrees(a):.5f}\t{T:.4f}")
    path = tmp_path / "angle_only.tsv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    m = load_record(path, params=params)
    error = np.max(np.abs(m.rack_m - c["rack_m"]))
    assert error < 1e-4, f"derived rack off by {error * 1000:.3f} mm"
    assert np.max(np.abs(m.columns["handwheel_angle_rad"] - c["handwheel_angle_rad"])) < math.radians(1e-5)
    assert "column law" in m.metadata["rack_derived"]


@pytest.mark.parametrize("version", ["4.10", "3.30"])
def test_mdf_file_resampled_onto_the_torque_channels_time_base(cycle, params, tmp_path, version):
    """An MDF4 (and MDF3) file written by asammdf with torque and angle at 50 Hz and the rack at 100 Hz in its own
    channel group, each with its unit metadata (mm, deg, N*m): the record takes the torque channel's time base and
    the converted rack equals the simulated one."""
    asammdf = pytest.importorskip("asammdf")
    mdf = asammdf.MDF(version=version)
    t2 = cycle["time_s"][::2]
    mdf.append([asammdf.Signal(cycle["handwheel_torque_Nm"][::2], t2, name="SteerTorque", unit="N*m"),
                asammdf.Signal(np.degrees(cycle["handwheel_angle_rad"][::2]), t2, name="SWA", unit="deg")])
    mdf.append([asammdf.Signal(1000 * cycle["rack_m"], cycle["time_s"], name="RackPos", unit="mm")])
    path = Path(mdf.save(tmp_path / f"car_{version}", overwrite=True))
    mdf.close()
    m = load_record(path, "RackPos=rack_m,SteerTorque=handwheel_torque_Nm,SWA=handwheel_angle_rad",
                    case="unladen", surface="ground", params=params)
    assert m.n_samples == len(t2) and np.array_equal(m.time_s, t2)
    assert np.max(np.abs(m.rack_m - cycle["rack_m"][::2])) < 1e-9
    # the angle-only MDF: no rack channel, the rack derived as for a text file
    mdf = asammdf.MDF(version=version)
    mdf.append([asammdf.Signal(cycle["handwheel_torque_Nm"][::2], t2, name="SteerTorque", unit="Nm"),
                asammdf.Signal(np.degrees(cycle["handwheel_angle_rad"][::2]), t2, name="SWA", unit="deg")])
    path = Path(mdf.save(tmp_path / f"angle_{version}", overwrite=True))
    mdf.close()
    m = load_record(path, case="unladen", surface="ground", params=params)
    assert np.max(np.abs(m.rack_m - cycle["rack_m"][::2])) < 1e-4


def test_mdf_without_the_extra_names_the_extra(tmp_path, monkeypatch, params):
    """Without asammdf an MDF file is refused in one line that says how to install the optional extra."""
    monkeypatch.setitem(sys.modules, "asammdf", None)
    path = tmp_path / "log.mf4"
    path.write_bytes(b"MDF     4.10    " + bytes(48))
    with pytest.raises(UsageError, match=r"log\.mf4: .*pip install 'parksteer\[mdf\]'"):
        load_record(path, case="unladen", surface="ground", params=params)


def test_bracketed_units_map_by_alias_without_a_map(params, tmp_path):
    """Without --map, 'Rack[mm]' and 'Torque (N*m)' map by their known aliases, and native names map to
    themselves; a rack drive (time and rack only) reads through the same reader."""
    t = np.arange(100) * 0.05
    rack = 0.06 * np.sin(2 * np.pi * t / 5.0)
    torque = 8.0 * np.cos(2 * np.pi * t / 5.0)
    text = "# case: unladen\n# surface: ground\nTime[s],Rack[mm],Torque (N*m)\n" + "".join(
        f"{a:.3f},{1000 * b:.6f},{c:.6f}\n" for a, b, c in zip(t, rack, torque))
    path = tmp_path / "aliases.csv"
    path.write_text(text, encoding="utf-8")
    m = load_record(path, params=params)
    assert np.allclose(m.rack_m, rack, atol=1e-9)
    drive = tmp_path / "drive.csv"
    drive.write_text("\ufefftime_s,rack_m\r\n\r\n" + "".join(f"{a:.3f},{b:.7f}\r\n\r\n" for a, b in zip(t, rack)))
    assert np.allclose(load_rack_drive(drive, case="unladen", surface="ground", params=params).rack_m, rack, atol=1e-7)


# ----------------------------------------------------------------------------------------- malformed corpus

# (file in tests/measure/corpus, extra arguments, text the one-line error must contain, what it must name)
CORPUS_CASES = [
    ("empty.csv", [], "empty file (no header row)", None),
    ("header_only.csv", [], "no data rows after the header", None),
    ("ragged_row.csv", [], "row 2 (line 5): 4 fields where the header has 3", None),
    ("not_a_number.csv", [], "column 'handwheel_torque_Nm', row 3 (line 6): 'n/a' is not a number", None),
    ("nan_cell.csv", [], "column 'handwheel_torque_Nm', row 5 (line 8): 'nan' is not a finite number", None),
    ("blank_cell.csv", [], "column 'handwheel_torque_Nm', row 5 (line 8): empty cell", None),
    ("time_not_increasing.csv", [], "column 'time_s', row 11 (line 14): time 1.62 s does not increase", None),
    ("too_few_samples.csv", [], "30 samples; at least 50", None),
    ("rack_mm_as_metres.csv", [], "looks like millimetres given as m: give the unit, e.g. --map 'rack_m[mm]=rack_m'",
     None),
    ("rack_cm_as_metres.csv", [], "looks like centimetres given as m", None),
    ("rack_beyond_lock.csv", [], "column 'rack_m', row 21 (line 24): 0.0774118 m is beyond the car's lock", None),
    ("angle_degrees_as_radians.csv", [], "looks like degrees given as rad", None),
    ("torque_sign_flipped.csv", [], "negate one, e.g. --map 'handwheel_torque_Nm=-handwheel_torque_Nm'", None),
    ("angle_sign_flipped.csv", [], "handwheel angle and rack move against each other", None),
    ("unknown_case.csv", [], "unknown case 'unloaded'", None),
    ("unknown_surface.csv", [], "unknown surface 'ice'", None),
    ("no_case.csv", [], "the file names no case; add '# case: NAME' above the header or give --case", None),
    ("no_surface.csv", [], "the file names no surface", None),
    ("no_case.csv", ["--surface", "air_bearing", "--case", "unladen"], "the file says surface 'ground'", None),
    ("duplicate_column.csv", [], "column 'rack_m' appears twice in the header row", None),
    ("metadata_after_header.csv", [], "line 9: metadata line after the header row", None),
    ("metadata_twice.csv", [], "line 3: metadata key 'case' given twice", None),
    ("not_utf8.csv", [], "not UTF-8 text (byte 27)", None),
    ("offset_metadata_in_mm.csv", [], "metadata extra_offset_m = 44.5 looks like millimetres", None),
    ("daq.csv", ["--map", DAQ_MAP], "the file names no case", None),
    ("daq_no_units.csv", FILL, "channel 'Time' has no unit", None),
    ("daq_two_racks.csv", FILL, "channels 'Rack' and 'RackPos' could both be 'rack_m'", None),
    ("daq_units_row_short.csv", FILL, "units row (line 2): 3 fields where the header has 4", None),
    ("daq_header_unit_conflict.csv", FILL, "column 'RackPos': header says [mm] but the units row says 'm'", None),
    ("daq_no_rack_no_angle.csv", FILL, "no rack channel, and no handwheel angle and torque to derive it from", None),
    ("daq_no_time.csv", FILL, "no time channel (channels: Stamp, RackPos, SteerTorque)", None),
    ("daq_torque_flipped.csv", ["--map-file", str(CORPUS / "map_good.txt"), *FILL],
     "e.g. --map 'SteerTorque[N*m]=-handwheel_torque_Nm'", None),
    ("daq.csv", ["--map", "RackPos[furlongz]=rack_m", *FILL], "channel 'RackPos': unit 'furlongz' is not a unit pint "
     "knows", None),
    ("daq.csv", ["--map", "RackPos[N*m]=rack_m", *FILL], "channel 'RackPos': unit 'N*m' is not a unit of length", None),
    ("daq.csv", ["--map", "SWA[%]=handwheel_angle_rad", *FILL], "channel 'SWA': unit '%' is not an angle", None),
    ("daq.csv", ["--map", "RackPos[m]=rack_m", *FILL], "--map says [m] but the file says [mm]", None),
    ("daq.csv", ["--map", "Wheel[mm]=rack_m", *FILL], "--map names channel 'Wheel', which the file does not have",
     None),
    ("daq.csv", ["--map", "RackPos[mm]=rack_mm", *FILL], "unknown target 'rack_mm'", "--map"),
    ("daq.csv", ["--map", "RackPos[mm]", *FILL], "must read 'Source[unit]=target'", "--map"),
    ("daq.csv", ["--map", "RackPos[mm]=rack_m,Other[mm]=rack_m", *FILL], "both map to 'rack_m'", "--map"),
    ("daq.csv", ["--map-file", str(CORPUS / "map_bad_line.txt"), *FILL], "map_bad_line.txt: line 3", "map_bad_line"),
    ("daq.csv", ["--map-file", str(CORPUS / "no_such_map.txt"), *FILL], "no_such_map.txt: cannot read", "no_such_map"),
    ("broken.mf4", FILL, "MDF", None),
    ("no_such_file.csv", [], "no_such_file.csv: cannot read (No such file or directory)", None),
]


def _run(args: list[str], capsys) -> tuple[int, str]:
    status = main(args)
    return status, capsys.readouterr().err


def _one_clean_line(status: int, err: str, expected: str, names: str) -> None:
    assert status == 2
    assert "Traceback" not in err
    lines = [line for line in err.strip().splitlines() if ": note: " not in line]
    assert len(lines) == 1, err
    assert expected in lines[0], lines[0]
    assert names in lines[0], f"the message names {names}: {lines[0]}"


@pytest.mark.parametrize("name, extra, expected, names", CORPUS_CASES,
                         ids=[f"{c[0]}:{c[2][:30]}" for c in CORPUS_CASES])
def test_malformed_input_is_refused_in_one_line_and_writes_nothing(name, extra, expected, names, capsys, tmp_path):
    """Each malformed input of the corpus: exit status 2, one line on stderr with the expected text naming the
    file (or the map at fault), no traceback, no output written."""
    plot = tmp_path / "out.svg"
    status, err = _run(["compare", str(CORPUS / name), *extra, "--plot", str(plot)], capsys)
    _one_clean_line(status, err, expected, names or name)
    assert not plot.exists()


@pytest.mark.parametrize("name, expected", [
    ("rack_mm_as_metres.csv", "looks like millimetres given as m"),
    ("daq_no_time.csv", "no time channel"),
    ("torque_sign_flipped.csv", "negate one"),
])
def test_rack_drive_input_is_checked_like_a_measurement(name, expected, capsys, tmp_path):
    """simulate --rack-from reads through the same reader: the same refusals, nothing written."""
    out = tmp_path / "run.csv"
    status, err = _run(["simulate", "--case", "unladen", "--rack-from", str(CORPUS / name), "--out", str(out)], capsys)
    _one_clean_line(status, err, expected, name)
    assert not out.exists()


def test_large_record_names_the_row_of_a_bad_cell(capsys, tmp_path):
    """A 200 000-row record (generated here) with one bad cell near its end: refused naming that row and line."""
    n = 200_000
    t = np.arange(n) * 1e-3
    rows = [f"{a:.3f};{60 * math.sin(b / 3):.4f};{5 * math.cos(b / 3):.4f}" for a, b in zip(t, t)]
    rows[150_000] = rows[150_000].rsplit(";", 1)[0] + ";#REF!"
    path = tmp_path / "big.csv"
    path.write_text("# case: unladen\n# surface: ground\nTime;RackPos;SteerTorque\ns;mm;N*m\n" + "\n".join(rows))
    plot = tmp_path / "out.svg"
    status, err = _run(["compare", str(path), "--plot", str(plot)], capsys)
    _one_clean_line(status, err, "column 'SteerTorque', row 150001 (line 150005): '#REF!' is not a number", "big.csv")
    assert not plot.exists()


def test_the_corpus_holds_at_least_25_malformed_inputs():
    """Bookkeeping: the corpus is as large as promised (files and argument variants)."""
    assert len(CORPUS_CASES) >= 25
    assert all((CORPUS / name).exists() for name, *_ in CORPUS_CASES if not name.startswith("no_such"))


# ------------------------------------------------------------------------------------- property-based tests

UNITS = [("mm", "rack_m"), ("cm", "rack_m"), ("m", "rack_m"), ("in", "rack_m"), ("deg", "handwheel_angle_rad"),
         ("rad", "handwheel_angle_rad"), ("rev", "handwheel_angle_rad"), ("turn", "handwheel_angle_rad"), ("N*m", "handwheel_torque_Nm"),
         ("Nm", "handwheel_torque_Nm"), ("N*mm", "handwheel_torque_Nm"), ("kN*m", "handwheel_torque_Nm"),
         ("ms", "time_s"), ("min", "time_s"), ("kN", "load_left_N"), ("lbf", "load_left_N")]
# Any measured magnitude: zero, or normal floats far from underflow (a rack of 1e-300 m has no meaning).
FINITE = st.floats(min_value=-1e9, max_value=1e9, allow_nan=False, allow_infinity=False,
                   allow_subnormal=False).filter(lambda v: v == 0.0 or abs(v) > 1e-290)


@settings(max_examples=300, deadline=None, database=None)
@given(value=FINITE, unit=st.sampled_from(UNITS))
def test_conversion_to_si_and_back_is_the_identity(value, unit):
    """A value converted to SI and back is itself (to rounding: a few units in the last place)."""
    name, target = unit
    back = from_si(to_si(np.array([value]), name, target), name, target)[0]
    assert back == pytest.approx(value, rel=1e-15, abs=0.0)


@settings(max_examples=300, deadline=None, database=None)
@given(value=FINITE)
def test_millimetres_to_metres_is_division_by_1000_exactly(value):
    """mm -> m is value / 1000 to the last bit (pint's factor 0.001 would not be: 0.001 is not exact in binary)."""
    assert to_si(np.array([value]), "mm", "rack_m")[0] == value / 1000


CELLS = st.floats(allow_nan=False, allow_infinity=False, width=64)


@settings(max_examples=200, deadline=None, database=None)
@given(table=st.integers(2, 5).flatmap(lambda k: st.lists(st.lists(CELLS, min_size=k, max_size=k), min_size=1,
                                                            max_size=15)),
       delimiter=st.sampled_from([",", ";", "\t"]), decimal_comma=st.booleans(),
       ending=st.sampled_from(["\n", "\r\n", "\r"]), bom=st.booleans(), units=st.booleans(), blanks=st.booleans())
def test_any_finite_table_in_any_supported_dialect_reads_back_the_same_numbers(table, delimiter, decimal_comma,
                                                                               ending, bom, units, blanks):
    """Any finite table written with comma, semicolon or tab, a decimal point or comma (not with a comma
    delimiter), LF, CRLF or CR, with or without BOM, units row and blank lines reads back bit for bit."""
    decimal_comma = decimal_comma and delimiter != ","
    k = len(table[0])

    def cell(v: float) -> str:
        text = repr(v)
        return text.replace(".", ",") if decimal_comma else text

    lines = ["# case: unladen", delimiter.join(f"c{j}" for j in range(k))]
    if units:
        lines.append(delimiter.join(["s"] + ["mm"] * (k - 1)))
    for row in table:
        lines.append(delimiter.join(cell(v) for v in row))
        if blanks:
            lines.append("")
    text = ("\ufeff" if bom else "") + ending.join(lines) + ending
    read = read_table(text, "t.csv")
    assert read.header == [f"c{j}" for j in range(k)] and read.metadata == {"case": "unladen"}
    assert (read.units is not None) == units
    got = np.column_stack([read.column(j) for j in range(k)])
    assert np.array_equal(got, np.array(table, dtype=float))
