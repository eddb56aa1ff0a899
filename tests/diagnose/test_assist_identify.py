"""An electric assist identified from its car's log (parksteer.diagnose.identify, ``parksteer assist identify``).

The records are not made by the assisted model the identified file feeds: a quasi-static column EPS written in the
test (eps_truth.py: the torsion bar and a worm-gear motor sharing the column torque sample by sample over the manual
car's replay, a progressive map of its own form, the motor's Coulomb friction and rotor through the worm, the
control unit reading a sensor rounded to 0.01 N m with a zero offset, the current logged in 0.1 A steps), on the
Polo's vehicle file, whose gear data differ from the truth's (torque constant 0.05 against 0.055 N m/A, motor
friction 0.02 against 0.03 N m, rotor inertia 2e-4 against 3e-4 kg m^2, back-driven efficiency 0.80 against
0.76). Each test names the physical fact the identification must recover.
"""

from __future__ import annotations

import dataclasses
import tomllib

import numpy as np
import pytest

import eps_truth as et
from parksteer.cli import main
from parksteer.diagnose.identify.assist_identify import identify_boost
from parksteer.model.symbolic.components import discover_effects
from parksteer.vehicle import load_vehicle

discover_effects()
pytestmark = pytest.mark.slow  # each test replays the car (a few seconds)


@pytest.fixture(scope="module")
def baseline(tmp_path_factory):
    truth = et.Truth()
    path = et.truth_record(truth, tmp_path_factory.mktemp("eps") / "baseline.csv")
    return truth, path, identify_boost([path], et.POLO)


def test_map_within_its_intervals(baseline):
    """The control unit's map is recovered point by point: the truth's current (its own power law a (|R| - D)^1.6
    beyond D) at each identified point lies within the point's 95 % interval, the dead band's interval holds the
    truth's 0.45 N m, the map's centre is the sensor's zero the log reads (0), and the residual is the current's
    rounding (0.1 A / sqrt(12))."""
    truth, _, found = baseline
    torques = np.array(found.torques)
    expected = truth.current(torques)
    for t, e, (lo, hi) in zip(torques[2:], expected[2:], found.current_ci95[2:]):
        assert lo <= e <= hi, (t, e, lo, hi)
    assert found.dead_band.ci95[0] <= truth.dead_band <= found.dead_band.ci95[1]
    assert found.map_centre.ci95[0] <= 0.0 <= found.map_centre.ci95[1]
    assert found.map_rms_A < 1.2 * truth.current_step / np.sqrt(12)
    assert found.beyond_map == ()


def test_gear_numbers_recovered(baseline):
    """The column balance fixes what the file had wrong: the product k_t eta N (the truth's 0.055 x 0.85 x 18 =
    0.8415 N m/A, the file's 0.765) within 0.5 %, the motor's Coulomb friction (0.03 N m, the file's 0.02) and the
    sensor's zero offset (0.04 N m), the rotor's inertia (3e-4 kg m^2, the file's 2e-4) and the back-driven
    efficiency (0.76, the file's 0.80) within their intervals, and the rack friction the truth's car has (730 N); the
    identified assist at each point is the truth's delivered torque k_t eta N i within its interval and 1 % (or two
    steps of the torque, 0.02 N m, near the dead band)."""
    truth, _, found = baseline
    assert found.product.value == pytest.approx(truth.product, rel=5e-3)
    assert found.motor_friction.ci95[0] <= truth.motor_friction <= found.motor_friction.ci95[1]
    assert found.motor_friction.ci95[1] - found.motor_friction.ci95[0] < 0.02
    assert found.offset.ci95[0] <= truth.offset <= found.offset.ci95[1]
    assert found.offset.ci95[1] - found.offset.ci95[0] < 0.03
    assert found.rack_friction.ci95[0] <= 730.0 <= found.rack_friction.ci95[1]
    assert found.motor_inertia.ci95[0] <= truth.rotor_inertia <= found.motor_inertia.ci95[1]
    assert found.motor_inertia.ci95[1] < 3.5e-4 and found.motor_inertia.ci95[0] > 2.5e-4
    assert found.back_efficiency.ci95[0] <= truth.back_efficiency <= found.back_efficiency.ci95[1]
    assert found.back_efficiency.ci95[1] < 0.8
    delivered = truth.product * truth.current(np.array(found.torques))
    for d, a, (lo, hi) in zip(delivered[2:], found.assist[2:], found.assist_ci95[2:]):
        assert lo <= d <= hi and a == pytest.approx(d, rel=0.01, abs=0.02)


