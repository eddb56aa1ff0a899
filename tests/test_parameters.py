"""The parameter file: the shipped file is valid and self-consistent, and every kind of defect is refused with
a one-line error naming the file and the key, by the loader, the command line and the pipeline alike."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from parksteer.errors import UsageError
from parksteer.parameters import DEFAULT_PATH, ParameterError, load_parameters

BIN = Path(sys.executable).parent
TABLE_B1_CASES = ["unladen", "part_laden", "offset_12_7mm", "offset_44_5mm", "offset_68_5mm"]


def _edit(text: str, old: str, new: str, after: str | None = None) -> str:
    """Replace the first `old` (after the line `after`, when given); fail if it is not there."""
    start = 0 if after is None else text.index(after + "\n")
    at = text.index(old, start)
    return text[:at] + new + text[at + len(old) :]


# defect: (text to replace, replacement, section header it follows or None, dotted key the message must name)
DEFECTS = {
    "unknown key": (
        "[geometry]\n",
        '[geometry]\nbump_steer_gain = { value = 0.1, unit = "rad/m", source = "choice" }\n',
        None,
        "geometry.bump_steer_gain",
    ),
    "missing key": (
        'castor_angle = { value = 0.0108, unit = "rad", source = "Appendix B, epsilon" }\n',
        "",
        None,
        "geometry.castor_angle",
    ),
    "missing value field": ("castor_angle = { value = 0.0108, ", "castor_angle = { ", None, "geometry.castor_angle"),
    "empty source": ('source = "Appendix B, p (car model)"', 'source = ""', None, "tyre.tyre_pressure"),
    "wrong unit": (
        'tyre_pressure = { value = 122500.0, unit = "Pa"',
        'tyre_pressure = { value = 1.225, unit = "bar"',
        None,
        "tyre.tyre_pressure",
    ),
    "angle in degrees": (
        'kingpin_inclination = { value = 0.219, unit = "rad"',
        'kingpin_inclination = { value = 12.5, unit = "deg"',
        None,
        "geometry.kingpin_inclination",
    ),
    "negative chassis mass": (
        "chassis_mass = { value = 468.4",
        "chassis_mass = { value = -468.4",
        "[cases.offset_44_5mm]",
        "cases.offset_44_5mm.chassis_mass",
    ),
    "negative assembly mass": (
        "steering_assembly_mass = { value = 40.0",
        "steering_assembly_mass = { value = -40.0",
        None,
        "steering.steering_assembly_mass",
    ),
    "negative stiffness": (
        "radial_stiffness = { value = 160000.0",
        "radial_stiffness = { value = -160000.0",
        None,
        "tyre.radial_stiffness",
    ),
    "zero stiffness": (
        "column_torsional_stiffness = { value = 1000.0",
        "column_torsional_stiffness = { value = 0.0",
        None,
        "steering.column_torsional_stiffness",
    ),
    "negative pressure": (
        "tyre_pressure = { value = 122500.0",
        "tyre_pressure = { value = -122500.0",
        None,
        "tyre.tyre_pressure",
    ),
    "negative load": (
        "load_left = { value = 3065.0",
        "load_left = { value = -3065.0",
        "[cases.part_laden]",
        "cases.part_laden.load_left",
    ),
    "number as text": (
        "friction_coefficient = { value = 0.666",
        'friction_coefficient = { value = "0.666"',
        None,
        "tyre.friction_coefficient",
    ),
    "text in a list": ("loads = { value = [2000.0, 2600.0", 'loads = { value = [2000.0, "2.6 kN"', None, "rig.loads"),
    "boolean": (
        "hooke_joint_angle = { value = 0.45",
        "hooke_joint_angle = { value = true",
        None,
        "steering.hooke_joint_angle",
    ),
    # A tyre pressure in the registry's physical range, 0.1-10 bar: 1.225 (kg/m^3, the density of air, or the
    # pressure in bar) is refused, as every check of a value against its quantity's bounds.
    "tyre pressure of 1.225 Pa": (
        'tyre_pressure = { value = 122500.0, unit = "Pa"',
        'tyre_pressure = { value = 1.225, unit = "Pa"',
        None,
        "tyre.tyre_pressure",
    ),
    # An effect's own quantities are declared on the effect, not in the parameter file: a section for one, as files
    # had before, is refused naming it.
    "effect section in the file": (
        "\n[synthetic]\n",
        '\n[rack_damping]\ndamping = { value = 0.0, unit = "N s/m", source = "x" }\n\n[synthetic]\n',
        None,
        "rack_damping",
    ),
    # Statics: the two wheel loads carry (chassis_mass + unsprung_mass) g, about 6.3 kN for the part-laden car's
    # 540 kg chassis; a 29 kN wheel load cannot be.
    "wheel load of 29 kN": (
        "load_left = { value = 3065.0",
        "load_left = { value = 29000.0",
        "[cases.part_laden]",
        "cases.part_laden.load_left",
    ),
    # Statics: the load difference's moment about the centreline is the chassis weight's at y_cm.
    "mass centre against the loads": (
        "chassis_cg_y = { value = 0.0286",
        "chassis_cg_y = { value = 0.0386",
        "[cases.offset_44_5mm]",
        "cases.offset_44_5mm.chassis_cg_y",
    ),
    # An added case must carry every Table B1 entry; the first one it lacks is named.
    "incomplete case": (
        "[cases.offset_68_5mm]\n",
        '[cases.fully_laden]\nchassis_mass = { value = 600.0, unit = "kg", source = "choice" }\n\n'
        "[cases.offset_68_5mm]\n",
        None,
        "cases.fully_laden.chassis_cg_y",
    ),
}


def _write_defective(tmp_path: Path, defect: str) -> tuple[Path, str]:
    old, new, after, key = DEFECTS[defect]
    text = _edit(DEFAULT_PATH.read_text(encoding="utf-8"), old, new, after)
    path = tmp_path / "bad_parameters.toml"
    path.write_text(text, encoding="utf-8")
    return path, key


def _assert_one_line_naming(message: str, path: Path, key: str) -> None:
    assert "\n" not in message.strip()
    assert str(path) in message
    assert key in message


def test_shipped_file_loads(params):
    """The shipped file passes the schema and holds the five Table B1 cases in the paper's order."""
    assert params.path == DEFAULT_PATH
    assert params.case_names == TABLE_B1_CASES
    assert params.source("tyre.friction_coefficient").startswith("Appendix B")


