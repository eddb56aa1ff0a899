"""Malformed and odd inputs for every entry point, made at run time from the shipped example record.

Each :class:`Case` builds its input files in a scratch folder and gives the command line to try; ``expect`` is
either ``"accepted"`` (exit 0) or the fragment the one-line error must contain. The base record is
``data/measurements/example_unladen.csv`` cut to every 9th sample (100 samples, 18 s), small enough that an
accepted replay takes a second or two.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "data" / "measurements" / "example_unladen.csv"
PARAMETERS = REPO / "src" / "parksteer" / "data" / "parameters.toml"
ACCEPTED = "accepted"


def base_record(step: int = 9) -> tuple[list[str], list[str], np.ndarray]:
    """(metadata lines, header names, data) of the example record, every `step`-th sample."""
    lines = EXAMPLE.read_text(encoding="utf-8").splitlines()
    meta = [line for line in lines if line.startswith("#")]
    rest = [line for line in lines if line.strip() and not line.startswith("#")]
    header = rest[0].split(",")
    data = np.array([[float(c) for c in row.split(",")] for row in rest[1:]])[::step]
    return meta, header, data


def record_text(meta=None, header=None, data=None, *, columns: dict | None = None, drop_meta=(), sep=",",
                newline="\n", blank_every: int = 0, bom=False) -> str:
    """The base record with changes: replaced columns ({name: function of the column}), dropped metadata keys,
    another delimiter or line end, blank lines between rows, a byte-order mark."""
    m, h, d = base_record()
    meta = [line for line in (m if meta is None else meta)
            if line[1:].partition(":")[0].strip() not in drop_meta]
    header = h if header is None else header
    d = (d if data is None else data).copy()
    for name, fn in (columns or {}).items():
        j = h.index(name)
        d[:, j] = fn(d[:, j], d)
    rows = [sep.join(f"{v:.9g}" for v in row) for row in d]
    if blank_every:
        rows = [r + (newline if (i + 1) % blank_every == 0 else "") for i, r in enumerate(rows)]
    text = newline.join(meta + [sep.join(header)] + rows) + newline
    return ("\ufeff" if bom else "") + text


@dataclass(frozen=True)
class Case:
    name: str
    entry: str  # compare | diagnose | simulate | check-params | checksums
    make: Callable[[Path], list[str]]  # scratch folder -> argv (files written there)
    expect: str  # ACCEPTED or a fragment of the one-line error
    outputs: tuple[str, ...] = ()  # files (relative to the scratch folder) that must not exist after an error
    status: int = 2  # 2: a usage error on stderr; 1: a verification that found a problem (one stdout line)


def _write(folder: Path, name: str, text: str | bytes) -> Path:
    path = folder / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8", newline="")
    return path


# ------------------------------------------------------------------------------------------ record defects

def _defects() -> dict[str, tuple[Callable[[], str | bytes], str]]:
    """name -> (file content, expected fragment) of a measurement defect; tried on every record entry point."""
    m, h, d = base_record()
    ragged = record_text().splitlines()
    ragged[len(m) + 3] += ",7"
    nan = record_text().splitlines()
    nan[len(m) + 4] = nan[len(m) + 4].rsplit(",", 1)[0] + ",nan"
    word = record_text().splitlines()
    word[len(m) + 2] = "0.36,n/a," + ",".join(word[len(m) + 2].split(",")[2:])
    after = record_text().splitlines()
    after.insert(len(m) + 5, "# late: key")
    back = d.copy()
    back[10, 0] = back[9, 0]
    ramp = d[: int(np.argmax(d[:, 1]))]
    return {
        "empty": (lambda: "", "empty file"),
        "header_only": (lambda: "\n".join(m + [",".join(h)]) + "\n", "no data rows"),
        "ragged_row": (lambda: "\n".join(ragged) + "\n", "fields where the header has"),
        "word_in_cell": (lambda: "\n".join(word) + "\n", "'n/a' is not a number"),
        "nan_cell": (lambda: "\n".join(nan) + "\n", "is not a finite number"),
        "time_repeats": (lambda: record_text(data=back), "does not increase"),
        "rack_in_mm": (lambda: record_text(columns={"rack_m": lambda x, _: 1000 * x}), "millimetres"),
        "rack_beyond_lock": (lambda: record_text(columns={"rack_m": lambda x, _: 1.6 * x}), "beyond the car's lock"),
        "torque_sign_flipped": (lambda: record_text(columns={"handwheel_torque_Nm": lambda x, _: -x}),
                                "negate one"),
        "rack_never_moves": (lambda: record_text(columns={"rack_m": lambda x, _: 0 * x + 0.001}),
                             "the rack never moves"),
        "five_samples": (lambda: record_text(data=d[:5]), "at least 50"),
        "duplicated_column": (lambda: record_text(header=h[:-1] + [h[0]]), "appears twice"),
        "not_utf8": (lambda: record_text().encode("utf-8").replace(b"# case", b"# c\xe4se"), "not UTF-8"),
        "metadata_after_header": (lambda: "\n".join(after) + "\n", "metadata line after the header"),
        "unknown_case": (lambda: record_text(meta=[x.replace("unladen", "nocar") for x in m]), "unknown case"),
        "no_case": (lambda: record_text(drop_meta=("case",)), "names no case"),
        "angle_in_degrees": (lambda: record_text(columns={"handwheel_angle_rad": lambda x, _: np.degrees(x)}),
                             "degrees"),
        "torque_in_Nmm": (lambda: record_text(columns={"handwheel_torque_Nm": lambda x, _: 1000 * x}),
                          "handwheel torque"),
        "ramp_no_reversal_short": (lambda: record_text(data=ramp[:30]), "at least 50"),
    }


def _record_argv(entry: str, path: Path, folder: Path) -> list[str]:
    if entry == "compare":
        return ["compare", str(path), "--plot", str(folder / "out.svg")]
    if entry == "diagnose":
        return ["diagnose", str(path), "--report", str(folder / "out.md")]
    return ["simulate", "--rack-from", str(path), "--out", str(folder / "out.csv")]


OUTPUTS = {"compare": ("out.svg",), "diagnose": ("out.md",), "simulate": ("out.csv",)}


def record_cases() -> list[Case]:
    cases = []
    for name, (content, fragment) in _defects().items():
        for entry in ("compare", "diagnose", "simulate"):
            def make(folder: Path, content=content, entry=entry, name=name) -> list[str]:
                return _record_argv(entry, _write(folder, f"{name}.csv", content()), folder)

            cases.append(Case(f"{entry}:{name}", entry, make, fragment, OUTPUTS[entry]))
    return cases


def _fd_path(folder: Path, text: str) -> str:
    """A /dev/fd/N path, as a shell's process substitution passes (the descriptor stays open for the run)."""
    import os

    path = _write(folder, "fd_source.csv", text)
    fd = os.open(path, os.O_RDONLY)
    return f"/dev/fd/{fd}"