def test_hysteresis_reported(tmp_path):
    """A control unit that adds a friction-compensation current of 1 A in the direction the wheel turns gives a
    current no map of the torsion-bar torque holds: the identification says so (hysteresis beyond its interval),
    and reads the compensation as what it does mechanically, a negative motor friction (1 A x 0.055 N m/A x 0.85
    = -0.047 N m against the truth's +0.03)."""
    truth = dataclasses.replace(et.Truth(), hysteresis_current=1.0)
    found = identify_boost([et.truth_record(truth, tmp_path / "hysteresis.csv")], et.POLO)
    assert any(b.startswith("hysteresis") for b in found.beyond_map)
    assert found.hysteresis_A.ci95[0] > 0.3
    assert found.motor_friction.value < 0.0


def test_written_file(baseline, tmp_path, capsys):
    """`parksteer assist identify` writes the vehicle file again: it loads as the car, its [assist.boost] is the
    identified table, its torque constant carries the product through the file's efficiency and reduction, its
    motor friction the identified one, each entry's source naming the record; the boost line's quantities (gain,
    dead band, its corner smoothing) are gone, and the file's other entries are kept."""
    truth, path, found = baseline
    out = tmp_path / "polo_identified.toml"
    assert main(["assist", "identify", str(path), "--vehicle", str(et.POLO), "--out", str(out), "--quiet"]) == 0
    assert "product k_t eta N" in capsys.readouterr().out
    doc = tomllib.loads(out.read_text(encoding="utf-8"))
    assist = doc["assist"]
    assert "dead_band_smoothing" not in assist and "gain" not in assist
    assert assist["torsion_bar_stiffness"]["value"] == 115.0
    assert assist["torque_constant"]["value"] * 0.85 * 18.0 == pytest.approx(found.product.value, rel=1e-5)
    assert "baseline.csv" in assist["torque_constant"]["source"]
    assert "baseline.csv" in assist["boost"]["assist"]["source"]
    assert assist["motor_friction_torque"]["value"] == pytest.approx(found.motor_friction.value, rel=1e-5)
    params = load_vehicle(out)
    assert params["electric_assist_column.boost_assist_0_4"] == pytest.approx(found.assist[4], rel=1e-5)
    assert params["electric_assist_column.motor_friction_torque"] == pytest.approx(found.motor_friction.value,
                                                                                   rel=1e-5)


