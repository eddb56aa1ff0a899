"""Measurement files: every defect is refused with one line naming file, column and row; writing round-trips."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure.io import MIN_SAMPLES, Measurement, read_measurement, write_measurement

N_ROWS = 60
HEADER_LINE = 3  # two metadata lines, then the header: data row r sits on line r + 3


def good_columns(n: int = N_ROWS) -> dict[str, list[str]]:
    """A plausible slice of a cycle: 50 Hz, rack at 15 mm/s, torque rising to 15 N m."""
    t = np.arange(n) * 0.02
    return {
        "time_s": [f"{v:g}" for v in t],
        "rack_m": [f"{v:g}" for v in 0.015 * t],
        "handwheel_torque_Nm": [f"{v:g}" for v in np.minimum(4.0 + 10.0 * t, 15.0)],
    }


def render(columns: dict[str, list[str]], metadata: dict[str, str] | None = None) -> str:
    metadata = {"case": "unladen", "surface": "ground"} if metadata is None else metadata
    lines = [f"# {k}: {v}" for k, v in metadata.items()]
    lines.append(",".join(columns))
    lines += [",".join(row) for row in zip(*columns.values())]
    return "\n".join(lines) + "\n"


def refused(tmp_path, text: str | bytes, params) -> str:
    path = tmp_path / "run3.csv"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    with pytest.raises(UsageError) as info:
        read_measurement(path, params)
    message = str(info.value)
    assert "\n" not in message, "a usage error is one line"
    assert str(path) in message, "the message names the file"
    return message


def with_cell(column: str, row: int, value: str) -> dict[str, list[str]]:
    cols = good_columns()
    cols[column][row - 1] = value
    return cols


def test_good_file_reads_with_metadata_and_float_columns(tmp_path, params):
    """A valid file gives float arrays equal to the written numbers, and the metadata as text."""
    path = tmp_path / "good.csv"
    path.write_text(render(good_columns(), {"case": "part_laden", "surface": "air_bearing", "operator": "JS"}))
    m = read_measurement(path, params)
    assert m.case == "part_laden" and m.surface == "air_bearing"
    assert m.metadata["operator"] == "JS", "unknown metadata keys are kept"
    assert m.n_samples == N_ROWS
    assert m.sample_interval_s == pytest.approx(0.02)
    assert m.rack_m[-1] == pytest.approx(0.015 * 0.02 * (N_ROWS - 1))
    assert m.extra_offset_m is None and not m.is_synthetic


@pytest.mark.parametrize(
    "column, row, value, expected",
    [
        ("handwheel_torque_Nm", 7, "n/a", "'n/a' is not a number"),
        ("rack_m", 12, "", "empty cell"),
        ("rack_m", 5, "nan", "'nan' is not a finite number"),
        ("handwheel_torque_Nm", 9, "inf", "'inf' is not a finite number"),
        ("handwheel_torque_Nm", 4, "250", "implausible handwheel torque"),
        ("time_s", 20, "0.36", "does not increase"),  # row 19 holds 0.36 s
    ],
)
def test_bad_cell_is_named_by_column_row_and_line(tmp_path, params, column, row, value, expected):
    """A bad value is located by column, 1-based data row and file line, so it can be fixed by hand."""
    message = refused(tmp_path, render(with_cell(column, row, value)), params)
    assert f"column {column!r}, row {row} (line {row + HEADER_LINE})" in message
    assert expected in message


def test_rack_in_millimetres_is_recognised(tmp_path, params):
    """A rack travel over 0.2 m is impossible on a car (the Maestro's is 0.067 m): the file is in mm."""
    cols = good_columns()
    cols["rack_m"] = [f"{1000 * float(v):g}" for v in cols["rack_m"]]
    message = refused(tmp_path, render(cols), params)
    assert "column 'rack_m'" in message and "looks like millimetres; convert to metres" in message
    first_over = next(i for i, v in enumerate(cols["rack_m"], start=1) if abs(float(v)) > 0.2)
    assert f"row {first_over} " in message


def test_angle_in_degrees_and_loads_in_kilonewtons_are_recognised(tmp_path, params):
    """Two turns of lock are 12.6 rad (720 degrees); front wheel loads are about 3000 N (3 kN)."""
    cols = good_columns()
    cols["handwheel_angle_rad"] = [f"{v:g}" for v in np.linspace(0.0, 720.0, N_ROWS)]
    assert "looks like degrees" in refused(tmp_path, render(cols), params)
    cols = good_columns()
    cols["load_left_N"] = ["2.7"] * N_ROWS
    message = refused(tmp_path, render(cols), params)
    assert "column 'load_left_N'" in message and "kilonewtons" in message
    cols["load_left_N"] = ["2.7e5"] * N_ROWS
    assert "implausible wheel load" in refused(tmp_path, render(cols), params)


def test_missing_and_unknown_columns(tmp_path, params):
    """A missing required column is named; an unknown column is named with the list of allowed ones."""
    cols = good_columns()
    del cols["rack_m"]
    assert "missing required column 'rack_m'" in refused(tmp_path, render(cols), params)
    cols = good_columns()
    cols["speed_m_s"] = ["0"] * N_ROWS
    message = refused(tmp_path, render(cols), params)
    assert "unknown column 'speed_m_s'" in message and "allowed: time_s, rack_m, handwheel_torque_Nm" in message
    text = render(good_columns()).replace("time_s,rack_m,", "time_s,rack_m,rack_m,", 1)
    assert "column 'rack_m' appears twice" in refused(tmp_path, text, params)


def test_ragged_row(tmp_path, params):
    """A row with more or fewer fields than the header is refused at that row and line."""
    lines = render(good_columns()).splitlines()
    lines[HEADER_LINE + 4 - 1] += ",3.0"  # data row 4
    message = refused(tmp_path, "\n".join(lines) + "\n", params)
    assert "row 4 (line 7): 4 fields where the header has 3" in message


def test_too_few_samples(tmp_path, params):
    """Fewer samples than the phases of a cycle need are refused, stating the minimum."""
    message = refused(tmp_path, render(good_columns(MIN_SAMPLES - 1)), params)
    assert f"{MIN_SAMPLES - 1} samples; at least {MIN_SAMPLES}" in message


@pytest.mark.parametrize(
    "metadata, expected",
    [
        ({"case": "unloaded", "surface": "ground"}, "unknown case 'unloaded' (known: unladen, part_laden,"),
        ({"case": "unladen", "surface": "ice"}, "unknown surface 'ice' (known: ground, air_bearing)"),
        ({"surface": "ground"}, "missing metadata line '# case: ...'"),
        ({"case": "unladen", "surface": "ground", "extra_offset_m": "44.5"}, "looks like millimetres"),
        ({"case": "unladen", "surface": "ground", "bits": "eight"}, "bits = 'eight'"),
        ({"case": "unladen", "surface": "ground", "bits_handwheel_angle_rad": "0"}, "bits_handwheel_angle_rad = '0'"),
        ({"case": "unladen", "surface": "ground", "bits_steer": "12"}, "bits_steer names no known column"),
        ({"case": "unladen", "surface": "ground", "full_scale_torque": "25"}, "names no known column"),
    ],
)
def test_bad_metadata(tmp_path, params, metadata, expected):
    """Metadata that the comparison with the model relies on is checked against the parameter file."""
    assert expected in refused(tmp_path, render(good_columns(), metadata), params)


def test_malformed_files(tmp_path, params):
    """Empty, header-only, undecodable, missing and misplaced-metadata files are each refused in one line."""
    assert "empty file" in refused(tmp_path, "", params)
    assert "empty file" in refused(tmp_path, "# case: unladen\n\n", params)
    assert "no data rows" in refused(tmp_path, "# case: unladen\ntime_s,rack_m,handwheel_torque_Nm\n", params)
    assert "not UTF-8" in refused(tmp_path, b"time_s,rack_m\n\xff\xfe\n", params)
    text = render(good_columns()) + "# note: late\n"
    assert "metadata line after the header row" in refused(tmp_path, text, params)
    text = "# case: unladen\n# case: part_laden\n" + render(good_columns(), {"surface": "ground"})
    assert "line 2: metadata key 'case' given twice" in refused(tmp_path, text, params)
    with pytest.raises(UsageError, match=r"missing\.csv: cannot read \(No such file or directory\)"):
        read_measurement(tmp_path / "missing.csv", params)
    with pytest.raises(UsageError, match="cannot read"):
        read_measurement(tmp_path, params)


def test_byte_order_mark_and_windows_line_ends_are_accepted(tmp_path, params):
    """Files saved by a spreadsheet (BOM, CRLF) read the same as plain ones."""
    path = tmp_path / "excel.csv"
    path.write_bytes(("\ufeff" + render(good_columns())).replace("\n", "\r\n").encode("utf-8"))
    assert read_measurement(path, params).n_samples == N_ROWS


def test_write_then_read_round_trips(tmp_path, params):
    """What write_measurement writes reads back to the same numbers (9 significant digits) and metadata."""
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.01, 0.03, 200))
    columns = {
        "time_s": t,
        "rack_m": 0.06 * np.sin(t),
        "handwheel_torque_Nm": 15.0 * np.tanh(t - 2.0) + rng.normal(0.0, 0.1, t.size),
        "load_right_N": 2878.0 + 40.0 * np.sin(t),
    }
    metadata = {"case": "offset_44_5mm", "surface": "ground", "extra_offset_m": "0.0445", "source": "bench: run 7"}
    path = tmp_path / "sub" / "run.csv"
    write_measurement(path, Measurement(None, columns, metadata), params)
    back = read_measurement(path, params)
    assert back.metadata == metadata
    assert list(back.columns) == ["time_s", "rack_m", "handwheel_torque_Nm", "load_right_N"]
    for name, values in columns.items():
        np.testing.assert_allclose(back.columns[name], values, rtol=1e-8, atol=0.0)
    assert back.extra_offset_m == 0.0445
    write_measurement(tmp_path / "again.csv", back, params)
    assert (tmp_path / "again.csv").read_bytes() == path.read_bytes(), "a written file is a fixed point"


