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

DATA = Path(__file__).resolve().parents[2] / "data/vehicles"
POLO, GOLF_IV = DATA / "polo_vi.toml", DATA / "golf_iv.toml"

# A Golf-sized car (the issue's: 860 kg front axle, ratio 14.1, 2.1 turns; VW Golf VII track, axis and tyre).
GOLF = ["--front-axle-mass-kg", "860", "--track-m", "1.549", "--kingpin-inclination-deg", "14", "--castor-deg", "7",
        "--scrub-radius-m", "0.01", "--tyre-size", "205/55R16", "--tyre-pressure-bar", "2.3",
        "--steering-ratio", "14.1", "--lock-turns", "2.1"]


def test_new_with_assist_writes_given_and_assumed_values(tmp_path):
    """The specification's values (reduction, motor limit, boost points) land in [assist] as given; the rest is
    marked assumed; the boost points are written as the table [assist.boost] (the origin added in front), not
    fitted by a line: the table gives each point's assist, the straight line's gain is off."""
    out = tmp_path / "golf.toml"
    assert main(["vehicle", "new", "--out", str(out), *GOLF, "--assist", "column", "--assist-reduction", "16.5",
                 "--assist-motor-torque-Nm", "3.5", "--assist-boost", "1:0,2:3,3:10"]) == 0
    params = load_vehicle(out)
    assert check_assist(params) == "electric_assist_column"
    assert "[assist.boost]" in out.read_text(encoding="utf-8")
    assert params["electric_assist_column.reduction_ratio"] == 16.5
    assert params["electric_assist_column.motor_torque_limit"] == 3.5
    assert params["electric_assist_column.gain"] == 0.0
    table = [params[f"electric_assist_column.boost_{k}"] for k in
             ("torque_0", "torque_1", "torque_2", "torque_3", "assist_0_0", "assist_0_1", "assist_0_2", "assist_0_3")]
    assert table == [0.0, 1.0, 2.0, 3.0, 0.0, 0.0, 3.0, 10.0]
    assert params.source("electric_assist_column.efficiency").startswith("assumed")


def test_boost_points_in_motor_torque_become_the_assist_at_the_column(tmp_path):
    """A boost curve given as motor torque is the assist eta N T_m at the column: the file's table carries the
    motor's points times eta N (0.85 x 18 = 15.3 at the defaults), not the motor torque read as a column torque."""
    out = tmp_path / "golf.toml"
    assert main(["vehicle", "new", "--out", str(out), *GOLF, "--assist", "column", "--assist-boost",
                 "0.5:0,1.5:0.2,3:1", "--assist-boost-unit", "motor"]) == 0
    params = load_vehicle(out)
    check_assist(params)
    assert params["electric_assist_column.boost_assist_0_2"] == pytest.approx(0.2 * 15.3)
    assert params["electric_assist_column.boost_assist_0_3"] == pytest.approx(15.3)
    # a column assist's points are not pinion torques: refused in one line (exit status 2)
    assert main(["vehicle", "new", "--out", str(tmp_path / "x.toml"), *GOLF, "--assist", "column",
                 "--assist-boost", "0.5:0,1:2", "--assist-boost-unit", "pinion"]) == 2


def test_polo_progressive_table_drives_the_motor_as_the_table_says(tmp_path):
    """The Polo's [assist.boost] is a progressive table at the column: simulated with its assist, the motor's torque
    against the torsion-bar torque is the table's assist over eta N, read by an independent monotone cubic
    (SciPy's PCHIP through the mirrored points), within 1 % wherever the motor gives more than 0.05 N m."""
    from scipy.interpolate import PchipInterpolator
    import tomllib

    boost = tomllib.loads(POLO.read_text(encoding="utf-8"))["assist"]["boost"]
    t, a = boost["torsion_bar_torque"]["value"], boost["assist"]["value"]
    curve = PchipInterpolator([-x for x in t[:0:-1]] + t, [-y for y in a[:0:-1]] + a)
    params = load_vehicle(POLO)
    name = check_assist(params)
    result = simulate(params.case_names[0], effects=f"+{name}", params=params)
    c = result.columns
    scale = params[f"{name}.efficiency"] * params[f"{name}.reduction_ratio"]
    expected = curve(c["torsion_bar_torque_Nm"]) / scale
    used = np.abs(expected) > 0.05
    assert np.max(np.abs(c["torsion_bar_torque_Nm"])) > 2.0
    assert np.max(np.abs(c["motor_torque_Nm"][used] / expected[used] - 1.0)) < 0.01


