"""A vehicle file with its power assist: ``[assist]``, ``parksteer vehicle new --assist``, the assisted car's torque."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from parksteer.cli import main
from parksteer.model.numeric.assist import check_assist, max_rack_force_N
from parksteer.model.numeric.simulate import simulate
from parksteer.parameters import ParameterError
from parksteer.tables import read_csv
from parksteer.vehicle import load_vehicle

# A Golf-sized car (the issue's: 860 kg front axle, ratio 14.1, 2.1 turns; VW Golf VII track, axis and tyre).
GOLF = ["--front-axle-mass-kg", "860", "--track-m", "1.549", "--kingpin-inclination-deg", "14", "--castor-deg", "7",
        "--scrub-radius-m", "0.01", "--tyre-size", "205/55R16", "--tyre-pressure-bar", "2.3",
        "--steering-ratio", "14.1", "--lock-turns", "2.1"]


def test_new_with_assist_writes_given_and_assumed_values(tmp_path):
    """The specification's values (reduction, motor limit, two boost points) land in [assist] as given; the rest is
    marked assumed; the boost points' line gives the gain (slope) and the dead band (its zero crossing)."""
    out = tmp_path / "golf.toml"
    assert main(["vehicle", "new", "--out", str(out), *GOLF, "--assist", "column", "--assist-reduction", "16.5",
                 "--assist-motor-torque-Nm", "3.5", "--assist-boost", "1:0,3:10"]) == 0
    params = load_vehicle(out)
    assert check_assist(params) == "electric_assist_column"
    assert params["electric_assist_column.reduction_ratio"] == 16.5
    assert params["electric_assist_column.motor_torque_limit"] == 3.5
    assert params["electric_assist_column.gain"] == pytest.approx(5.0)  # 10 N m over 2 N m
    assert params["electric_assist_column.dead_band"] == pytest.approx(1.0)
    assert params.source("electric_assist_column.efficiency").startswith("assumed")


def test_implausible_assist_is_refused_in_one_line(tmp_path):
    """An assist that could push the rack with 400 kN (a relief pressure given in Pa where bar was meant, say) is
    no car's: refused naming the file and the section."""
    out = tmp_path / "golf.toml"
    assert main(["vehicle", "new", "--out", str(out), *GOLF, "--assist", "hydraulic"]) == 0
    text = out.read_text().replace("relief_pressure = { value = 9000000.0", "relief_pressure = { value = 2.9e7")
    text = text.replace("piston_area = { value = 0.0008", "piston_area = { value = 0.005")
    out.write_text(text)
    with pytest.raises(ParameterError, match=r"golf.toml: assist: the largest rack force .* outside"):
        check_assist(load_vehicle(out))
    out.write_text(text.replace('type = "hydraulic"', 'type = "steam"'))
    with pytest.raises(ParameterError, match=r"golf.toml: assist.type: 'steam'"):
        load_vehicle(out)


def test_golf_with_default_column_assist_meets_the_service_manuals(tmp_path):
    """Plausibility against the real world: car makers' service manuals give 29-39 N at the rim (0.18 m radius),
    5-7 N m, for assisted steering at standstill; the Golf-sized car with its default (assumed) column assist
    lies there at the peak of the lock-to-lock cycle, while the same car without assistance needs about five
    times as much."""
    out = tmp_path / "golf.toml"
    assert main(["vehicle", "new", "--out", str(out), *GOLF, "--assist", "column"]) == 0
    params = load_vehicle(out)
    assert 5e3 < max_rack_force_N(params, "electric_assist_column") < 2e4
    assisted = simulate("kerb", effects="+electric_assist_column", params=params)
    manual = simulate("kerb", params=params)
    peak_assisted = np.max(np.abs(assisted.columns["handwheel_torque_Nm"]))
    peak_manual = np.max(np.abs(manual.columns["handwheel_torque_Nm"]))
    assert 5.0 <= peak_assisted <= 7.0
    assert peak_manual > 4 * peak_assisted
    # the motor stays below its limit: the boost curve's linear range sets the torque, not the saturation
    assert np.max(np.abs(assisted.columns["motor_torque_Nm"])) < params["electric_assist_column.motor_torque_limit"]


def test_sizing_study_of_the_polo(tmp_path, capsys):
    """The sizing study of the shipped Polo: the rack force falls as the car creeps (the rolling tyre), the motor
    torque follows the excess over the target through the worm gear (quasi-statically E / (eta N) plus the motor's
    friction over eta), and running the cycle again with the assist sized so leaves the driver within 5 % of the
    target: the quasi-static sizing holds in the dynamic model."""
    from pathlib import Path

    out = tmp_path / "sizing"
    assert main(["assist", "size", "--vehicle", str(Path(__file__).resolve().parents[2] / "data/vehicles/polo_vi.toml"),
                 "--target-torque", "3", "--out-dir", str(out)]) == 0
    assert "electric_assist_column" in capsys.readouterr().out
    table, _ = read_csv(out / "sizing.csv")
    assert list(table["speed_kmh"]) == [0.0, 1.0, 3.0, 5.0]
    assert np.all(np.diff(table["peak_rack_force_N"]) < 0)
    assert np.all(np.abs(table["peak_handwheel_assisted_Nm"] / 3.0 - 1) < 0.05)
    eta, n, friction = 0.85, 18.0, 0.02  # the column assist's assumed defaults
    excess = table["peak_handwheel_manual_Nm"] - 3.0
    assert np.allclose(table["motor_torque_Nm"], (excess / n + friction) / eta, rtol=1e-6)
    assert (out / "torque_against_rack.svg").stat().st_size > 0 and (out / "rack_force_against_speed.svg").exists()


def test_the_polos_assist_is_used_only_when_asked(tmp_path):
    """The shipped Polo carries a column assist, but a run of the file is the car without assistance unless
    --with-assist asks for it (its existing outputs unchanged). Asked for, the assist carries most of the road
    torque: beyond the dead band the driver keeps about 1/(1 + G) of it, so the peak falls below a third of the
    unassisted peak at the default gain of 6 (1/7 plus the dead band's share)."""
    polo = str(Path(__file__).resolve().parents[2] / "data/vehicles/polo_vi.toml")
    manual, assisted = tmp_path / "manual.csv", tmp_path / "assisted.csv"
    assert main(["simulate", "--vehicle", polo, "--out", str(manual)]) == 0
    assert main(["simulate", "--vehicle", polo, "--with-assist", "--out", str(assisted)]) == 0
    columns, header = read_csv(manual)
    assert "electric_assist_column" not in header["components"]
    peak = float(np.max(np.abs(columns["handwheel_torque_Nm"])))
    with_assist, header = read_csv(assisted)
    assert "electric_assist_column" in header["components"]
    assert float(np.max(np.abs(with_assist["handwheel_torque_Nm"]))) < peak / 3.0
    assert main(["simulate", "--case", "unladen", "--with-assist", "--out", str(assisted)]) == 2
