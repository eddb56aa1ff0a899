"""Malformed and odd inputs for every entry point, made at run time from the shipped example record.

Each :class:`Case` builds its input files in a scratch folder and gives the command line to try; ``expect`` is
either ``"accepted"`` (exit 0) or the fragment the one-line error must contain. The base record is
``data/measurements/example_unladen.csv`` cut to every 9th sample (100 samples, 18 s), small enough that an
accepted replay takes a second or two.
"""

from __future__ import annotations

import re
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
    entry: str  # compare | diagnose | simulate | check-params | checksums | vehicle
    make: Callable[[Path], list[str]]  # scratch folder -> argv (files written there)
    expect: str  # ACCEPTED or a fragment of the one-line error
    outputs: tuple[str, ...] = ()  # files (relative to the scratch folder) that must not exist after an error
    status: int = 2  # 2: a usage error on stderr; 1: a verification that found a problem (one stdout line)
    env: tuple[tuple[str, str], ...] = ()  # environment variables of the run ({scratch} in a value: its folder)


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




# ------------------------------------------------------------------------------ findings and further entry points

VEHICLE = REPO / "data" / "vehicles" / "maestro.toml"


def _logger_text() -> str:
    """The base record as a logger writes it: its own names, units in brackets (rack in mm), semicolons."""
    m, _, d = base_record()
    header = ["Time [s]", "RackPos [mm]", "SteerTorque [N*m]"]
    rows = [f"{t:.9g};{1000 * x:.9g};{T:.9g}" for t, x, T in d[:, :3]]
    return "\n".join([line for line in m if not line.startswith(("# full_scale", "# bits"))] + [";".join(header)]
                     + rows) + "\n"


def _quoted_text() -> str:
    """The base record with every header name and number in double quotes, as some spreadsheets export."""
    return "".join(line + "\n" if line.startswith("#") else ",".join(f'"{c}"' for c in line.split(",")) + "\n"
                   for line in record_text().splitlines())


def _rack_renamed_text() -> str:
    """Time, torque and a rack column under a name no alias knows, and no angle to derive the rack from."""
    out = []
    for line in record_text().splitlines():
        if line.startswith("#"):
            if "rack_m" not in line and "angle" not in line:
                out.append(line)
        else:
            out.append(",".join(line.split(",")[:3]).replace("rack_m", "Zahnrad"))
    return "\n".join(out) + "\n"


def _loop(folder: Path) -> Path:
    import os

    path = folder / "loop.csv"
    os.symlink(path, path)
    return path


def _mdf(folder: Path, *, unit: str = "mm", time_back: bool = False) -> Path:
    """The base record as MDF 4 (asammdf): torque and rack channels; a rack unit, a time base going back."""
    import asammdf

    _, _, d = base_record()
    t = d[:, 0].copy()
    if time_back:
        t[40] = t[38]
    mdf = asammdf.MDF(version="4.10")
    mdf.append([asammdf.Signal(d[:, 2], d[:, 0], name="SteerTorque", unit="N*m")])
    mdf.append([asammdf.Signal(1000 * d[:, 1], t, name="RackPos", unit=unit)])
    path = Path(mdf.save(folder / "log.mf4", overwrite=True))
    mdf.close()
    return path


def _vehicle_text(old: str | None = None, new: str | None = None) -> str:
    text = VEHICLE.read_text(encoding="utf-8")
    if old is not None and "kingpin_top_y" in old:  # an inboard top leans the axis across the centreline
        text = text.replace("kingpin_inclination = { value = 0.219,", "kingpin_inclination = { value = -0.45,", 1)
    if old is not None:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


SPEC = ["--front-axle-mass-kg", "780", "--track-m", "1.46", "--kingpin-inclination-deg", "13", "--castor-deg", "3",
        "--scrub-radius-m", "0.01", "--tyre-size", "185/65R15", "--tyre-pressure-bar", "2.2", "--steering-ratio",
        "15", "--lock-turns", "3"]


def _spec(folder: Path, option: str | None = None, value: str | None = None) -> list[str]:
    argv = ["vehicle", "new", "--out", str(folder / "car.toml"), *SPEC]
    if option is not None:
        if option in argv:
            argv[argv.index(option) + 1] = value
        else:
            argv += [option, value]
    return argv


def finding_cases() -> list[Case]:
    """The bad inputs a review found handled badly, each now refused (or read) as it should be."""
    out = ("out.csv",)
    stiff = _params_text("radial_stiffness = { value = 160000.0,", "radial_stiffness = { value = 1e15,")
    return [
        Case("compare:rack_column_unknown_name", "compare",
             lambda f: ["compare", str(_write(f, "r.csv", _rack_renamed_text())), "--plot", str(f / "out.svg")],
             "of which Zahnrad is not a known channel name", ("out.svg",)),
        Case("simulate:parameters_radial_stiffness_1e15", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--parameters", str(_write(f, "p.toml", stiff)), "--out",
                        str(f / "out.csv")], "p.toml: tyre.radial_stiffness: value 1e+15 N/m is non-physical", out),
        Case("check-params:radial_stiffness_1e15", "check-params",
             lambda f: ["check-params", str(_write(f, "p.toml", stiff))], "tyre.radial_stiffness"),
        Case("check-params:rack_mass_in_grams", "check-params",
             lambda f: ["check-params", str(_write(f, "p.toml", _params_text("rack_mass = { value = 10.0,",
                                                                              "rack_mass = { value = 10000.0,")))],
             "steering.rack_mass: value 10000 kg is non-physical"),
        Case("compare:quoted_numbers", "compare",
             lambda f: ["compare", str(_write(f, "q.csv", _quoted_text()))], ACCEPTED),
        Case("simulate:quoted_numbers", "simulate",
             lambda f: _record_argv("simulate", _write(f, "q.csv", _quoted_text()), f), ACCEPTED),
        Case("compare:symlink_loop", "compare", lambda f: ["compare", str(_loop(f))], "symbolic link loop"),
        Case("simulate:rack_from_symlink_loop", "simulate",
             lambda f: _record_argv("simulate", _loop(f), f), "symbolic link loop", out),
    ]


