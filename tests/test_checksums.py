"""Checksum verification: a changed figure byte is caught and explained by its data difference."""

from __future__ import annotations

import hashlib
import subprocess
import sys
from pathlib import Path

import pytest

from parksteer.checksums import read_sums, refresh, verify
from parksteer.plotting import new_figure, save_svg
from parksteer.tables import write_csv


def _make_figure(root: Path, name: str, scale: float) -> list[str]:
    """A small figure and its data, written with the project's deterministic writers."""
    x = [0.0, 1.0, 2.0, 3.0]
    y = [scale * v * v for v in x]
    write_csv(root / f"figures/{name}.csv", {"x_m": x, "torque_Nm": y})
    fig, ax = new_figure(3, 2)
    ax.plot(x, y)
    save_svg(fig, root / f"figures/{name}.svg")
    return [f"figures/{name}.svg", f"figures/{name}.csv"]


def test_same_inputs_give_same_bytes(tmp_path):
    """Determinism: drawing the same data twice gives byte-identical SVG and CSV files."""
    files = _make_figure(tmp_path / "a", "f", 1.0)
    _make_figure(tmp_path / "b", "f", 1.0)
    for rel in files:
        assert (tmp_path / "a" / rel).read_bytes() == (tmp_path / "b" / rel).read_bytes(), rel


def test_refresh_writes_sha256sum_format(tmp_path):
    """The stored sums are the sha256 of each file, in the format `sha256sum -c` reads."""
    files = _make_figure(tmp_path, "f", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    sums = read_sums(tmp_path / "figures/SHA256SUMS")
    for rel in files:
        assert sums[rel] == hashlib.sha256((tmp_path / rel).read_bytes()).hexdigest()
    check = subprocess.run(["sha256sum", "-c", "figures/SHA256SUMS"], cwd=tmp_path, capture_output=True, text=True)
    assert check.returncode == 0, check.stdout + check.stderr
    assert verify(tmp_path, tmp_path / "figures/SHA256SUMS", files) == []


def test_verification_fails_when_a_figure_byte_changes(tmp_path):
    """One changed digit in an SVG's drawing fails verification; unchanged data is reported as a rendering-only
    change (a byte that breaks the XML is damage instead: see the truncation test below)."""
    files = _make_figure(tmp_path, "f", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    svg = tmp_path / "figures/f.svg"
    raw = bytearray(svg.read_bytes())
    at = raw.index(b' d="M ') + len(b' d="M ')
    raw[at] = ord("1") if raw[at] != ord("1") else ord("2")
    svg.write_bytes(bytes(raw))
    problems = verify(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    assert len(problems) == 1
    assert problems[0].startswith("figures/f.svg: checksum mismatch")
    assert "only the rendering differs" in problems[0]


def test_mismatch_names_the_largest_data_difference(tmp_path):
    """A real change in the data is reported with its column, row and the old and new values."""
    files = _make_figure(tmp_path, "f", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    _make_figure(tmp_path, "f", 1.5)  # y = 1.5 x^2: largest change at x = 3, 9 -> 13.5
    problems = verify(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    assert len(problems) == 2
    for line in problems:
        assert "column torque_Nm, row 4: 9 -> 13.5" in line


def test_new_or_missing_figures_are_reported(tmp_path):
    """A figure without a stored sum, or one not built, fails verification with a reason."""
    files = _make_figure(tmp_path, "f", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    extra = _make_figure(tmp_path, "g", 2.0)
    problems = verify(tmp_path, tmp_path / "figures/SHA256SUMS", files + extra)
    assert any("figures/g.svg: no stored checksum" in p for p in problems)
    (tmp_path / "figures/f.csv").unlink()
    problems = verify(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    assert any("figures/f.csv: missing" in p for p in problems)


def test_cli_verify_exit_status(tmp_path):
    """`parksteer checksums verify` exits 0 on a match and 1 on a mismatch, with a pass/fail count."""
    files = _make_figure(tmp_path, "f", 1.0)
    cmd = [sys.executable, "-m", "parksteer.cli", "checksums"]
    ok = subprocess.run(cmd + ["refresh", *files], cwd=tmp_path, capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    ok = subprocess.run(cmd + ["verify", *files], cwd=tmp_path, capture_output=True, text=True)
    assert ok.returncode == 0 and "2 passed, 0 failed" in ok.stdout
    _make_figure(tmp_path, "f", 2.0)
    bad = subprocess.run(cmd + ["verify", *files], cwd=tmp_path, capture_output=True, text=True)
    assert bad.returncode == 1 and "0 passed, 2 failed" in bad.stdout


@pytest.mark.parametrize("value,text", [(-0.0, "0"), (1e-12, "1e-12"), (0.1 + 0.2, "0.3"), (float("nan"), "nan")])
def test_number_formatting_absorbs_last_bit_noise(value, text):
    """Seven significant digits: a last-bit floating-point difference does not change the bytes."""
    from parksteer.tables import format_number

    assert format_number(value) == text


@pytest.mark.parametrize("victim", ["svg", "csv"])
def test_truncated_file_is_reported_broken_not_as_a_wobble(tmp_path, victim):
    """A figure or its data cut off mid-write (a killed job, a full disk) is damage, not a rendering wobble:
    verify says "broken" and names the file, instead of a traceback or "only the rendering differs"."""
    files = _make_figure(tmp_path, "f", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    path = tmp_path / f"figures/f.{victim}"
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    problems = verify(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    assert len(problems) == 1, problems
    assert problems[0].startswith(f"figures/f.{victim}: broken: "), problems[0]
    assert "rendering" not in problems[0]


def test_rendering_only_change_keeps_its_wording(tmp_path):
    """The harmless case stays distinguishable: a well-formed SVG whose data is unchanged is "only the rendering
    differs", not "broken"."""
    files = _make_figure(tmp_path, "f", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    svg = tmp_path / "figures/f.svg"
    svg.write_text(svg.read_text(encoding="utf-8").replace("</svg>", "<!-- other renderer --></svg>"), encoding="utf-8")
    problems = verify(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    assert len(problems) == 1 and "only the rendering differs" in problems[0], problems


def test_a_table_cut_at_a_row_boundary_is_damage_not_a_smaller_table(tmp_path):
    """A table that lost its last rows to a cut exactly at a line end still parses; the row count that write_csv
    puts last in the header makes the cut visible to the reader, to the damage check before a build and to verify."""
    from parksteer.checksums import integrity_problem
    from parksteer.outputs import content_problem
    from parksteer.tables import read_csv

    path = tmp_path / "t.csv"
    write_csv(path, {"x": [1.0, 2.0, 3.0, 4.0]}, {"figure": "t"})
    assert content_problem(path) is None and integrity_problem(path) is None
    assert len(read_csv(path)[0]["x"]) == 4
    lines = path.read_text(encoding="utf-8").splitlines(keepends=True)
    path.write_text("".join(lines[:-2]), encoding="utf-8")  # the last two rows gone, a newline at the end
    assert "2 data rows where its header says 4" in content_problem(path)
    assert "truncated" in integrity_problem(path)
    with pytest.raises(ValueError, match="truncated"):
        read_csv(path)
