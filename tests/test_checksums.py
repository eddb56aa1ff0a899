"""Checksum verification: each file is identical, within its family's tolerance (with the platform facts that
differ) or changed, and a changed figure byte is explained by its data difference."""

from __future__ import annotations

import hashlib
import json
import math
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from parksteer.checksums import CHANGED, IDENTICAL, WITHIN, failures, read_sums, refresh, verify
from parksteer.plotting import new_figure, save_svg
from parksteer.tables import write_csv


# The platform the tests' sums are "made on"; verification is told the running platform explicitly.
PLATFORM = {"machine": "x86_64", "os": "Linux 6.1", "libc": "glibc 2.36", "python": "3.11.7", "blas": "openblas 0.3",
            "blas_core": "Haswell", "compiler": "cc 12.2.0", "numpy": "2.4.6", "scipy": "1.17.1", "sympy": "1.14.0",
            "matplotlib": "3.11.2"}


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
    assert {c.outcome for c in verify(tmp_path, tmp_path / "figures/SHA256SUMS", files)} == {IDENTICAL}


def _problems(root: Path, files: list[str], strict: bool = False) -> list[str]:
    return [c.line for c in failures(verify(root, root / "figures/SHA256SUMS", files, PLATFORM), strict)]


def test_verification_fails_when_a_figure_byte_changes(tmp_path):
    """One changed leading digit of an SVG coordinate (tens of points) fails verification although the data is
    unchanged: the drawing moved beyond the rendering tolerance (a byte that breaks the XML is damage instead: see
    the truncation test below)."""
    files = _make_figure(tmp_path, "fig12", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    svg = tmp_path / "figures/fig12.svg"
    raw = bytearray(svg.read_bytes())
    at = raw.index(b' d="M ') + len(b' d="M ')
    raw[at] = ord("1") if raw[at] != ord("1") else ord("2")
    svg.write_bytes(bytes(raw))
    problems = _problems(tmp_path, files)
    assert len(problems) == 1
    assert problems[0].startswith("figures/fig12.svg: changed: checksum mismatch; drawing line"), problems
    assert "allowed 0.05 pt" in problems[0]


def test_mismatch_names_the_largest_data_difference(tmp_path):
    """A real change in the data is reported with its column, row and the old and new values."""
    files = _make_figure(tmp_path, "fig12", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _make_figure(tmp_path, "fig12", 1.5)  # y = 1.5 x^2: largest change at x = 3, 9 -> 13.5
    problems = _problems(tmp_path, files)
    assert len(problems) == 2
    for line in problems:
        assert "changed" in line and "column torque_Nm, row 4: 9 -> 13.5" in line


def test_new_or_missing_figures_are_reported(tmp_path):
    """A figure without a stored sum, or one not built, fails verification with a reason."""
    files = _make_figure(tmp_path, "f", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    extra = _make_figure(tmp_path, "g", 2.0)
    problems = _problems(tmp_path, files + extra)
    assert any("figures/g.svg: no stored checksum" in p for p in problems)
    (tmp_path / "figures/f.csv").unlink()
    problems = _problems(tmp_path, files)
    assert any("figures/f.csv: missing" in p for p in problems)


def test_cli_verify_exit_status(tmp_path):
    """`parksteer checksums verify` exits 0 on a match and 1 on a mismatch, with a pass/fail count."""
    files = _make_figure(tmp_path, "f", 1.0)
    cmd = [sys.executable, "-m", "parksteer.cli", "checksums"]
    ok = subprocess.run(cmd + ["refresh", *files], cwd=tmp_path, capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    ok = subprocess.run(cmd + ["verify", *files], cwd=tmp_path, capture_output=True, text=True)
    assert ok.returncode == 0 and "2 identical, 0 within tolerance, 0 changed" in ok.stdout, ok.stdout
    _make_figure(tmp_path, "f", 2.0)
    bad = subprocess.run(cmd + ["verify", *files], cwd=tmp_path, capture_output=True, text=True)
    assert bad.returncode == 1 and "0 identical, 0 within tolerance, 2 changed" in bad.stdout, bad.stdout


def test_cli_verify_of_a_subset_checks_only_those_files_unless_complete(tmp_path):
    """A user checking the files built (one figure of several) passes on identical files; the verify rule's
    `--complete` reports a stored figure that was not given as no longer made."""
    files = _make_figure(tmp_path, "f", 1.0) + _make_figure(tmp_path, "g", 3.0)
    cmd = [sys.executable, "-m", "parksteer.cli", "checksums"]
    assert subprocess.run(cmd + ["refresh", *files], cwd=tmp_path, capture_output=True).returncode == 0
    subset = [f for f in files if "/f." in f]
    ok = subprocess.run(cmd + ["verify", *subset, "--strict"], cwd=tmp_path, capture_output=True, text=True)
    assert ok.returncode == 0 and "2 identical, 0 within tolerance, 0 changed" in ok.stdout, ok.stdout
    bad = subprocess.run(cmd + ["verify", *subset, "--complete"], cwd=tmp_path, capture_output=True, text=True)
    assert bad.returncode == 1 and "no longer makes it" in bad.stdout, bad.stdout


@pytest.mark.parametrize("value,text", [(-0.0, "0"), (1e-12, "1e-12"), (0.1 + 0.2, "0.3"), (float("nan"), "nan")])
def test_number_formatting_absorbs_last_bit_noise(value, text):
    """Seven significant digits: a last-bit floating-point difference does not change the bytes."""
    from parksteer.tables import format_number

    assert format_number(value) == text


def test_a_number_reads_as_zero_only_when_it_is_zero_and_a_column_is_written_as_each_number_is():
    """format_number writes Python's `digits` significant digits and "0" for either zero, and only for a zero (no
    nonzero float, subnormals among them, rounds to a text that reads as zero); format_numbers writes a column
    exactly as format_number writes each of its numbers (random bit patterns of both signs, zeros, subnormals,
    infinities and nan)."""
    from parksteer.tables import format_number, format_numbers

    rng = np.random.default_rng(11)
    patterns = rng.integers(0, 2**64, 20000, dtype=np.uint64, endpoint=False)
    values = np.concatenate([patterns.view(np.float64), [0.0, -0.0, 5e-324, -5e-324, 2.2e-308, np.inf, -np.inf,
                                                          np.nan, -np.nan, 0.1 + 0.2, 123456789.5]])
    for digits in (1, 7, 9, 10):
        texts = format_numbers(values, digits)
        assert texts == [format_number(v, digits) for v in values]
        for value, text in zip(values.tolist(), texts):
            if value == 0.0:
                assert text == "0"
            elif math.isfinite(value):
                assert float(text) != 0.0 and text == f"{value:.{digits}g}"
            else:
                assert text == ("nan" if math.isnan(value) else "inf" if value > 0 else "-inf")


@pytest.mark.parametrize("victim", ["svg", "csv"])
def test_truncated_file_is_reported_broken_not_as_a_wobble(tmp_path, victim):
    """A figure or its data cut off mid-write (a killed job, a full disk) is damage, not a rendering wobble:
    verify says "broken" and names the file, instead of a traceback or "only the rendering differs"."""
    files = _make_figure(tmp_path, "f", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files)
    path = tmp_path / f"figures/f.{victim}"
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    checks = verify(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    problems = [c for c in checks if c.outcome != IDENTICAL]
    assert len(problems) == 1 and problems[0].outcome == CHANGED, problems
    assert problems[0].line.startswith(f"figures/f.{victim}: broken: "), problems[0].line
    assert "rendering" not in problems[0].line


def test_an_svg_element_more_is_changed_even_with_identical_data(tmp_path):
    """An SVG whose text differs beyond its numbers (here an added element) is changed, though its data is
    identical: only numbers may move within tolerance, the drawing's structure must match."""
    files = _make_figure(tmp_path, "fig12", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    svg = tmp_path / "figures/fig12.svg"
    svg.write_text(svg.read_text(encoding="utf-8").replace("</svg>", "<!-- other renderer --></svg>"), encoding="utf-8")
    problems = _problems(tmp_path, files)
    assert len(problems) == 1 and problems[0].startswith("figures/fig12.svg: changed:"), problems
    assert "text differs" in problems[0]


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


# ----------------------------------------------------------------------------- identical / within / changed

def _table(root: Path, name: str, columns: dict, header: dict | None = None) -> list[str]:
    write_csv(root / f"figures/{name}.csv", columns, header)
    return [f"figures/{name}.csv"]


def _edit_cell(root: Path, name: str, column: str, row: int, text: str) -> None:
    """Replace one cell's printed text (row counted from 1), keeping everything else byte for byte."""
    path = root / f"figures/{name}.csv"
    lines = path.read_text(encoding="utf-8").splitlines()
    first = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    names = lines[first].split(",")
    cells = lines[first + row].split(",")
    cells[names.index(column)] = text
    lines[first + row] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _outcome(root: Path, files: list[str], rel: str, platform_now: dict | None = None):
    checks = {c.path: c for c in verify(root, root / "figures/SHA256SUMS", files, platform_now or PLATFORM)}
    return checks[rel]


MODEL_COLUMNS = {"time_s": [0.0, 0.01, 0.02], "rack_mm": [0.0, 12.34567, 24.69134],
                 "torque_Nm": [0.005764961, 15.56351, 16.02403]}


def test_identical_file_is_reported_identical(tmp_path):
    """A file whose sha256 matches its stored sum is "identical", and nothing more is said about it."""
    files = _table(tmp_path, "fig12", MODEL_COLUMNS)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    check = _outcome(tmp_path, files, "figures/fig12.csv")
    assert check.outcome == IDENTICAL and check.line == "figures/fig12.csv: identical"


def test_last_digit_wobble_of_a_model_torque_is_within_tolerance(tmp_path):
    """One unit of the 7th printed digit of a simulated torque (15.56351 -> 15.56352) is a platform wobble: within
    tolerance, with the difference and its allowance in N m."""
    files = _table(tmp_path, "fig12", MODEL_COLUMNS)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _edit_cell(tmp_path, "fig12", "torque_Nm", 2, "15.56352")
    check = _outcome(tmp_path, files, "figures/fig12.csv")
    assert check.outcome == WITHIN, check.line
    assert "column torque_Nm, row 2: 15.56351 -> 15.56352" in check.line and "N m" in check.line


def test_one_percent_change_of_a_model_torque_is_changed(tmp_path):
    """A 1 % larger torque (15.56351 -> 15.71915 N m) is far beyond a few times the integrator's tolerance: changed."""
    files = _table(tmp_path, "fig12", MODEL_COLUMNS)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _edit_cell(tmp_path, "fig12", "torque_Nm", 2, "15.71915")
    check = _outcome(tmp_path, files, "figures/fig12.csv")
    assert check.outcome == CHANGED and "column torque_Nm, row 2: 15.56351 -> 15.71915" in check.line, check.line


def test_closed_form_allows_its_last_printed_digit_only(tmp_path):
    """A closed-form figure (fig3) may move by the rounding of its last printed digit, not by one more digit."""
    files = _table(tmp_path, "fig3", {"load_N": [2000.0, 3000.0], "gough_torque_Nm": [70.85215, 91.0583]})
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _edit_cell(tmp_path, "fig3", "gough_torque_Nm", 1, "70.85216")
    assert _outcome(tmp_path, files, "figures/fig3.csv").outcome == WITHIN
    _edit_cell(tmp_path, "fig3", "gough_torque_Nm", 1, "70.85225")
    assert _outcome(tmp_path, files, "figures/fig3.csv").outcome == CHANGED


DIAG_COLUMNS = {"name": ["b00", "b01"], "verdict": ["missing", "adequate"], "named_first": [1.0, 0.0],
                "calibrated_over_floor": [1.446166, 1.036632], "best_delta_bic": [7.920569, 3.1]}


def test_a_changed_verdict_is_changed(tmp_path):
    """Text has no tolerance: a diagnosis verdict that changes (missing -> adequate) makes the file changed, even
    though every number is identical."""
    files = _table(tmp_path, "diag_benchmark", DIAG_COLUMNS)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _edit_cell(tmp_path, "diag_benchmark", "verdict", 1, "adequate")
    check = _outcome(tmp_path, files, "figures/diag_benchmark.csv")
    assert check.outcome == CHANGED and "text column verdict, row 1: 'missing' -> 'adequate'" in check.line


def test_diagnosis_numbers_move_within_their_fit_tolerance_but_a_flag_does_not(tmp_path):
    """A fitted ratio 2e-4 of itself away and a BIC 0.05 away are within the diagnosis tolerance; a yes/no flag
    that flips (named_first 1 -> 0) is changed."""
    files = _table(tmp_path, "diag_benchmark", DIAG_COLUMNS, {"noise_floor_Nm": 0.163988})
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _edit_cell(tmp_path, "diag_benchmark", "calibrated_over_floor", 1, "1.446455")
    _edit_cell(tmp_path, "diag_benchmark", "best_delta_bic", 1, "7.970569")
    path = tmp_path / "figures/diag_benchmark.csv"
    path.write_text(path.read_text(encoding="utf-8").replace("0.163988", "0.164"), encoding="utf-8")
    assert _outcome(tmp_path, files, "figures/diag_benchmark.csv").outcome == WITHIN
    _edit_cell(tmp_path, "diag_benchmark", "named_first", 1, "0")
    assert _outcome(tmp_path, files, "figures/diag_benchmark.csv").outcome == CHANGED


def test_reordered_columns_are_changed(tmp_path):
    """The same numbers under reordered columns are a structural change, not a wobble."""
    files = _table(tmp_path, "fig12", MODEL_COLUMNS)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    reordered = {k: MODEL_COLUMNS[k] for k in ("time_s", "torque_Nm", "rack_mm")}
    _table(tmp_path, "fig12", reordered)
    check = _outcome(tmp_path, files, "figures/fig12.csv")
    assert check.outcome == CHANGED and "columns differ" in check.line


def test_a_changed_header_text_is_changed(tmp_path):
    """The `# key: value` lines are structure: other words there make the file changed."""
    files = _table(tmp_path, "fig12", MODEL_COLUMNS, {"runs": "unladen__full"})
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _table(tmp_path, "fig12", MODEL_COLUMNS, {"runs": "part_laden__full"})
    check = _outcome(tmp_path, files, "figures/fig12.csv")
    assert check.outcome == CHANGED and "header runs" in check.line


def test_a_figure_without_a_declared_family_cannot_be_within_tolerance(tmp_path):
    """A figure no family declares has no tolerance: any byte difference is changed, and the line says why."""
    files = _table(tmp_path, "unlisted", MODEL_COLUMNS)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _edit_cell(tmp_path, "unlisted", "torque_Nm", 2, "15.56352")
    check = _outcome(tmp_path, files, "figures/unlisted.csv")
    assert check.outcome == CHANGED and "no tolerance declared" in check.line


def _nudge_svg_number(svg: Path, by: float) -> str:
    """Move the first coordinate of the first drawn line (after 'd="M ') by `by` points; return the new number."""
    text = svg.read_text(encoding="utf-8")
    start = text.index(' d="M ') + len(' d="M ')
    end = text.index(" ", start)
    new = f"{float(text[start:end]) + by:.6f}".rstrip("0").rstrip(".")
    svg.write_text(text[:start] + new + text[end:], encoding="utf-8")
    return new


def test_svg_within_rendering_tolerance_when_its_data_is(tmp_path):
    """A model figure's SVG whose data is within tolerance and whose drawing moved by 0.004 pt is within
    tolerance; moved by 0.2 pt (beyond the model figures' 0.05 pt) it is changed."""
    files = _make_figure(tmp_path, "fig12", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    svg = tmp_path / "figures/fig12.svg"
    original = svg.read_text(encoding="utf-8")
    _nudge_svg_number(svg, 0.004)
    check = _outcome(tmp_path, files, "figures/fig12.svg")
    assert check.outcome == WITHIN and "abs 0.004 pt, allowed 0.05 pt" in check.line, check.line
    svg.write_text(original, encoding="utf-8")
    _nudge_svg_number(svg, 0.2)
    assert _outcome(tmp_path, files, "figures/fig12.svg").outcome == CHANGED


def test_svg_is_changed_when_its_data_is(tmp_path):
    """A drawing within its rendering tolerance is still changed when its data changed beyond tolerance."""
    files = _make_figure(tmp_path, "fig12", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    _nudge_svg_number(tmp_path / "figures/fig12.svg", 0.004)
    _edit_cell(tmp_path, "fig12", "torque_Nm", 4, "9.1")
    check = _outcome(tmp_path, files, "figures/fig12.svg")
    assert check.outcome == CHANGED and "data figures/fig12.csv" in check.line, check.line


def test_renamed_clip_path_ids_alone_do_not_change_a_drawing(tmp_path):
    """matplotlib names clip paths by a hash of their geometry: a renamed id (the same drawing) is not a change."""
    from parksteer.checksums.compare import compare_drawings
    from parksteer.checksums.tolerances import family_of

    files = _make_figure(tmp_path, "fig12", 1.0)
    svg = tmp_path / files[0]
    reference = svg.read_text(encoding="utf-8")
    import re

    ids = sorted(set(re.findall(r"(?<=[\"#])p[0-9a-f]{10}(?=[\")])", reference)))
    assert ids, "the test figure has a clip path"
    svg.write_text(reference.replace(ids[0], "p0123456789"), encoding="utf-8")
    assert compare_drawings(svg, reference, family_of("fig12").drawing).within


@pytest.mark.parametrize("text,unit", [("15.56351", 1e-5), ("1.234567e-05", 1e-11), ("282", 0.0), ("0.3", 0.0),
                                       ("-4.947861e-11", 1e-17), ("1234567", 1.0)])
def test_printing_unit_is_one_unit_of_the_seventh_digit(text, unit):
    """A number printed with all 7 significant digits may carry a rounding of one unit of its last digit; a shorter
    one (an integer count, 0.3) was printed exactly."""
    from parksteer.checksums.compare import printing_unit

    assert printing_unit(text) == pytest.approx(unit, rel=1e-9, abs=0.0)


# ---------------------------------------------------------------------------------- strictness and platform

def test_cli_strict_fails_on_within_tolerance_and_names_the_platform(tmp_path):
    """Through the command line: a file within tolerance passes (exit 0) and fails with --strict (exit 1); its line
    names the platform facts that differ from figures/PLATFORM.json, and so does the report file."""
    files = _table(tmp_path, "fig12", MODEL_COLUMNS)
    cmd = [sys.executable, "-m", "parksteer.cli", "checksums"]
    assert subprocess.run(cmd + ["refresh", *files], cwd=tmp_path, capture_output=True).returncode == 0
    recorded = json.loads((tmp_path / "figures/PLATFORM.json").read_text(encoding="utf-8"))
    assert recorded["machine"] == platform.machine() and recorded["python"] == platform.python_version()
    other = "riscv64" if platform.machine() != "riscv64" else "aarch64"
    recorded.update(machine=other, libc="musl 1.2.5")
    (tmp_path / "figures/PLATFORM.json").write_text(json.dumps(recorded), encoding="utf-8")
    _edit_cell(tmp_path, "fig12", "torque_Nm", 2, "15.56352")

    lenient = subprocess.run(cmd + ["verify", *files, "--report", "report.txt"], cwd=tmp_path, capture_output=True,
                             text=True)
    assert lenient.returncode == 0, lenient.stdout + lenient.stderr
    line = next(line for line in lenient.stdout.splitlines() if line.startswith("figures/fig12.csv"))
    assert line.startswith("figures/fig12.csv: within tolerance: largest difference column torque_Nm"), line
    assert f"machine {other} -> {platform.machine()}" in line, line
    assert "libc musl 1.2.5 -> " in line, line
    assert "0 identical, 1 within tolerance, 0 changed" in lenient.stdout
    assert f"machine {other} -> {platform.machine()}" in (tmp_path / "report.txt").read_text(encoding="utf-8")

    strict = subprocess.run(cmd + ["verify", *files, "--strict"], cwd=tmp_path, capture_output=True, text=True)
    assert strict.returncode == 1 and "verification failed: 1 file(s) not identical" in strict.stdout, strict.stdout

    _edit_cell(tmp_path, "fig12", "torque_Nm", 2, "15.71915")
    changed = subprocess.run(cmd + ["verify", *files], cwd=tmp_path, capture_output=True, text=True)
    assert changed.returncode == 1 and "figures/fig12.csv: changed:" in changed.stdout, changed.stdout


def test_refresh_records_the_platform_and_the_drawings(tmp_path):
    """Refresh writes figures/PLATFORM.json beside the sums and a gzipped reference copy of each SVG, the same
    bytes when repeated."""
    files = _make_figure(tmp_path, "fig12", 1.0)
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    copy = tmp_path / "figures/reference/fig12.svg.gz"
    first = copy.read_bytes()
    refresh(tmp_path, tmp_path / "figures/SHA256SUMS", files, PLATFORM)
    assert copy.read_bytes() == first
    assert json.loads((tmp_path / "figures/PLATFORM.json").read_text(encoding="utf-8")) == PLATFORM


def test_platform_facts_are_quick_and_complete():
    """The running platform's facts take a fraction of a second and name machine, libc, BLAS, compiler, packages."""
    import time

    from parksteer.checksums.platform_facts import gather

    start = time.perf_counter()
    facts = gather()
    assert time.perf_counter() - start < 1.0
    for key in ("machine", "os", "libc", "python", "blas", "blas_core", "compiler", "numpy", "scipy", "sympy"):
        assert facts[key], key
    assert facts["machine"] == platform.machine()


@pytest.mark.skipif(not (platform.system() == "Linux" and platform.machine() == "x86_64"), reason="x86-64 Linux only")
def test_cpu_flags_hold_the_x86_64_baseline_and_agree_with_the_fma_fact():
    """Every x86-64 CPU has SSE2 (the architecture's baseline), so /proc/cpuinfo's flags, as cpu_flags reads them, name
    it; and the recorded fact of FMA is the flags' (what picks glibc's FMA variants, and which OpenBLAS kernels run)."""
    from parksteer.checksums.platform_facts import cpu_flags, gather

    flags = cpu_flags()
    assert {"sse2", "fpu"} <= flags
    assert gather()["cpu_fma"] == ("yes" if "fma" in flags else "no")


def test_every_stored_figure_has_a_tolerance_family():
    """Every figure in figures/SHA256SUMS belongs to a declared family, so none is judged without a tolerance."""
    from parksteer.checksums.tolerances import family_of

    root = Path(__file__).resolve().parents[1]
    stems = {Path(rel).stem for rel in read_sums(root / "figures/SHA256SUMS")}
    assert stems and not [s for s in sorted(stems) if family_of(s) is None]


def test_docs_show_the_declared_tolerances():
    """docs/reproducibility.md shows the tolerance table exactly as parksteer.checksums.tolerances declares it."""
    from parksteer.checksums.tolerances import table_markdown

    docs = (Path(__file__).resolve().parents[1] / "docs/reproducibility.md").read_text(encoding="utf-8")
    assert table_markdown() in docs


def test_platform_differences_name_each_fact_and_ignore_a_kernel_update():
    """Each differing fact is named old -> new; another kernel release of the same OS is not a difference, another
    OS is; a missing record is said as such."""
    from parksteer.checksums.platform_facts import differences

    running = dict(PLATFORM, os="Linux 6.8", libc="glibc 2.39")
    assert differences(PLATFORM, running) == ["libc glibc 2.36 -> glibc 2.39"]
    assert differences(PLATFORM, dict(PLATFORM, os="Darwin 23.1.0")) == ["os Linux 6.1 -> Darwin 23.1.0"]
    assert "no record" in differences(None, PLATFORM)[0]


def test_a_text_cell_with_a_comma_is_refused_and_nothing_is_written(tmp_path):
    """The figures' CSV has no quoting: a label holding a comma would add a cell to its row (the damage check
    then takes the table for a cut one). Writing it is refused with the column and row named, and no file is left."""
    from parksteer.tables import write_csv

    path = tmp_path / "labels.csv"
    with pytest.raises(ValueError, match=r"column method, row 2: .*comma"):
        write_csv(path, {"method": ["plain", "own, as another's"], "count": [1, 2]})
    assert not path.exists()