def test_golf_valve_table_sets_the_pressure_as_the_table_says():
    """The Golf IV's [assist.boost] is its rotary valve's progressive characteristic in bar: simulated with its
    assist, the pressure against the torsion-bar torque is the table's (bar x 1e5), read by an independent monotone
    cubic (SciPy's PCHIP through the mirrored points), within 1 % wherever the valve gives more than 1 bar."""
    from scipy.interpolate import PchipInterpolator
    import tomllib

    boost = tomllib.loads(GOLF_IV.read_text(encoding="utf-8"))["assist"]["boost"]
    assert boost["assist"]["unit"] == "bar"
    t, p = boost["torsion_bar_torque"]["value"], [b * 1e5 for b in boost["assist"]["value"]]
    curve = PchipInterpolator([-x for x in t[:0:-1]] + t, [-y for y in p[:0:-1]] + p)
    params = load_vehicle(GOLF_IV)
    name = check_assist(params)
    result = simulate(params.case_names[0], effects=f"+{name}", params=params)
    c = result.columns
    expected = curve(c["torsion_bar_torque_Nm"])
    used = np.abs(expected) > 1e5
    assert np.max(np.abs(c["torsion_bar_torque_Nm"])) > 2.0
    assert np.max(np.abs(c["pressure_Pa"][used] / expected[used] - 1.0)) < 0.01


def test_new_hydraulic_with_boost_points_writes_the_valve_table_in_bar(tmp_path):
    """A hydraulic gear's --assist-boost points are its valve's pressure in bar: written as the table
    [assist.boost] (unit bar, the origin added in front), read in Pa, the valve's straight line off; a file that
    gives both a table and a valve slope is refused naming the file."""
    out = tmp_path / "hps.toml"
    assert main(["vehicle", "new", "--out", str(out), *GOLF, "--assist", "hydraulic", "--assist-boost",
                 "0.5:0,2:20,3.5:60"]) == 0
    text = out.read_text(encoding="utf-8")
    assert 'unit = "bar"' in text and "valve_slope" not in text
    params = load_vehicle(out)
    assert check_assist(params) == "hydraulic_assist"
    assert params["hydraulic_assist.valve_slope"] == 0.0
    assert [params[f"hydraulic_assist.boost_assist_0_{k}"] for k in range(4)] == [0.0, 0.0, 2.0e6, 6.0e6]
    out.write_text(text.replace('type = "hydraulic"', 'type = "hydraulic"\nvalve_slope = { value = 1.5e6, unit = '
                                '"Pa/(N m)", source = "x" }'))
    with pytest.raises(ParameterError, match=r"hps.toml: assist: a boost table and a valve slope"):
        load_vehicle(out)
    # the unit --assist-boost-unit names is an electric gear's
    assert main(["vehicle", "new", "--out", str(tmp_path / "x.toml"), *GOLF, "--assist", "hydraulic",
                 "--assist-boost", "0.5:0,2:20", "--assist-boost-unit", "motor"]) == 2


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