def test_invalid_measurement_is_never_written(tmp_path, params):
    """A defect found while writing leaves the previous file untouched and no temporary file behind."""
    path = tmp_path / "run.csv"
    path.write_text("previous contents\n")
    cols = {k: np.array([float(v) for v in vals]) for k, vals in good_columns().items()}
    cols["rack_m"] = cols["rack_m"] * 1000.0
    with pytest.raises(UsageError, match="looks like millimetres"):
        write_measurement(path, Measurement(None, cols, {"case": "unladen", "surface": "ground"}), params)
    with pytest.raises(UsageError, match="unknown case"):
        cols["rack_m"] = cols["rack_m"] / 1000.0
        write_measurement(path, Measurement(None, cols, {"case": "nope", "surface": "ground"}), params)
    assert path.read_text() == "previous contents\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv"]


def test_the_shipped_example_file_is_a_valid_synthetic_measurement(repo_root, params):
    """data/measurements/example_unladen.csv reads, says it is synthetic and records its logger settings."""
    m = read_measurement(repo_root / "data" / "measurements" / "example_unladen.csv", params)
    assert m.is_synthetic and m.case == "unladen" and m.surface == "ground"
    assert m.quantisation_step("handwheel_torque_Nm") == pytest.approx(2 * 25.0 / 255)
    for key in ("noise_seed", "sample_rate_hz", "noise_rms_handwheel_torque_Nm", "hand_seed"):
        assert key in m.metadata