def map_cases() -> list[Case]:
    """--map and --map-file on a logger's export: unknown unit, unknown channel, a target mapped twice."""
    def with_map(spec: str):
        return lambda f: ["compare", str(_write(f, "log.csv", _logger_text())), "--map", spec, "--plot",
                          str(f / "out.svg")]

    def with_file(lines: str):
        return lambda f: ["compare", str(_write(f, "log.csv", _logger_text())), "--map-file",
                          str(_write(f, "map.txt", lines)), "--plot", str(f / "out.svg")]

    svg = ("out.svg",)
    return [
        Case("compare:logger_export", "compare", lambda f: ["compare", str(_write(f, "log.csv", _logger_text()))],
             ACCEPTED),
        Case("compare:map_unknown_unit", "compare", with_map("RackPos[furlongz]=rack_m"),
             "unit 'furlongz' is not a unit pint knows (the unit of --map)", svg),
        Case("compare:map_unknown_channel", "compare", with_map("Wheel[mm]=rack_m"),
             "--map names channel 'Wheel', which the file does not have", svg),
        Case("compare:map_duplicate_target", "compare", with_map("RackPos[mm]=rack_m,SteerTorque[N*m]=rack_m"),
             "both map to 'rack_m'", svg),
        Case("compare:map_file_unknown_unit", "compare", with_file("# logger\nRackPos[furlongz]=rack_m\n"),
             "(the unit of ", svg),
        Case("compare:map_file_unknown_channel", "compare", with_file("Wheel[mm]=rack_m\n"),
             "map.txt: line 1 names channel 'Wheel'", svg),
        Case("compare:map_file_duplicate_target", "compare",
             with_file("RackPos[mm]=rack_m\nSteerTorque[N*m]=rack_m\n"), "map.txt: line 2", svg),
        Case("compare:map_and_map_file_same_target", "compare",
             lambda f: ["compare", str(_write(f, "log.csv", _logger_text())), "--map-file",
                        str(_write(f, "map.txt", "RackPos[mm]=rack_m\n")), "--map", "SteerTorque[N*m]=rack_m",
                        "--plot", str(f / "out.svg")], "repeats a channel or target", svg),
    ]


def vehicle_cases() -> list[Case]:
    """--vehicle with every statics check of a vehicle file failing, and vehicle new/check on absurd specs."""
    statics = {
        "shipped": (None, None, ACCEPTED),
        "unsprung_mass": ("unsprung_mass = { value = 100.0,", "unsprung_mass = { value = 150.0,",
                          "vehicle.unsprung_mass: 150 kg, but the parts"),
        "negative_mass": ("rack_mass = { value = 10.0,", "rack_mass = { value = -10.0,", "steering.rack_mass"),
        "load_sum": ("load_left = { value = 2698.0,", "load_left = { value = 3698.0,", "wheel loads sum to"),
        "heights_out_of_order": ("wheel_centre_z = { value = 0.2,", "wheel_centre_z = { value = 0.6,",
                                 "geometry.wheel_centre_z: heights out of order"),
        "kingpin_outboard": ("kingpin_top_y = { value = 0.58,", "kingpin_top_y = { value = 0.9,",
                             "is not outboard of geometry.kingpin_top_y"),
        "axis_across_centreline": ("kingpin_top_y = { value = 0.58,", "kingpin_top_y = { value = 0.1,",
                                   "across the centreline"),
        "lock_beyond_linkage": ("handwheel_lock_angle = { value = 12.566,", "handwheel_lock_angle = { value = 40.0,",
                                "input.handwheel_lock_angle"),
        "missing_value": ('rack_mass = { value = 10.0, unit = "kg", source = "Appendix B" }\n', "",
                          "steering.rack_mass: missing value"),
        "unknown_key": ("[steering]\n", "[steering]\nrack_colour = { value = 1.0, unit = \"1\", source = \"x\" }\n",
                        "steering.rack_colour: unknown key"),
    }
    cases = []
    for name, (old, new, fragment) in statics.items():
        def make(f, old=old, new=new):
            return ["simulate", "--vehicle", str(_write(f, "car.toml", _vehicle_text(old, new))), "--case", "unladen",
                    "--output-dt", "0.5", "--out", str(f / "out.csv")]

        cases.append(Case(f"simulate:vehicle_{name}", "simulate", make, fragment,
                          () if fragment == ACCEPTED else ("out.csv",)))
    cases.append(Case("vehicle:check_negative_mass", "vehicle",
                      lambda f: ["vehicle", "check", str(_write(f, "car.toml", _vehicle_text(
                          "rack_mass = { value = 10.0,", "rack_mass = { value = -10.0,")))], "steering.rack_mass"))
    cases.append(Case("vehicle:check_missing", "vehicle", lambda f: ["vehicle", "check", str(f / "nope.toml")],
                      "nope.toml: cannot read"))
    absurd = {
        "accepted": (None, None, ACCEPTED),
        "negative_mass": ("--front-axle-mass-kg", "-780", "--front-axle-mass-kg -780: must be positive"),
        "zero_load": ("--front-axle-mass-kg", "0", "--front-axle-mass-kg 0: must be positive"),
        "mass_below_unsprung": ("--front-axle-mass-kg", "50", "nothing written: "),
        "ratio_zero": ("--steering-ratio", "0", "--steering-ratio 0"),
        "lock_turns_zero": ("--lock-turns", "0", "--lock-turns 0"),
        "track_negative": ("--track-m", "-1.46", "--track-m -1.46"),
        "left_share_above_one": ("--left-share", "1.5", "--left-share 1.5"),
        "tyre_size_word": ("--tyre-size", "big", "--tyre-size 'big'"),
        "kingpin_inclination_80deg": ("--kingpin-inclination-deg", "80", "--kingpin-inclination-deg 80: outside"),
        "castor_80deg": ("--castor-deg", "80", "--castor-deg 80: outside"),
        "pressure_negative": ("--tyre-pressure-bar", "-2", "--tyre-pressure-bar -2"),
        "scrub_radius_beyond_track": ("--scrub-radius-m", "5", "geometry.kingpin_top_y"),
        "lock_beyond_linkage": ("--steering-ratio", "3", "input.handwheel_lock_angle"),
        "out_not_toml": ("--out", "car.txt", "name it .toml"),
    }
    for name, (option, value, fragment) in absurd.items():
        def make(f, option=option, value=value):
            argv = _spec(f, option, str(f / value) if option == "--out" else value)
            return argv

        cases.append(Case(f"vehicle:new_{name}", "vehicle", make, fragment,
                          () if fragment == ACCEPTED else ("car.toml", "car.txt")))
    return cases