def test_sizing_with_a_speed_dependent_gain(tmp_path):
    """With a speed-sensitive boost curve the Polo has one assist: its parking gain G_0, sized at standstill, falls
    as G_0 / (1 + (v / v_half)^2) as the car creeps. With v_half = 3 km/h the gain at 3 km/h is half the parking
    gain, and quasi-statically the driver's torque at each speed is (T_road + G(v) D) / (1 + G(v)) beyond the dead
    band D, the road torque T_road the unassisted car's at that speed plus the motor's bearing friction through the
    worm gear: the study's driver torque at 1, 3 and 5 km/h agrees with it; at 5 km/h the gain is a quarter of the
    parking gain and the driver needs more than the 3 N m target, though the road torque is less than half."""
    out = tmp_path / "sizing"
    assert main(["assist", "size", "--vehicle", str(POLO), "--target-torque", "3", "--gain-half-speed-kmh", "3",
                 "--out-dir", str(out)]) == 0
    table, _ = read_csv(out / "sizing.csv")
    band, friction_column = 0.5, 18.0 * 0.02  # dead band, N T_f: the column assist's assumed defaults
    road = table["peak_handwheel_manual_Nm"] + friction_column
    parking_gain = (road[0] - 3.0) / (3.0 - band)  # the target met at standstill
    assert table["peak_handwheel_assisted_Nm"][0] == pytest.approx(3.0, rel=0.03)
    for speed, road_torque, driver in zip(table["speed_kmh"][1:], road[1:], table["peak_handwheel_assisted_Nm"][1:]):
        gain = parking_gain / (1.0 + (speed / 3.0) ** 2)
        assert driver == pytest.approx((road_torque + gain * band) / (1.0 + gain), rel=0.05)
    assert table["peak_handwheel_assisted_Nm"][-1] > 3.0 and road[-1] < road[0] / 2


def test_hydraulic_golf_iv_sizing(tmp_path):
    """The shipped hydraulic car (data/vehicles/golf_iv.toml) sized for 3 N m: the tyres need the same rack force
    whoever supplies it, so the assisted car's peak rack force at standstill (pinion and piston together) is the
    unassisted car's; the pressure that takes is the quasi-static demand, well below the car's relief valve (its
    pump suffices for parking); the driver's peak torque is the target, within the 3 % the quasi-static sizing
    leaves to the rack's inertia and dampers, at standstill and creeping."""
    from parksteer.sweep.assist_sizing import size_assist

    params = load_vehicle(GOLF_IV)
    assert check_assist(params) == "hydraulic_assist"
    study = size_assist(params, "kerb", 3.0, (0.0, 3.0))
    manual, assisted = study.standstill_manual, study.standstill_assisted
    manual_force = np.max(np.abs(manual.columns["handwheel_torque_Nm"]
                                 * manual.outputs()["column_angle_per_rack_rad_per_m"]))
    assert np.max(np.abs(assisted.columns["rack_force_N"])) == pytest.approx(manual_force, rel=0.005)
    pressure = np.max(np.abs(assisted.columns["pressure_Pa"]))
    assert pressure == pytest.approx(study.rows[0].pressure_Pa, rel=0.02)
    assert pressure < 0.5 * params["hydraulic_assist.relief_pressure"]
    for row in study.rows:
        assert row.peak_handwheel_assisted_Nm < 1.03 * 3.0


def test_new_with_a_speed_dependent_boost_curve(tmp_path):
    """A specification's speed at which the gain halves (km/h) lands in [assist] in m/s with the speed dependence
    on; a hydraulic gear's valve has no such curve, so the option is refused for it in one line."""
    out = tmp_path / "golf.toml"
    assert main(["vehicle", "new", "--out", str(out), *GOLF, "--assist", "column",
                 "--assist-gain-half-speed-kmh", "36"]) == 0
    params = load_vehicle(out)
    assert params["electric_assist_column.speed_dependence"] == 1.0
    assert params["electric_assist_column.gain_half_speed"] == pytest.approx(10.0)
    assert main(["vehicle", "new", "--out", str(tmp_path / "hps.toml"), *GOLF, "--assist", "hydraulic",
                 "--assist-gain-half-speed-kmh", "36"]) == 2