def _fast_text(rate_hz: float) -> str:
    """The example cycle resampled to `rate_hz` (made at run time: 36 000 rows at 2 kHz)."""
    meta, header, d = base_record(1)
    meta = [m for m in meta if not m.startswith(("# bits", "# full_scale", "# sample_rate"))]
    t = np.arange(d[0, 0], d[-1, 0], 1.0 / rate_hz)
    data = np.column_stack([t] + [np.interp(t, d[:, 0], d[:, j]) for j in range(1, d.shape[1])])
    return record_text(meta=meta, data=data)


def _ramp_text() -> str:
    """The first stroke only (to the right lock, 112 samples): the rack never turns back."""
    _, _, d = base_record(2)
    return record_text(data=d[: int(np.argmax(d[:, 1]))])


def odd_record_cases() -> list[Case]:
    """Odd but valid records (accepted) and record-level refusals that need more than the reader."""
    accepted = {
        "bom_crlf": lambda: record_text(bom=True, newline="\r\n"),
        "blank_lines_between_rows": lambda: record_text(blank_every=3),
        "semicolons": lambda: record_text(sep=";"),
    }
    cases = []
    for name, content in accepted.items():
        for entry in ("compare", "simulate"):
            def make(folder, content=content, entry=entry, name=name):
                return _record_argv(entry, _write(folder, f"{name}.csv", content()), folder)

            cases.append(Case(f"{entry}:{name}", entry, make, ACCEPTED))
    for entry in ("compare", "simulate"):
        def make(folder, entry=entry):
            return _record_argv(entry, Path(_fd_path(folder, record_text(blank_every=4))), folder)

        cases.append(Case(f"{entry}:dev_fd_path", entry, make, ACCEPTED))
    cases += [
        Case("diagnose:rack_never_reverses", "diagnose",
             lambda f: _record_argv("diagnose", _write(f, "ramp.csv", _ramp_text()), f), "never reverses",
             ("out.md",)),
        Case("compare:missing_file", "compare", lambda f: ["compare", str(f / "nope.csv")], "cannot read"),
        Case("compare:directory_as_file", "compare", lambda f: ["compare", str(f)], "cannot read"),
        Case("diagnose:no_output_named", "diagnose",
             lambda f: ["diagnose", str(_write(f, "ok.csv", record_text()))], "say where the result goes"),
        Case("compare:plot_not_svg", "compare",
             lambda f: ["compare", str(_write(f, "ok.csv", record_text())), "--plot", str(f / "out.png")],
             "name it .svg", ("out.png",)),
        Case("simulate:out_is_directory", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--out", str(f)], "is a directory"),
        Case("diagnose:report_is_directory", "diagnose",
             lambda f: ["diagnose", str(_write(f, "ok.csv", record_text())), "--report", str(f)], "is a directory"),
        Case("compare:plot_is_directory", "compare",
             lambda f: ["compare", str(_write(f, "ok.csv", record_text())), "--plot", str((f / "d.svg").mkdir() or
                                                                                            f / "d.svg")],
             "is a directory"),
        Case("simulate:output_step_longer_than_run", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--output-dt", "1e6", "--out", str(f / "out.csv")],
             "fewer than two outputs", ("out.csv",)),
        Case("simulate:output_step_negative", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--output-dt", "-1", "--out", str(f / "out.csv")],
             "must be positive", ("out.csv",)),
        Case("simulate:unknown_override", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--set", "tyre.nothing=1", "--out", str(f / "out.csv")],
             "unknown key", ("out.csv",)),
        Case("simulate:override_not_a_number", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--set", "tyre.tyre_pressure=high", "--out",
                        str(f / "out.csv")], "is not a number", ("out.csv",)),
        Case("simulate:override_out_of_bounds", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--set", "tyre.carcass_torsional_stiffness=1e9", "--out",
                        str(f / "out.csv")], "non-physical", ("out.csv",)),
        Case("simulate:rack_from_missing", "simulate",
             lambda f: ["simulate", "--rack-from", str(f / "nope.csv"), "--out", str(f / "out.csv")], "no such file",
             ("out.csv",)),
        Case("simulate:wheel_load_against_statics", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--set", "case.load_left=29000", "--out", str(f / "out.csv")],
             "wheel loads sum to", ("out.csv",)),
        Case("compare:2kHz_record", "compare", lambda f: ["compare", str(_write(f, "fast.csv", _fast_text(2000.0)))],
             ACCEPTED),
        Case("simulate:unknown_case_option", "simulate",
             lambda f: ["simulate", "--case", "nocar", "--out", str(f / "out.csv")], "nocar", ("out.csv",)),
    ]
    return cases


