"""parksteer compare: the model against measurement files, by phase, beside the noise floor."""

from __future__ import annotations

import json

import numpy as np
import pytest

from parksteer.cli import main
from parksteer.diagnose.compare import compare_files
from parksteer.diagnose.problem import load_files


@pytest.fixture(scope="module")
def own_data(written):
    """The paper's model, logged by the synthetic 8-bit logger: nothing hidden, parameters as in the file."""
    paths, truth = written("own_model", kind="null")
    return paths


def test_the_model_against_its_own_data_sits_at_the_noise_floor(own_data, params):
    """Replaying a measurement the model itself made leaves only the logger's noise: the weighted RMS error is
    the noise floor (quantisation step / sqrt(12) with the analog noise) within 15 %, and so is the plain RMS
    on the sliding plateau, where the replay is certain."""
    result = compare_files(load_files(own_data, params), params)
    summary = result.as_dict()["files"][0]
    floor = summary["noise_floor"]["total_rms"]
    assert 0.9 < summary["over_floor"] < 1.15
    assert summary["by_phase"]["plateau"]["rms"] < 1.2 * floor
    assert abs(summary["by_phase"]["plateau"]["mean"]) < 0.3 * floor
    # the logger's noise floor: a 25 N m full scale in 8 bits is a 0.196 N m step, 0.057 N m RMS, with 0.15 N m analog
    assert floor == pytest.approx(np.hypot(50.0 / 255 / np.sqrt(12.0), 0.15), rel=0.15)


def test_a_wrong_rack_friction_shows_as_a_sign_switching_offset(own_data, params):
    """200 N more rack friction in the model is 200 / 186.47 = 1.07 N m more torque against the motion: the mean
    residual on the plateau of each stroke is -1.07 N m times the stroke's direction (within the Hooke joint's
    +-11 % speed ratio)."""
    result = compare_files(load_files(own_data, params), params,
                           overrides={"steering.rack_friction_force": params["steering.rack_friction_force"] + 200})
    f, model = result.files[0], result.predictions[0]
    expected = 200.0 / params["steering.handwheel_to_rack_ratio"]
    for stroke in f.phases.strokes:
        plateau = slice(stroke.windup_stop, stroke.stop)
        offset = np.mean((f.torque_Nm - model)[plateau]) * stroke.direction
        assert offset == pytest.approx(-expected, rel=0.12)


def test_compare_command_writes_json_and_figure(own_data, tmp_path, capsys):
    """The command prints the comparison as JSON (per file, per phase, with the noise floor) and draws the figure."""
    plot = tmp_path / "compare.svg"
    assert main(["compare", str(own_data[0]), "--json", "--plot", str(plot)]) == 0
    result = json.loads(capsys.readouterr().out)
    entry = result["files"][0]
    assert entry["case"] == "unladen" and entry["surface"] == "ground"
    assert set(entry["by_phase"]) >= {"wind_up", "plateau", "reversal"}
    assert entry["weighted_rms_Nm"] >= entry["noise_floor"]["total_rms"] * 0.8
    assert plot.read_text(encoding="utf-8").startswith("<?xml")


@pytest.mark.parametrize(
    "extra",
    [
        ["--case", "no_such_case"],
        ["--effects=+no_such_effect"],
        ["--set", "steering.no_such=1"],
        ["--set", "steering.rack_friction_force=-5"],
        ["--set", "friction_force=5"],
    ],
)
def test_bad_arguments_are_one_line_errors_and_write_nothing(own_data, tmp_path, capsys, extra):
    """A bad case, effect or parameter is a usage error: status 2, one line on stderr, no figure written."""
    plot = tmp_path / "out.svg"
    assert main(["compare", str(own_data[0]), "--plot", str(plot), *extra]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
    assert not plot.exists()


def test_a_defective_file_is_refused_in_one_line(tmp_path, capsys):
    """A rack written in millimetres (beyond 0.2 m) or a missing file: status 2, one line naming the file."""
    bad = tmp_path / "mm.csv"
    rows = "\n".join(f"{0.02 * i},{0.5 * i},{0.1 * i}" for i in range(60))
    bad.write_text(f"# case: unladen\n# surface: ground\ntime_s,rack_m,handwheel_torque_Nm\n{rows}\n", encoding="utf-8")
    for path in (bad, tmp_path / "missing.csv"):
        assert main(["compare", str(path), "--json"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and path.name in err[0]


def test_diagnose_needs_somewhere_to_put_its_result(own_data, capsys):
    """diagnose without --json, --report or --plot would compute for nothing: a one-line usage error."""
    assert main(["diagnose", str(own_data[0])]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
