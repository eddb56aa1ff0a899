"""A record's vehicle-speed channel sets the run's speed in compare (parksteer.diagnose.intake.with_record_speed)."""

from __future__ import annotations

import json

import pytest

from parksteer.cli import main

CREEP_KMH = 3.0


def _logged(tmp_path, name: str, speed_mps: list[float] | float | None) -> str:
    """A creeping car's simulated record (rack and torque), with a speed channel of `speed_mps` if given."""
    run = tmp_path / "creep.csv"
    if not run.exists():
        assert main(["simulate", "--case", "unladen", "--speed-kmh", str(CREEP_KMH), "--out", str(run), "--quiet"]) == 0
    lines = run.read_text(encoding="utf-8").splitlines()
    header = [line for line in lines if line.startswith("#")]
    rows = [line.split(",") for line in lines if not line.startswith("#")]
    keep = [rows[0].index(c) for c in ("time_s", "rack_m", "handwheel_torque_Nm")]
    out = [",".join(rows[0][i] for i in keep) + (",vehicle_speed_mps" if speed_mps is not None else "")]
    for k, row in enumerate(rows[1:]):
        speed = "" if speed_mps is None else f",{speed_mps[k] if isinstance(speed_mps, list) else speed_mps!r}"
        out.append(",".join(row[i] for i in keep) + speed)
    path = tmp_path / name
    path.write_text("\n".join(header + out) + "\n", encoding="utf-8")
    return str(path)


def _weighted_rms(capsys, path: str) -> float:
    assert main(["compare", path, "--json", "--quiet"]) == 0
    return json.loads(capsys.readouterr().out)["files"][0]["weighted_rms_Nm"]


def test_a_creeping_record_is_replayed_at_its_logged_speed(tmp_path, capsys):
    """Physical fact: once the wheel rolls a few contact lengths per radian of steer, the tyre's friction moment
    collapses (turn slip), so a record made at 3 km/h matches the model only at that speed. With the speed channel
    the replay of the car's own record leaves a weighted error of a few hundredths of a newton metre (the rack's
    spline at the reversals); without it (standstill assumed) several newton metres, the standstill moment."""
    at_speed = _weighted_rms(capsys, _logged(tmp_path, "with_speed.csv", CREEP_KMH / 3.6))
    standstill = _weighted_rms(capsys, _logged(tmp_path, "without.csv", None))
    assert at_speed < 0.05
    assert standstill > 3.0


def test_a_varying_speed_is_refused_naming_file_and_column(tmp_path, capsys):
    """The model takes one constant speed a run: a record that accelerates from 0 to 5 km/h is refused in one line."""
    path = _logged(tmp_path, "probe.csv", 0.0)
    n = sum(1 for line in open(path, encoding="utf-8") if not line.startswith("#")) - 1
    ramp = [5.0 / 3.6 * k / (n - 1) for k in range(n)]
    varying = _logged(tmp_path, "accelerating.csv", ramp)
    assert main(["compare", varying, "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "accelerating.csv" in err[0] and "vehicle_speed_mps" in err[0]


@pytest.mark.parametrize("speed_mps", [0.0, 0.01])
def test_standstill_speed_channel_changes_nothing(tmp_path, capsys, speed_mps):
    """Below 0.1 km/h the run is the standstill model itself: the same weighted error as without the channel."""
    base = _weighted_rms(capsys, _logged(tmp_path, "without.csv", None))
    assert _weighted_rms(capsys, _logged(tmp_path, "still.csv", speed_mps)) == base