# ---------------------------------------------------------------------------------------- parameter files

def _params_text(old: str | None = None, new: str | None = None) -> str:
    text = PARAMETERS.read_text(encoding="utf-8")
    if old is not None:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def parameter_cases() -> list[Case]:
    variants = {
        "shipped": (lambda: _params_text(), ACCEPTED),
        "bom": (lambda: "\ufeff" + _params_text(), ACCEPTED),
        "crlf": (lambda: _params_text().replace("\n", "\r\n"), ACCEPTED),
        "toml_syntax": (lambda: _params_text("[steering]", "[steering"), "toml"),
        "wrong_unit": (lambda: _params_text('rack_mass = { value = 10.0, unit = "kg"',
                                            'rack_mass = { value = 10.0, unit = "g"'), "rack_mass"),
        "mass_out_of_bounds": (lambda: _params_text('rack_mass = { value = 10.0,', 'rack_mass = { value = -10.0,'),
                               "rack_mass"),
        "value_is_text": (lambda: _params_text('rack_mass = { value = 10.0,', 'rack_mass = { value = "10",'),
                          "rack_mass"),
        "unknown_key": (lambda: _params_text("[steering]\n", "[steering]\nrack_colour = { value = 1.0, unit = \"1\", "
                                             "source = \"x\" }\n"), "rack_colour"),
        "missing_key": (lambda: _params_text('rack_mass = { value = 10.0, unit = "kg", source = "Appendix B" }\n', ""),
                        "rack_mass"),
        "chassis_mass_statics": (lambda: _params_text("chassis_mass = { value = 468.4,",
                                                      "chassis_mass = { value = 4684.0,"), "chassis_mass"),
        "not_utf8": (lambda: _params_text().encode("utf-8").replace(b"# parksteer", b"# p\xe4rksteer"), "UTF-8"),
        "tyre_pressure_in_atmospheres": (lambda: _params_text("tyre_pressure = { value = 122500.0,",
                                                              "tyre_pressure = { value = 1.225,"),
                                         "tyre.tyre_pressure: value 1.225 Pa is non-physical"),
    }
    cases = []
    for name, (content, fragment) in variants.items():
        def make(folder, content=content, name=name):
            return ["check-params", str(_write(folder, f"{name}.toml", content()))]

        cases.append(Case(f"check-params:{name}", "check-params", make, fragment))
    cases.append(Case("check-params:missing", "check-params", lambda f: ["check-params", str(f / "nope.toml")],
                      "nope.toml"))
    return cases