def diagnose_option_cases() -> list[Case]:
    """diagnose --angle, --torque-lag and --html where they cannot apply."""
    no_angle = lambda: record_text(header=None)  # noqa: E731 (the base record has an angle; dropped below)

    def without_angle(f):
        lines = []
        for line in no_angle().splitlines():
            lines.append(line if line.startswith("#") else ",".join(line.split(",")[:3]))
        return ["diagnose", str(_write(f, "r.csv", "\n".join(l for l in lines if "angle" not in l) + "\n")),
                "--angle", "--report", str(f / "out.md")]

    def angle_only(f):
        m, h, d = base_record()
        text = "\n".join([x for x in m if "rack_m" not in x] + ["time_s,handwheel_torque_Nm,handwheel_angle_rad"]
                         + [f"{r[0]:.9g},{r[2]:.9g},{r[3]:.9g}" for r in d]) + "\n"
        return ["diagnose", str(_write(f, "a.csv", text)), "--angle", "--report", str(f / "out.md")]

    def lag_angle_only(f):
        argv = angle_only(f)
        argv[argv.index("--angle")] = "--torque-lag"
        return argv

    return [
        Case("diagnose:angle_without_angle_column", "diagnose", without_angle, "--angle needs a handwheel angle",
             ("out.md",)),
        Case("diagnose:angle_with_rack_derived", "diagnose", angle_only, "its rack is derived from the angle",
             ("out.md",)),
        Case("diagnose:torque_lag_with_rack_derived", "diagnose", lag_angle_only, "--torque-lag", ("out.md",)),
        Case("diagnose:html_in_proc", "diagnose",
             lambda f: ["diagnose", str(_write(f, "ok.csv", record_text())), "--html", "/proc/out.html"],
             "cannot write in folder /proc"),
        Case("diagnose:html_under_a_file", "diagnose",
             lambda f: ["diagnose", str(_write(f, "ok.csv", record_text())), "--html", str(f / "ok.csv" / "o.html")],
             "is a file, not a folder"),
    ]


def mdf_cases() -> list[Case]:
    """ASAM MDF files (written here with asammdf): read, a channel the map names missing, a unit that is no
    length, a time base that goes back."""
    fill = ["--case", "unladen", "--surface", "ground"]
    svg = ("out.svg",)

    def argv(path: Path, f: Path, *extra: str) -> list[str]:
        return ["compare", str(path), *fill, *extra, "--plot", str(f / "out.svg")]

    return [
        Case("compare:mdf", "compare", lambda f: argv(_mdf(f), f), ACCEPTED),
        Case("compare:mdf_missing_channel", "compare",
             lambda f: argv(_mdf(f), f, "--map", "SWA[deg]=handwheel_angle_rad"),
             "--map names channel 'SWA', which the file does not have", svg),
        Case("compare:mdf_wrong_unit", "compare", lambda f: argv(_mdf(f, unit="N"), f),
             "channel 'RackPos': unit 'N' is not a unit of length", svg),
        Case("compare:mdf_time_goes_back", "compare", lambda f: argv(_mdf(f, time_back=True), f),
             "channel 'RackPos': time stamps do not increase", svg),
    ]


# ------------------------------------------------------------------------------------------------ CAN bus logs