def test_sizing_reports_the_rack_force_over_the_friction_band(tmp_path, capsys):
    """The standstill load is mostly the tyres' bore torque, proportional to the tyre-ground friction: over the band
    0.67, 0.8, 1.0 the Polo's peak rack force and the motor torque it asks rise at every step; the rack's Coulomb
    friction is fully developed where the rack slides at the peak, so the force without it is the force less the
    file's 730 N; at 0.67 (the file's 0.666, nearly) the force is below the 3 kN of the class range and the command
    says so. Against the class range's ends the motor's torque is linear in the rack force, quasi-statically: the
    excess column torque F / c' less the target through the worm, (F / c' - T) / (N eta) plus the rotor's friction
    over eta, so 8 kN asks 5 kN / (c' N eta) more than 3 kN, c' the gear's d(column angle)/d(rack) (between 100
    and 300 rad/m for any current car's gear; the Polo's 125.5 rad/m through the Hooke joint)."""
    assert main(["assist", "size", "--vehicle", str(POLO), "--target-torque", "3", "--speeds-kmh", "0",
                 "--out-dir", str(tmp_path / "sizing")]) == 0
    out, err = capsys.readouterr()
    rows = [line.split() for line in out.splitlines() if line.strip()[:4] in ("0.67", "0.80", "1.00")]
    assert [r[0] for r in rows] == ["0.67", "0.80", "1.00"]
    force = [float(r[1]) for r in rows]
    without = [float(r[2]) for r in rows]
    motor = [float(r[3]) for r in rows]
    assert force[0] < force[1] < force[2] and motor[0] < motor[1] < motor[2]
    assert [f - w for f, w in zip(force, without)] == pytest.approx([730.0] * 3, abs=1.0)
    assert force[0] < 3000.0 and "warning: at tyre-ground friction 0.67" in err
    ends = [line.split() for line in out.splitlines() if line.split()[:1] in (["3000"], ["8000"])]
    assert [e[0] for e in ends] == ["3000", "8000"]
    params = load_vehicle(POLO)
    name = "electric_assist_column"
    gear = params[f"{name}.reduction_ratio"] * params[f"{name}.efficiency"]
    slope_lo, slope_hi = (5000.0 / (c * gear) for c in (100.0, 300.0))  # c' of any current gear lies in between
    rise = float(ends[1][1]) - float(ends[0][1])
    assert slope_hi < rise < slope_lo


@pytest.mark.slow  # derives the two models of the Polo with the nonlinear linkage on an empty cache: about 20 s of CPU
def test_a_linkage_ratio_rising_toward_lock_raises_the_wheels_share_of_the_rack_force(tmp_path, capsys):
    """A linkage steer = G x (1 + c (G x)^2) passes the road wheels' moments to the rack through d(steer)/dx =
    G (1 + 3 c (G x)^2): with c = 0.1 in the Polo's file ([linkage_nonlinearity]) the sizing runs carry the effect,
    and the standstill force without rack friction rises at every friction of the band. The tyre's bore moment,
    most of the load, is Coulomb and so the same at any steer angle: its share rises by at most the ratio's factor
    at lock, 1 + 3 c (G x_lock)^2 = 1.107 for the Polo's 0.597 rad; lifting, which grows with the wider steer at
    lock, adds a little more, so the whole rise stays below 1.2. A file giving c = 0 sizes exactly as the file
    without the key (the linear linkage is the default)."""
    text = POLO.read_text(encoding="utf-8")
    rows = {}
    for c in (None, 0.0, 0.1):
        path = tmp_path / f"polo_{c}.toml"
        extra = "" if c is None else (f"\n[linkage_nonlinearity]\ncubic_coefficient = {{ value = {c}, unit = \"1\", "
                                      "source = \"test\" }\n")
        path.write_text(text + extra, encoding="utf-8")
        assert main(["assist", "size", "--vehicle", str(path), "--target-torque", "3", "--speeds-kmh", "0",
                     "--out-dir", str(tmp_path / f"out_{c}")]) == 0
        out = capsys.readouterr().out
        rows[c] = [line.split()[:3] for line in out.splitlines() if line.strip()[:4] in ("0.67", "0.80", "1.00")]
    assert len(rows[None]) == 3 and rows[0.0] == rows[None]
    for linear, rising in zip(rows[None], rows[0.1]):
        ratio = float(rising[2]) / float(linear[2])
        assert 1.0 < ratio < 1.2
        assert float(rising[1]) > float(linear[1])
