"""The import of an assisted car's record: torsion-bar torque, motor current or torque, vehicle speed."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure.importers import load_record


def logger_file(tmp_path, header: str, units: str, rows: int = 200, current_scale: float = 1.0,
                name: str = "eps.csv"):
    """A logger export of an assisted car: a rack sweep, a torsion-bar torque that follows it, a motor current
    (20 A per N m of torque beyond the dead band) and a creeping speed (2 km/h)."""
    t = np.arange(rows) * 0.02
    rack_mm = 30.0 * np.sin(2 * np.pi * t / 4.0)
    torque = 2.0 * np.cos(2 * np.pi * t / 4.0)
    current = 20.0 * np.sign(torque) * np.maximum(np.abs(torque) - 0.5, 0.0) * current_scale
    lines = [header, units]
    for row in zip(t, rack_mm, torque, current, np.full(rows, 2.0)):
        lines.append(",".join(f"{v:.6f}" for v in row))
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path, {"time_s": t, "rack_m": rack_mm / 1000, "torque": torque, "current": current}


def test_assisted_logger_channels_map_by_their_names(tmp_path):
    """Unit conversion and the role of each channel: the torsion bar's torque becomes the record's torque, flagged
    as the torsion bar's (an assisted car has no other torque sensor), the current stays in amperes, km/h become
    m/s (2 km/h = 0.5556 m/s), mm become m."""
    path, expected = logger_file(tmp_path, "Time,RackPos,TorsionBarTorque,MotorCurrent,VehicleSpeed",
                                 "s,mm,N*m,A,km/h")
    m = load_record(path, case="unladen", surface="ground")
    assert m.torque_sensor == "torsion_bar"
    assert np.allclose(m.columns["handwheel_torque_Nm"], expected["torque"], atol=1e-6)
    assert np.allclose(m.columns["motor_current_A"], expected["current"], atol=1e-6)
    assert np.allclose(m.columns["vehicle_speed_mps"], 2.0 / 3.6, atol=1e-9)
    assert np.allclose(m.columns["rack_m"], expected["rack_m"], atol=1e-9)


def test_a_map_names_the_assisted_targets(tmp_path):
    """The same through an explicit map, with the motor's torque in N*cm instead of a current (1 N m = 100 N cm)."""
    path, expected = logger_file(tmp_path, "t,x,Ts,Mot,v", "s,mm,N*m,N*cm,km/h")
    m = load_record(path, "t[s]=time_s,x[mm]=rack_m,Ts[N*m]=torsion_bar_torque_Nm,Mot[N*cm]=motor_torque_Nm,"
                          "v[km/h]=vehicle_speed_mps",
                    case="unladen", surface="ground")
    assert m.torque_sensor == "torsion_bar"
    assert np.allclose(m.columns["motor_torque_Nm"], expected["current"] / 100.0, atol=1e-6)


@pytest.mark.parametrize(("header", "units", "scale", "message"), [
    ("Time,RackPos,TorsionBarTorque,MotorCurrent,VehicleSpeed", "s,mm,N*m,mA,km/h", 1.0,
     r"eps.csv: column 'motor_current_A', row \d+ \(line \d+\): .* beyond \+-500 A"),
    ("Time,RackPos,TorsionBarTorque,MotorCurrent,VehicleSpeed", "s,mm,N*m,V,km/h", 1.0,
     r"eps.csv: channel 'MotorCurrent': unit 'V' is not a unit of current"),
    ("Time,RackPos,SteerTorque,TorsionBarTorque,VehicleSpeed", "s,mm,N*m,N*m,km/h", 1.0,
     r"eps.csv: channels 'SteerTorque' \(handwheel_torque_Nm\) and 'TorsionBarTorque' \(torsion_bar_torque_Nm\) "
     r"are both a steering torque"),
    ("Time,RackPos,TorsionBarTorque,MotorCurrent,MotorTorque", "s,mm,N*m,A,N*m", 1.0,
     r"eps.csv: channels 'MotorCurrent' \(motor_current_A\) and 'MotorTorque' \(motor_torque_Nm\) are both"),
])
def test_bad_assisted_channels_are_refused_in_one_line(tmp_path, header, units, scale, message):
    """A current logged in mA but labelled A... (and the other defects) is refused with file, column and row."""
    path, _ = logger_file(tmp_path, header, units, current_scale=1000.0 if "mA" in units else scale)
    if "mA" in units:  # the unit row says mA: the values are fine; label them A to get the implausible case
        path.write_text(path.read_text().replace("s,mm,N*m,mA,km/h", "s,mm,N*m,A,km/h"))
    with pytest.raises(UsageError, match=message):
        load_record(path, case="unladen", surface="ground")