def _bus_frames(torque_factor: float = 0.5):
    """The example record's torque (times `torque_factor`, so that it fits the 10.23 N m of LH_EPS_03) and angle
    as the frames of a VW MQB car (parksteer.measure.bus.encode_frames), and the bus map."""
    from parksteer.measure.bus import bus_channel_map, encode_frames
    from parksteer.measure.io import Measurement

    _, h, d = base_record(step=1)
    columns = {"time_s": d[:, h.index("time_s")], "handwheel_torque_Nm": torque_factor * d[:, h.index("handwheel_torque_Nm")],
               "handwheel_angle_rad": d[:, h.index("handwheel_angle_rad")]}
    channels = bus_channel_map("vw_mqb", None, None, None)
    return encode_frames(Measurement(None, columns), channels), channels


def _reframe(frame, data: bytes | None = None, timestamp: float | None = None, arbitration_id: int | None = None):
    import can

    return can.Message(timestamp=frame.timestamp if timestamp is None else timestamp,
                       arbitration_id=frame.arbitration_id if arbitration_id is None else arbitration_id,
                       data=frame.data if data is None else data, is_extended_id=False, channel=0)


def _with_crc(data: bytearray, frame_id: int) -> bytes:
    from parksteer.measure.readers.bus_files import e2e_p2_checksum, load_bus

    data[0] = e2e_p2_checksum(bytes(data), load_bus("vw_mqb").data_ids[frame_id])
    return bytes(data)