def test_spacer_cases_move_the_wheel_centre_by_the_spacer(params):
    """Table B1: a spacer of thickness s moves the wheel centre outboard by s, y2 = 0.73 m + s, and the three
    spacer cases are the three spacers listed for Fig. A3 (12.7, 44.5, 68.5 mm)."""
    standard_y_m = params.case("unladen")["wheel_centre_y"]
    spacer_cases = [name for name in params.case_names if params.case(name)["extra_offset"] > 0.0]
    assert [params.case(name)["extra_offset"] for name in spacer_cases] == list(params["spacers.extra_offsets"])
    assert list(params["spacers.extra_offsets"]) == [0.0127, 0.0445, 0.0685]
    for name in spacer_cases:
        case = params.case(name)
        assert case["wheel_centre_y"] == pytest.approx(standard_y_m + case["extra_offset"], abs=1e-12)


@pytest.mark.parametrize("defect", sorted(DEFECTS))
def test_defect_is_refused_with_one_line_naming_file_and_key(tmp_path, defect):
    """Each kind of defect (unknown or missing key, missing field, wrong unit, non-physical sign, non-number)
    is refused with a ParameterError whose message is one line naming the file and the dotted key."""
    path, key = _write_defective(tmp_path, defect)
    with pytest.raises(ParameterError) as info:
        load_parameters(path)
    _assert_one_line_naming(str(info.value), path, key)


def test_table_b1_loads_satisfy_the_chassis_statics_to_printing_precision(params):
    """Table B1's wheel loads carry the front end's weight, (chassis_mass + unsprung_mass) g, to within the 1 N
    the loads are printed to, and their difference balances the chassis weight's moment at y_cm to within the
    0.1 mm y_cm is printed to (plus the loads' 1 N at the half track)."""
    g, unsprung_kg = params["vehicle.gravity"], params["vehicle.unsprung_mass"]
    for name in params.case_names:
        c = params.case(name)
        assert c["load_left"] + c["load_right"] == pytest.approx((c["chassis_mass"] + unsprung_kg) * g, abs=1.0)
        implied_cg_y_m = (c["load_right"] - c["load_left"]) * c["wheel_centre_y"] / (c["chassis_mass"] * g)
        tolerance_m = 0.05e-3 + 1.0 * c["wheel_centre_y"] / (c["chassis_mass"] * g)
        assert implied_cg_y_m == pytest.approx(c["chassis_cg_y"], abs=tolerance_m)


def test_an_effect_quantity_out_of_its_declared_bounds_is_refused(params):
    """An effect's own quantity is declared on the effect with its bounds (a rack's lash, half the free play of the
    mesh, is 0-0.5 mm in a worn rack; the bound is 5 mm): parameters used with the effects know it (its default
    reads 0, absent), and a lash of 0.5 m is refused in one line naming the key, as a value of the parameter file
    out of its bounds is. The parameter file alone knows no effect's quantity, whatever was imported or loaded
    before: the key is unknown there."""
    from parksteer.model.symbolic.components import resolve_effects, with_effect_quantities

    resolve_effects("+rack_lash")  # loading an effect registers nothing anywhere
    assert "rack_lash.lash" not in params.declared
    with pytest.raises(UsageError) as unknown:
        params.with_overrides({"rack_lash.lash": 1e-4})
    assert "unknown key" in str(unknown.value)
    with_effects = with_effect_quantities(params)
    assert with_effects["rack_lash.lash"] == 0.0  # declared default: absent
    with pytest.raises(UsageError) as info:
        with_effects.with_overrides({"rack_lash.lash": 0.5})
    message = str(info.value)
    assert "\n" not in message and message.startswith("rack_lash.lash:") and "non-physical" in message