def test_record_without_current_refused(baseline, tmp_path, capsys):
    """A record with no motor current holds no map: refused in one line naming the file and the column, and nothing
    is written."""
    _, path, _ = baseline
    lines = path.read_text(encoding="utf-8").splitlines()
    record = tmp_path / "no_current.csv"
    record.write_text("\n".join(line if line.startswith("#") else line.rsplit(",", 1)[0] for line in lines
                                if "motor_current_A:" not in line) + "\n", encoding="utf-8")
    out = tmp_path / "out.toml"
    assert main(["assist", "identify", str(record), "--vehicle", str(et.POLO), "--out", str(out), "--quiet"]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no_current.csv" in err[0] and "motor_current_A" in err[0]
    assert not out.exists()


def test_angle_only_record(tmp_path):
    """A car's bus logs no rack: the handwheel angle in 0.1 deg steps (the column angle plus the twist of the column
    shaft and torsion bar in series) gives the rack through the torsion bar, and the gear's numbers come back as from
    the rack: the product within 0.5 %, the motor friction, the offset and the rotor inertia within their intervals."""
    truth = et.Truth()
    found = identify_boost([et.truth_record(truth, tmp_path / "angle_only.csv", angle_only=True)], et.POLO)
    assert found.product.value == pytest.approx(truth.product, rel=5e-3)
    for estimate, value in ((found.motor_friction, truth.motor_friction), (found.offset, truth.offset),
                            (found.motor_inertia, truth.rotor_inertia)):
        assert estimate.ci95[0] <= value <= estimate.ci95[1]


def test_a_record_in_memory_is_its_file(baseline):
    """A benchmark hands its records in memory: a Measurement identifies to the same numbers as the file it was
    read from (the same preparation: rack smoothing, noise floors)."""
    from parksteer.measure.importers import load_record

    truth, path, found = baseline
    again = identify_boost([load_record(path, None, params=load_vehicle(et.POLO))], et.POLO)
    assert again.product == found.product and again.motor_friction == found.motor_friction
    assert again.assist == found.assist and again.records == found.records


def test_a_value_the_balance_confirms_is_kept_and_written_as_measured(baseline, tmp_path):
    """A number of the gear whose 95 % interval holds the file's assumed value keeps that value, now measured: with
    the file's rotor inertia set to the truth's (3e-4 kg m^2 against the shipped 2e-4, which the records
    contradict), the identified file keeps 3e-4 and its source names the record and the interval, so a later
    diagnosis no longer replays it as assumed (nor tells the owner to run the identification just run); the band
    of the motor's friction, which a bus's records do not fix, stays the file's, assumed."""
    truth, path, found = baseline
    text = et.POLO.read_text(encoding="utf-8")
    vehicle = tmp_path / "polo.toml"
    vehicle.write_text(text.replace("motor_inertia = { value = 0.0002,", "motor_inertia = { value = 0.0003,"),
                       encoding="utf-8")
    again = identify_boost([path], vehicle)
    assert "motor_inertia" in again.kept and "motor_inertia" not in found.kept
    written = tomllib.loads(again.to_vehicle_toml(vehicle.read_text(encoding="utf-8")))["assist"]
    inertia = written["motor_inertia"]
    assert inertia["value"] == 0.0003 and inertia["provenance"] == "identified"
    assert "baseline.csv" in inertia["source"] and "holds the file's 0.0003" in inertia["source"]
    assert "friction_speed" not in written or written["friction_speed"].get("provenance", "assumed") == "assumed"


def test_a_data_sheets_product_stands_against_a_balance_read_at_the_wrong_tyre_friction(baseline, tmp_path):
    """The column balance reads the assist against the road's load, which scales with the tyre-ground friction as
    the assist scales with the product k_t eta N: the balance cannot tell the two apart. With the truth's torque
    constant given as a data sheet's (0.055 N m/A) and the file's tyre-ground friction 0.60 (the truth's car has
    0.666), the balance reads another product, the written file keeps the data sheet's, and the friction at which
    the balance would read the data sheet's is the car's own. Declared assumed instead, the same balance's product
    is written: only a value declared measured is held against it."""
    truth, path, _ = baseline
    text = et.POLO.read_text(encoding="utf-8")
    sheet = ('torque_constant = { value = 0.055, unit = "N m/A", source = "data sheet of the motor", '
             'provenance = "measured" }')
    text = "\n".join(sheet if line.startswith("torque_constant = ") else line for line in text.splitlines())
    friction = 'friction_coefficient = { value = 0.60, unit = "1", source = "assumed: not this car\'s" }'
    text = "\n".join(friction if line.startswith("friction_coefficient = ") else line for line in text.splitlines())
    vehicle = tmp_path / "sheet.toml"
    vehicle.write_text(text + "\n", encoding="utf-8")
    found = identify_boost([path], vehicle)
    product = 0.055 * 0.85 * 18.0
    assert "torque_constant" in found.kept
    assert abs(found.balance_product / product - 1.0) > 0.05  # the balance alone would overturn the data sheet
    agree = found.tyre_friction + (product - found.balance_product) / found.product_per_tyre_friction
    assert agree == pytest.approx(0.666, abs=0.01)  # 0.665 measured: the balance is linear in the friction
    assumed = tmp_path / "assumed.toml"
    assumed.write_text(text.replace('provenance = "measured"', 'provenance = "assumed"') + "\n", encoding="utf-8")
    assert "torque_constant" not in identify_boost([path], assumed).kept