def _bus_log(folder: Path, fault: str = "", fmt: str = "candump", torque_factor: float = 0.5) -> Path:
    """A VW MQB bus log of the example record with one fault of a real bus."""
    from parksteer.measure.bus import WRITERS, write_log

    frames, channels = _bus_frames(torque_factor)
    start = frames[0].timestamp
    at = [f.timestamp - start for f in frames]
    if fault == "other_bus":  # every id moved: a log of another bus
        frames = [_reframe(f, arbitration_id=f.arbitration_id + 0x300) for f in frames]
    elif fault == "clock_back":
        k = len(frames) // 2
        frames[k] = _reframe(frames[k], timestamp=frames[k - 5].timestamp)
    elif fault == "torque_gap":  # 0.3 s of LH_EPS_03 lost while the rest of the bus goes on
        frames = [f for f, t in zip(frames, at) if not (f.arbitration_id == 159 and 5.0 < t < 5.3)]
    elif fault == "bus_off":  # 0.3 s without any frame
        frames = [f for t, f in zip(at, frames) if not 5.0 < t < 5.3]
    elif fault == "checksum":  # every LWI_01 frame's checksum wrong
        frames = [_reframe(f, data=bytes([f.data[0] ^ 0x55]) + bytes(f.data[1:])) if f.arbitration_id == 134 else f
                  for f in frames]
    elif fault == "qbit":  # the torque sensor's quality bit set in every frame (a substitute value)
        frames = [_reframe(f, data=_with_crc(bytearray(f.data[:6]) + bytes([f.data[6] | 0x40]) + f.data[7:], 159))
                  if f.arbitration_id == 159 else f for f in frames]
    elif fault == "dropped":  # a few frames lost, one duplicated, one with a bad checksum: noted, accepted
        frames = [f for k, f in enumerate(frames) if k not in (300, 301, 900)]
        frames.insert(500, frames[499])
        frames[700] = _reframe(frames[700], data=bytes([frames[700].data[0] ^ 1]) + bytes(frames[700].data[1:]))
    path = write_log(frames, folder / f"run{WRITERS[fmt]}", fmt, channels.bus.dbc)
    if fault == "truncated":
        raw = path.read_bytes()
        path.write_bytes(raw[: len(raw) // 2])
    return path


def bus_cases() -> list[Case]:
    """Raw CAN logs of a VW MQB car (the example record's angle and half its torque, encoded with
    parksteer.measure.bus): read in each format, and each fault of a bus with its one line."""
    fill = ["--case", "unladen", "--surface", "ground"]
    svg = ("out.svg",)

    def argv(path: Path, f: Path, *extra: str) -> list[str]:
        return ["compare", str(path), *fill, *extra, "--plot", str(f / "out.svg")]

    def bus(fault: str = "", fmt: str = "candump", **kw):
        return lambda f: argv(_bus_log(f, fault, fmt, **kw), f, "--bus", "vw_mqb")

    return [
        Case("compare:bus_candump", "compare", bus(), ACCEPTED),
        Case("compare:bus_blf_dropped_frames", "compare", bus("dropped", "blf"), ACCEPTED),
        Case("compare:bus_without_dbc", "compare", lambda f: argv(_bus_log(f), f), "decoding it needs the car's DBC",
             svg),
        Case("compare:bus_unknown", "compare",
             lambda f: argv(_bus_log(f), f, "--bus", "vw_nope"), "--bus vw_nope: no such bus (known: vw_mqb)", svg),
        Case("compare:bus_csv_given_a_dbc", "compare",
             lambda f: argv(_write(f, "r.csv", record_text()), f, "--bus", "vw_mqb"), "not a CAN log", svg),
        Case("compare:bus_map_unknown_signal", "compare",
             lambda f: argv(_bus_log(f), f, "--bus", "vw_mqb", "--map", "LH_EPS_03.EPS_Moment[N*m]=handwheel_torque_Nm"),
             "message LH_EPS_03 has no signal 'EPS_Moment'", svg),
        Case("compare:bus_other_bus", "compare", bus("other_bus"),
             "no frame of LH_EPS_03 (id 159 = 0x09F) in the log, which holds 0x", svg),
        Case("compare:bus_clock_back", "compare", bus("clock_back", "asc"), "the logger's clock jumped", svg),
        Case("compare:bus_torque_gap", "compare", bus("torque_gap", "trc"), "frames of this one lost", svg),
        Case("compare:bus_off", "compare", bus("bus_off"), "bus off or a logger pause", svg),
        Case("compare:bus_checksum", "compare", bus("checksum"), "LWI_01: the checksum fails in", svg),
        Case("compare:bus_quality_bit", "compare", bus("qbit"), "quality bit EPS_Lenkmoment_QBit set", svg),
        Case("compare:bus_torque_saturated", "compare", bus(torque_factor=1.0),
             "LH_EPS_03.EPS_Lenkmoment sits at its largest raw value 1023", svg),
        Case("compare:bus_blf_truncated", "compare", bus("truncated", "blf"), "the Vector BLF is cut short", svg),
        Case("compare:bus_mf4_truncated", "compare", bus("truncated", "mf4"),
             "cannot read as ASAM MDF4 bus logging", svg),
    ]


# ------------------------------------------------------------------------------------------ a user's effect file

def effect_text(*, name: str = "bore_friction", bounds: str = "0.0, 2000.0", unit: str = "N", default: str = "0.0",
                free: bool = True, candidate: bool = False, loads_body: str = "", extra: str = "") -> str:
    """A user's effect file in the form of examples/user_effect/centre_friction.py: a rack friction of one free
    strength `<name>.force` with the given bounds, unit and default; `loads_body` a line run first in loads()."""
    return f'''"""A rack friction written by a user (a corpus input)."""
import sympy as sp

from parksteer.model.symbolic.components import Effect
from parksteer.model.symbolic.system import action_reaction
from parksteer.parameters import Quantity


class BoreFriction(Effect):
    name = {name!r}
    description = "a rack friction: -F tanh(beta v)"
    in_default_set = False
    diagnosis_candidate = {candidate!r}
    quantities = (Quantity("{name}.force", {unit!r}, {bounds}, lower_inclusive=True, default={default},
                           free={free!r}, source="a corpus input"),)
    uses = ("{name}.force", "steering.friction_smoothing")
{extra}
    def loads(self, model):
        {loads_body or "pass"}
        k = model.kinematics
        force = model.p("{name}.force") * sp.tanh(model.p("steering.friction_smoothing") * model.rack_u)
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


EFFECT = BoreFriction()
'''


EFFECT_DEFECTS: dict[str, tuple[dict, str]] = {
    "bounds_none": (dict(bounds="None, None"), "bounds_none.force: lower bound None is not a number"),
    "bounds_text": (dict(bounds="0.0, '2000'"), "upper bound '2000' is not a number"),
    "bounds_nan": (dict(bounds="0.0, float('nan')"), "upper bound is NaN"),
    "bounds_reversed": (dict(bounds="10.0, 0.0"), "bounds out of order: the lower bound 10 must be below the upper 0"),
    "bounds_infinite_free": (dict(bounds="-float('inf'), float('inf')"), "needs finite bounds"),
    "default_outside": (dict(default="-5.0"), "default -5 N is outside its bounds [0, 2000]"),
    "default_text": (dict(default="'0'"), "default '0' is not a number"),
    "unit_furlong": (dict(unit="furlong"), "unit 'furlong' is not SI (1 furlong = 201.168 m)"),
    "unit_unknown": (dict(unit="furlongz"), "unit 'furlongz' is not a unit pint knows"),
    "unit_millimetres": (dict(unit="mm", bounds="0.0, 2.0"), "unit 'mm' is not SI"),
    "unit_not_text": (dict(unit=5), "unit 5: give its SI unit as text"),
    "name_of_library_effect": (dict(name="column_friction"),
                               "effect 'column_friction' has the name of the library's; name it otherwise, or "
                               "remove the library's first: --effects=-column_friction,+"),
    "name_of_parameter_section": (dict(name="tyre"), "section tyre belongs to the parameter file"),
    "name_of_run_section": (dict(name="run"), "effect name 'run' is a section of the parameter file's keys"),
    "candidate_strength_unbounded": (dict(bounds="0.0, float('inf')", free=False, candidate=True),
                                     "a diagnosis candidate's strength needs a finite upper"),
}


def _effect_argv(entry: str, spec: str, folder: Path) -> list[str]:
    record = str(_write(folder, "r.csv", record_text()))
    if entry == "simulate":
        return ["simulate", "--case", "unladen", "--effects", spec, "--out", str(folder / "out.csv")]
    if entry == "diagnose":
        return ["diagnose", record, "--effects", spec, "--report", str(folder / "out.md")]
    return ["compare", record, "--effects", spec, "--plot", str(folder / "out.svg")]


def effect_file_cases() -> list[Case]:
    """A user's effect file (--effects=+FILE.py, PARKSTEER_EFFECT_MODULES) with each defect of its declarations,
    its name or its hooks: refused at the door, naming the file, by every command that builds a model from it."""
    cases = []
    for name, (kw, fragment) in EFFECT_DEFECTS.items():
        # each defect's effect of its own name: the corpus runs in one process, where a key once declared keeps its
        # unit and bounds
        kw = {"name": name, **kw}
        for entry in ("compare", "diagnose", "simulate"):
            def make(f, kw=kw, entry=entry):
                return _effect_argv(entry, f"+{_write(f, 'mine.py', effect_text(**kw))}", f)

            cases.append(Case(f"{entry}:effect_{name}", entry, make, fragment, OUTPUTS[entry]))

    def env_clash(f):
        _write(f, "mine.py", effect_text(name="rack_friction"))
        return _effect_argv("compare", "+hooke_joint", f)

    def hook_raises(f):  # found while the model is derived: --quiet leaves the one line alone on stderr
        text = effect_text(name="hook_raises", loads_body="1 / 0")
        return _effect_argv("compare", f"+{_write(f, 'mine.py', text)}", f) + ["--quiet"]

    def hook_returns(f):  # the package fails on what loads() gave: the line names the hook all the same
        text = effect_text(name="hook_returns", loads_body="return 5")
        return _effect_argv("compare", f"+{_write(f, 'mine.py', text)}", f) + ["--quiet"]

    def removed_after(f):
        return _effect_argv("compare", f"+{_write(f, 'mine.py', effect_text(name='column_friction'))},-column_friction",
                            f)

    def suggest_onto_effect(f):
        path = _write(f, "mine.py", effect_text(name="suggest_onto"))
        return _effect_argv("diagnose", f"+{path}", f) + ["--suggest-effect", str(path)]

    return cases + [
        Case("compare:effect_file_example", "compare",
             lambda f: _effect_argv("compare", f"+{REPO / 'examples' / 'user_effect' / 'centre_friction.py'}", f),
             ACCEPTED),
        Case("compare:effect_environment_name_of_library", "compare", env_clash,
             "mine.py: effect 'rack_friction' has the name of the library's", ("out.svg",),
             env=(("PARKSTEER_EFFECT_MODULES", "{scratch}/mine.py"),)),
        Case("compare:effect_hook_loads_raises", "compare", hook_raises,
             "mine.py: its hook loads() raised ZeroDivisionError: division by zero (line ", ("out.svg",)),
        Case("compare:effect_hook_loads_returns_a_number", "compare", hook_returns,
             "mine.py: its hook loads() returned what the model cannot use (TypeError: ", ("out.svg",)),
        Case("compare:effect_library_removed_after_it", "compare", removed_after,
             "--effects=-column_friction,+", ("out.svg",)),
        Case("compare:effect_file_missing", "compare",
             lambda f: _effect_argv("compare", f"+{f / 'nope.py'}", f), "nope.py: no such file", ("out.svg",)),
        Case("compare:effect_file_syntax_error", "compare",
             lambda f: _effect_argv("compare", f"+{_write(f, 'mine.py', 'def (:')}", f), "mine.py: cannot load",
             ("out.svg",)),
        Case("compare:effect_file_without_effect", "compare",
             lambda f: _effect_argv("compare", f"+{_write(f, 'mine.py', 'X = 1')}", f), "module defines no EFFECT",
             ("out.svg",)),
        Case("diagnose:suggest_effect_onto_the_effect_file", "diagnose", suggest_onto_effect,
             "the effect file the model is built with"),
    ]


def suggest_effect_cases() -> list[Case]:
    """diagnose --suggest-effect where the file cannot be written."""
    def argv(f, target):
        return ["diagnose", str(_write(f, "r.csv", record_text())), "--suggest-effect", target]

    return [
        Case("diagnose:suggest_effect_not_py", "diagnose", lambda f: argv(f, str(f / "s.txt")), "name it .py",
             ("s.txt",)),
        Case("diagnose:suggest_effect_is_directory", "diagnose",
             lambda f: argv(f, str((f / "d.py").mkdir() or f / "d.py")), "d.py: is a directory"),
        Case("diagnose:suggest_effect_folder_missing", "diagnose", lambda f: argv(f, str(f / "no" / "s.py")),
             "does not exist"),
    ]


# ------------------------------------------------------------------------------------- boost tables, assist commands

POLO = REPO / "data" / "vehicles" / "polo_vi.toml"
BASELINE = REPO / "data" / "samples" / "polo_baseline.csv"
POLO_ASSIST_ROW = "value = [0.0, 0.0, 0.9, 2.73, 5.22, 8.27, 12.78, 18.0, 30.3], unit = \"N m\""
SPEED_TABLE = ('torsion_bar_torque = { value = [0.0, 1.0, 2.0], unit = "N m", source = "x" }\n'
               'vehicle_speed = { value = [0.0, 5.0], unit = "km/h", source = "x" }\n'
               'assist = { value = [[0.0, 2.0, 6.0], %s], unit = "N m", source = "x" }\n')


def _polo_text(old: str | None = None, new: str | None = None) -> str:
    text = POLO.read_text(encoding="utf-8")
    if old is not None:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def _speed_table(second_row: str) -> str:
    """The Polo with a boost table of two vehicle speeds, its second row `second_row` (TOML)."""
    text = _polo_text()
    head, _, rest = text.partition("[assist.boost]\n")
    tail = rest.split("\n", 2)[2]  # the Polo's two lines of its table replaced
    return head + "[assist.boost]\n" + SPEED_TABLE % second_row + tail


BOOST_DEFECTS: dict[str, tuple[Callable[[], str], str]] = {
    "true_in_assist": (lambda: _polo_text("[0.0, 0.0, 0.9, 2.73", "[0.0, 0.0, true, 2.73"),
                       "assist.boost.assist: point 3: true is not a number"),
    "text_in_assist": (lambda: _polo_text("[0.0, 0.0, 0.9, 2.73", '[0.0, 0.0, "0.9", 2.73'),
                       'assist.boost.assist: point 3: "0.9" is not a number'),
    "text_in_torques": (lambda: _polo_text("[0.0, 0.4, 0.8,", '[0.0, "0.4", 0.8,'),
                        'assist.boost.torsion_bar_torque: point 2: "0.4" is not a number'),
    "torques_a_number": (lambda: _polo_text("value = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.5, 3.0, 4.0]", "value = 4.0"),
                         "assist.boost.torsion_bar_torque: expected a list of numbers"),
    "unit_a_number": (lambda: _polo_text(POLO_ASSIST_ROW, "value = [0.0, 0.0, 0.9, 2.73, 5.22, 8.27, 12.78, 18.0, "
                                                          "30.3], unit = 3"),
                      "assist.boost.assist: unit 3 is not a string"),
    "row_with_true": (lambda: _speed_table("[0.0, true, 5.0]"), "assist.boost.assist: row 2, point 2: true is not"),
    "rows_without_speeds": (lambda: _polo_text("value = [0.0, 0.0, 0.9, 2.73, 5.22, 8.27, 12.78, 18.0, 30.3]",
                                               "value = [[0.0, 0.0, 0.9, 2.73, 5.22, 8.27, 12.78, 18.0, 30.3]]"),
                            "assist.boost.assist: rows for several vehicle speeds need vehicle_speed"),
    "row_not_a_list": (lambda: _speed_table("7.0"), "assist.boost.assist: expected one list of numbers per vehicle speed"),
    "type_a_list": (lambda: _polo_text('type = "column"', 'type = ["column"]'),
                    "assist.type: ['column'], expected one of"),
    "source_a_number": (lambda: re.sub(r'(reduction_ratio = \{ value = 18.0, unit = "1", source = )"[^"]*"',
                                       r"\g<1>18", _polo_text()),
                        "assist.reduction_ratio: source 18 is not a string"),
    "assist_falls": (lambda: _polo_text("[0.0, 0.0, 0.9, 2.73", "[0.0, 0.0, 0.9, 0.5"),
                     "assist.boost: assist: the assist must rise strictly beyond the dead band (0.9 then 0.5"),
}


def boost_table_cases() -> list[Case]:
    """A vehicle file's boost table with a value of the wrong type or shape (a TOML true, a number in quotes, a row
    that is no list): refused by `vehicle check` and by a run of the car, naming the file, the key, row and point."""
    cases = [Case("vehicle:check_boost_shipped", "vehicle",
                  lambda f: ["vehicle", "check", str(_write(f, "car.toml", _polo_text()))], ACCEPTED)]
    for name, (text, fragment) in BOOST_DEFECTS.items():
        cases.append(Case(f"vehicle:check_boost_{name}", "vehicle",
                          lambda f, text=text: ["vehicle", "check", str(_write(f, "car.toml", text()))],
                          f"car.toml: {fragment}"))
    text, fragment = BOOST_DEFECTS["true_in_assist"]
    cases.append(Case("compare:with_assist_boost_true", "compare",
                      lambda f: ["compare", str(_write(f, "r.csv", BASELINE.read_text(encoding="utf-8"))), "--vehicle",
                                 str(_write(f, "car.toml", text())), "--with-assist", "--plot", str(f / "out.svg")],
                      f"car.toml: {fragment}", ("out.svg",)))
    return cases


def _zero_current_text() -> str:
    """The Polo's baseline with its motor current 0 throughout (a logger that lost the channel's scaling, or the
    assist off)."""
    out = []
    for line in BASELINE.read_text(encoding="utf-8").splitlines():
        if line.startswith(("#", "time")):
            out.append(line)
        else:
            out.append(",".join(line.split(",")[:3] + ["0"]))
    return "\n".join(out) + "\n"


def _boost_spec(folder: Path, points: str) -> list[str]:
    return _spec(folder) + ["--assist", "column", "--assist-boost", points]


def assist_cases() -> list[Case]:
    """`assist identify` and `assist size`, and `vehicle new --assist-boost`, on bad inputs."""
    def identify(f, *extra, record=None):
        record = record or _write(f, "base.csv", BASELINE.read_text(encoding="utf-8"))
        return ["assist", "identify", str(record), "--vehicle", str(POLO), "--out", str(f / "id.toml"), *extra]

    def out_exists(f):
        _write(f, "kept.toml", "# the user's own file\n")
        argv = identify(f)
        argv[argv.index("--out") + 1] = str(f / "kept.toml")
        return argv

    no_current = "".join(line.rsplit(",", 1)[0] + "\n" if not line.startswith("#") else line + "\n"
                         for line in BASELINE.read_text(encoding="utf-8").splitlines())
    return [
        Case("assist:identify_out_exists", "assist", out_exists, "kept.toml: exists (--force to overwrite)"),
        Case("assist:identify_out_not_toml", "assist",
             lambda f: identify(f)[:-1] + [str(f / "id.txt")], "name it .toml", ("id.txt",)),
        Case("assist:identify_out_in_proc", "assist", lambda f: identify(f)[:-1] + ["/proc/id.toml"],
             "--out /proc/id.toml: cannot write in folder /proc"),
        Case("assist:identify_out_is_the_vehicle", "assist",
             lambda f: identify(f)[:-1] + [str(POLO)], "the vehicle file given"),
        Case("assist:identify_zero_current", "assist",
             lambda f: identify(f, "--quiet", record=_write(f, "zero.csv", _zero_current_text())),
             "zero.csv: motor_current_A: the motor current does not follow the torsion-bar torque", ("id.toml",)),
        Case("assist:identify_without_current", "assist",
             lambda f: identify(f, record=_write(f, "nocur.csv", no_current)), "column 'motor_current_A': missing",
             ("id.toml",)),
        Case("assist:identify_vehicle_without_assist", "assist",
             lambda f: identify(f)[:4] + [str(VEHICLE)] + identify(f)[5:], "no [assist] section", ("id.toml",)),
        Case("assist:identify_vehicle_boost_true", "assist",
             lambda f: identify(f)[:4] + [str(_write(f, "car.toml", BOOST_DEFECTS["true_in_assist"][0]()))]
             + identify(f)[5:], "car.toml: assist.boost.assist: point 3: true is not a number", ("id.toml",)),
        Case("assist:size_quiet_unknown_case", "assist",
             lambda f: ["assist", "size", "--vehicle", str(POLO), "--case", "nocar", "--target-torque", "3",
                        "--out-dir", str(f / "sizing"), "--quiet"], "--case nocar: not a case of", ("sizing",)),
        Case("assist:size_out_dir_in_proc", "assist",
             lambda f: ["assist", "size", "--vehicle", str(POLO), "--target-torque", "3", "--out-dir", "/proc/sizing"],
             "--out-dir /proc/sizing: cannot write in folder /proc"),
        Case("assist:size_out_dir_is_a_file", "assist",
             lambda f: ["assist", "size", "--vehicle", str(POLO), "--target-torque", "3", "--out-dir",
                        str(_write(f, "sizing", "x"))], "sizing: is a file, not a folder"),
        Case("assist:size_speeds_beyond_creeping", "assist",
             lambda f: ["assist", "size", "--vehicle", str(POLO), "--target-torque", "3", "--speeds-kmh", "0,50",
                        "--out-dir", str(f / "sizing")], "--speeds-kmh 0,50: speeds within", ("sizing",)),
        Case("assist:size_vehicle_boost_text", "assist",
             lambda f: ["assist", "size", "--vehicle", str(_write(f, "car.toml", BOOST_DEFECTS["text_in_assist"][0]())),
                        "--target-torque", "3", "--out-dir", str(f / "sizing")],
             'car.toml: assist.boost.assist: point 3: "0.9" is not a number', ("sizing",)),
        Case("assist:size_target_torque_nan", "assist",
             lambda f: ["assist", "size", "--vehicle", str(POLO), "--target-torque", "nan", "--out-dir",
                        str(f / "sizing")], "--target-torque nan: must be positive", ("sizing",)),
        Case("assist:size_gain_half_speed_zero", "assist",
             lambda f: ["assist", "size", "--vehicle", str(POLO), "--target-torque", "3", "--gain-half-speed-kmh", "0",
                        "--out-dir", str(f / "sizing")], "--gain-half-speed-kmh 0: must be a positive speed",
             ("sizing",)),
        Case("simulate:speed_beyond_creeping", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--speed-kmh", "50", "--out", str(f / "out.csv")],
             "--speed-kmh 50: outside 0-10.8 km/h", ("out.csv",)),
        Case("simulate:with_assist_car_without_one", "simulate",
             lambda f: ["simulate", "--vehicle", str(VEHICLE), "--with-assist", "--case", "unladen", "--out",
                        str(f / "out.csv")], "has no [assist] section", ("out.csv",)),
        Case("vehicle:new_assist_boost_leading_minus", "vehicle", lambda f: _boost_spec(f, "-0.5:0,1:2,3:6"),
             "--assist-boost -0.5:0,1:2,3:6: torsion_bar_torque: finite values from 0", ("car.toml",)),
        Case("vehicle:new_assist_boost_word", "vehicle", lambda f: _boost_spec(f, "0:0,one:2"),
             "--assist-boost 0:0,one:2: expected points T:A", ("car.toml",)),
        Case("vehicle:new_assist_boost_falls", "vehicle", lambda f: _boost_spec(f, "0:0,1:2,2:1"),
             "the assist must rise strictly beyond the dead band (2 then 1", ("car.toml",)),
        Case("vehicle:new_assist_boost", "vehicle", lambda f: _boost_spec(f, "0:0,1:20,3:60"), ACCEPTED),
        Case("vehicle:new_assist_boost_motor_units", "vehicle", lambda f: _boost_spec(f, "0:0,1:2,3:6"),
             "the motor's torque written as the assist at the column?", ("car.toml",)),
        Case("vehicle:new_out_in_proc", "vehicle",
             lambda f: _spec(f, "--out", "/proc/car.toml"), "/proc/car.toml: cannot write in folder /proc"),
        Case("simulate:out_in_proc", "simulate",
             lambda f: ["simulate", "--case", "unladen", "--output-dt", "0.5", "--out", "/proc/out.csv"],
             "/proc/out.csv: cannot write in folder /proc"),
        Case("vehicle:new_out_exists", "vehicle",
             lambda f: (_write(f, "car.toml", "# kept\n"), _spec(f))[1], "exists (--force to overwrite)"),
    ]


def all_cases() -> list[Case]:
    return (record_cases() + odd_record_cases() + parameter_cases() + checksum_cases() + finding_cases()
            + map_cases() + vehicle_cases() + diagnose_option_cases() + mdf_cases() + bus_cases()
            + effect_file_cases() + suggest_effect_cases() + boost_table_cases() + assist_cases())