def test_a_load_sum_two_newtons_off_is_refused(tmp_path):
    """The statics tolerance is the printing precision, not slack: moving 2 N onto one wheel of the unladen case
    (outside the 1 N the printed loads allow) is refused naming the case's load."""
    text = _edit(DEFAULT_PATH.read_text(encoding="utf-8"), "load_left = { value = 2698.0",
                 "load_left = { value = 2700.0", "[cases.unladen]")
    path = tmp_path / "off.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ParameterError) as info:
        load_parameters(path)
    _assert_one_line_naming(str(info.value), path, "cases.unladen.load_left")


def test_unknown_case_name_is_refused(params):
    """Asking for a case the file does not define is a user error naming the file and the case, on one line."""
    with pytest.raises(ParameterError) as info:
        params.case("fully_laden")
    _assert_one_line_naming(str(info.value), params.path, "fully_laden")


def test_missing_file_is_refused(tmp_path):
    """A parameter file that does not exist is a one-line user error naming it."""
    path = tmp_path / "absent.toml"
    with pytest.raises(ParameterError) as info:
        load_parameters(path)
    _assert_one_line_naming(str(info.value), path, "cannot read")


def _run(args: list[str], cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=300)


def test_check_params_accepts_shipped_file():
    """`parksteer check-params` on the shipped file exits 0 and reports the cases."""
    result = _run([str(BIN / "parksteer"), "check-params"])
    assert result.returncode == 0, result.stderr
    assert "unladen" in result.stdout
    assert result.stderr == ""


@pytest.mark.parametrize("defect", ["wrong unit", "tyre pressure of 1.225 Pa", "wheel load of 29 kN"])
def test_check_params_refuses_bad_file(tmp_path, defect):
    """`parksteer check-params bad.toml` exits with status 2 and prints exactly one line on stderr naming the
    file and the key, nothing on stdout: a wrong unit, a value outside the quantity's physical bounds (1.225 Pa
    of tyre pressure), wheel loads that contradict the chassis statics."""
    path, key = _write_defective(tmp_path, defect)
    result = _run([str(BIN / "parksteer"), "check-params", str(path)])
    assert result.returncode == 2
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1
    _assert_one_line_naming(lines[0], path, key)


FIGA3_OUTPUTS = ("figures/figA3.svg", "figures/figA3.csv", "results/figA3.json")


@pytest.mark.slow
def test_pipeline_refuses_bad_file_without_output(repo_root, tmp_path):
    """End to end: `snakemake figA3` with a defective parameter file is refused while the DAG is built, before
    any job runs: non-zero exit, exactly one error line naming file and key, and no figure file; the same workflow
    copy with the shipped file then builds Fig. A3 (so the absence is the refusal, not a broken rule)."""
    workdir = tmp_path / "workflow_copy"
    workdir.mkdir()
    shutil.copytree(repo_root / "workflow", workdir / "workflow")
    shutil.copytree(repo_root / "config", workdir / "config")
    (workdir / "src").symlink_to(repo_root / "src")
    bad_path, key = _write_defective(tmp_path, "angle in degrees")
    snakemake = [str(BIN / "snakemake"), "--cores", "1", "--directory", str(workdir)]
    snakemake += ["--snakefile", str(workdir / "workflow" / "Snakefile")]

    bad = _run([*snakemake, "figA3", "--config", f"parameters={bad_path}"])
    assert bad.returncode != 0
    error_lines = [line for line in bad.stderr.splitlines() if "error" in line.lower()]
    assert len(error_lines) == 1, bad.stderr[-2000:]
    _assert_one_line_naming(error_lines[0], bad_path, key)
    assert not (workdir / "logs" / "figA3.log").exists()  # refused before any job started
    for output in FIGA3_OUTPUTS:
        assert not (workdir / output).exists(), output

    good = _run([*snakemake, "figA3"])
    assert good.returncode == 0, good.stderr[-2000:]
    for output in FIGA3_OUTPUTS:
        assert (workdir / output).stat().st_size > 0, output
    summary = json.loads((workdir / "results" / "figA3.json").read_text())
    assert round(summary["cases"]["unladen"]["torque_at_right_lock_Nm"], 1) == 1.7