def test_a_channel_with_its_own_converter_has_its_own_step(tmp_path, params):
    """``bits_<column>`` gives one channel its own converter: its step is 2 full_scale / (2**bits - 1) with its own
    bits (a 12-bit rack over +-0.1 m: 0.2 / 4095 m), while the other channels keep the file's ``bits``."""
    path = tmp_path / "own_bits.csv"
    metadata = {"case": "unladen", "surface": "ground", "bits": "8", "full_scale_handwheel_torque_Nm": "25",
                "full_scale_rack_m": "0.1", "bits_rack_m": "12"}
    path.write_text(render(good_columns(), metadata), encoding="utf-8")
    m = read_measurement(path, params)
    assert m.quantisation_step("rack_m") == pytest.approx(0.2 / 4095)
    assert m.quantisation_step("handwheel_torque_Nm") == pytest.approx(50.0 / 255)


def test_of_several_bad_cells_the_first_by_row_is_named(tmp_path, params):
    """A column with an infinite number above a cell that is no number is refused at the infinite one, the first
    defect a reader going down the file meets."""
    cols = with_cell("rack_m", 9, "-inf")
    cols["rack_m"][30] = "1.2.3"
    message = refused(tmp_path, render(cols), params)
    assert f"column 'rack_m', row 9 (line {9 + HEADER_LINE})" in message and "not a finite number" in message


def test_a_column_holds_each_cells_number_to_the_bit():
    """Table.column gives, for every cell, the float parse_number reads from it (shortest and long decimal forms,
    exponents, signs, surrounding spaces, decimal commas): the same bits."""
    from parksteer.measure.text_table import parse_number, read_table

    rng = np.random.default_rng(5)
    values = (rng.standard_normal(3000) * 10.0 ** rng.integers(-300, 300, 3000)).tolist()
    texts = [f" {v!r}" if i % 3 == 0 else f"{v:.17g} " if i % 3 == 1 else f"{v:+.6e}" for i, v in enumerate(values)]
    for delimiter, decimal in ((",", "."), (";", ",")):
        cells = [t.replace(".", ",") for t in texts] if decimal == "," else texts
        table = read_table("a" + delimiter + "b\n" + "\n".join(f"{i}{delimiter}{c}" for i, c in enumerate(cells)),
                           "t.csv")
        assert table.decimal == decimal
        expected = np.array([parse_number(c.replace(",", "."), "t.csv") for c in cells])
        assert table.column(1).tobytes() == expected.tobytes()