# ------------------------------------------------------------------------------------------- checksums

def _figure(folder: Path) -> list[str]:
    from parksteer.checksums import refresh
    from parksteer.plotting import new_figure, save_svg
    from parksteer.tables import write_csv

    x = [0.0, 1.0, 2.0, 3.0]
    write_csv(folder / "figures/f.csv", {"x_m": x, "torque_Nm": [v * v for v in x]})
    fig, ax = new_figure(3, 2)
    ax.plot(x, x)
    save_svg(fig, folder / "figures/f.svg")
    files = ["figures/f.svg", "figures/f.csv"]
    refresh(folder, folder / "figures/SHA256SUMS", files)
    return files


def _verify_argv(folder: Path, files: list[str]) -> list[str]:
    return ["checksums", "verify", *files, "--root", str(folder), "--sums", str(folder / "figures/SHA256SUMS")]


def _truncate(folder: Path, rel: str, keep: float) -> None:
    path = folder / rel
    raw = path.read_bytes()
    path.write_bytes(raw[: int(len(raw) * keep)])


def checksum_cases() -> list[Case]:
    def intact(f):
        return _verify_argv(f, _figure(f))

    def csv_mid_line(f):
        files = _figure(f)
        _truncate(f, "figures/f.csv", 0.8)
        return _verify_argv(f, files)

    def svg_truncated(f):
        files = _figure(f)
        _truncate(f, "figures/f.svg", 0.5)
        return _verify_argv(f, files)

    def missing_sums(f):
        files = _figure(f)
        (f / "figures/SHA256SUMS").unlink()
        return _verify_argv(f, files)

    def file_deleted(f):
        files = _figure(f)
        (f / "figures/f.csv").unlink()
        return _verify_argv(f, files)

    return [
        Case("checksums:intact", "checksums", intact, ACCEPTED),
        Case("checksums:csv_truncated_mid_line", "checksums", csv_mid_line, "figures/f.csv: broken", status=1),
        Case("checksums:svg_truncated", "checksums", svg_truncated, "figures/f.svg: broken", status=1),
        Case("checksums:sums_missing", "checksums", missing_sums, "SHA256SUMS: no stored checksums"),
        Case("checksums:file_deleted", "checksums", file_deleted, "figures/f.csv: missing", status=1),
    ]


def all_cases() -> list[Case]:
    return record_cases() + odd_record_cases() + parameter_cases() + checksum_cases()
