"""The diagnosis's one front door (parksteer.diagnose.intake): the command line, the workflow, experiments/ and the
case study take a record in through it, so one record gives one diagnosis whichever door it came in by."""

from __future__ import annotations

import json
import time

import pytest

from parksteer.cli import main
from parksteer.errors import UsageError
from parksteer.diagnose.intake import Intake, Request, intake
from parksteer.experiments.benchmark import diagnose_written
from parksteer.measure.io import read_measurement, write_measurement
from parksteer.parameters import load_parameters
from parksteer.reporting.report import diagnosis_dict, without_machine_times
from parksteer.synthetic.variations import variation_by_name, variation_record

PARAMS = load_parameters()
CREEP_KMH = 3.0


class _Stopped(Exception):
    """Raised in place of a diagnosis, once its intake is seen."""


def _intake_of(monkeypatch, run) -> Intake:
    """The intake `run` diagnoses: :meth:`Intake.diagnose` replaced by one that keeps it and stops there."""
    seen = []

    def stop(self, **options):
        seen.append(self)
        raise _Stopped

    with monkeypatch.context() as patched:
        patched.setattr(Intake, "diagnose", stop)
        with pytest.raises(_Stopped):
            run()
    (taken,) = seen
    return taken


@pytest.fixture(scope="module")
def creeping(tmp_path_factory):
    """A car's record made at 3 km/h (rack and torque), with its speed channel and without it: (with, without)."""
    folder = tmp_path_factory.mktemp("creep")
    run = folder / "simulated.csv"
    assert main(["simulate", "--case", "unladen", "--speed-kmh", str(CREEP_KMH), "--out", str(run), "--quiet"]) == 0
    lines = run.read_text(encoding="utf-8").splitlines()
    header = [line for line in lines if line.startswith("#")]
    rows = [line.split(",") for line in lines if not line.startswith("#")]
    keep = [rows[0].index(c) for c in ("time_s", "rack_m", "handwheel_torque_Nm")]
    paths = []
    for name, speed in (("with_speed.csv", f",{CREEP_KMH / 3.6!r}"), ("without.csv", "")):
        out = [",".join(rows[0][i] for i in keep) + (",vehicle_speed_mps" if speed else "")]
        out += [",".join(row[i] for i in keep) + speed for row in rows[1:]]
        (folder / name).write_text("\n".join(header + out) + "\n", encoding="utf-8")
        paths.append(str(folder / name))
    return tuple(paths)


def _names(effects) -> list[str]:
    return sorted(e.name for e in effects)


def _by_experiment(monkeypatch, path, folder) -> Intake:
    """The intake of the hidden-effect benchmark's diagnosis (experiments/benchmark.py) of the record at `path`,
    written into `folder` as the benchmark writes its records."""
    measurement = read_measurement(path, PARAMS)
    records = [(measurement.case, measurement.surface, measurement)]
    return _intake_of(monkeypatch, lambda: diagnose_written(PARAMS, records, folder, {}, folder / "truth.json",
                                                            folder / "diagnosis.json", time.perf_counter()))


def test_a_creeping_record_gets_turn_slip_through_the_command_line_and_through_experiments(creeping, tmp_path,
                                                                                          monkeypatch):
    """Physical fact: a tyre rolling at 3 km/h has lost most of its standstill friction moment (turn slip), so a
    record with a speed channel is diagnosed with the rolling tyre's turn slip and the creeping car's values. The
    command line (`parksteer diagnose`) and the benchmark of experiments/ both take the record in that way, with
    the same effects and the same parameter values; the record without its speed channel gets neither, by either
    door."""
    with_speed, without = creeping
    by_command = _intake_of(monkeypatch, lambda: main(["diagnose", with_speed, "--json", "--quiet"]))
    (tmp_path / "a").mkdir()
    by_experiment = _by_experiment(monkeypatch, with_speed, tmp_path / "a")
    assert "turn_slip" in _names(by_command.effects)
    assert _names(by_experiment.effects) == _names(by_command.effects)
    # the same creeping car (the benchmark writes the record again, its speed to the writer's 10 digits)
    for taken in (by_command, by_experiment):
        assert taken.params["run.vehicle_speed"] == pytest.approx(CREEP_KMH / 3.6, rel=1e-9)
        assert {k: v for k, v in taken.params.sections.items() if k != "run"} == \
            {k: v for k, v in by_command.params.sections.items() if k != "run"}
    assert PARAMS["run.vehicle_speed"] == 0.0

    standstill = _intake_of(monkeypatch, lambda: main(["diagnose", without, "--json", "--quiet"]))
    (tmp_path / "b").mkdir()
    standstill_experiment = _by_experiment(monkeypatch, without, tmp_path / "b")
    assert "turn_slip" not in _names(standstill.effects)
    assert _names(standstill_experiment.effects) == _names(standstill.effects)
    assert standstill.params.sections == PARAMS.sections
    assert standstill_experiment.params.sections == PARAMS.sections


def test_the_intake_refuses_what_the_command_line_refuses_in_one_line(creeping, tmp_path, capsys):
    """A precondition is the intake's, so a direct caller meets the command line's refusal: a record cut inside its
    first stroke, whose rack never reverses, holds no reversal to calibrate the friction on; the intake refuses it
    naming the file and the column, and the command line prints that one line and exits with status 2."""
    _, without = creeping
    lines = open(without, encoding="utf-8").read().splitlines()
    header = [line for line in lines if line.startswith("#")]
    rows = [line for line in lines if not line.startswith("#")]
    one_way = tmp_path / "one_way.csv"
    one_way.write_text("\n".join(header + rows[: len(rows) // 10]) + "\n", encoding="utf-8")
    rack = [float(row.split(",")[1]) for row in rows[1: len(rows) // 10]]
    steps = [b - a for a, b in zip(rack, rack[1:])]
    assert rack[-1] != rack[0] and (min(steps) >= 0.0 or max(steps) <= 0.0)  # the rack moves one way only
    with pytest.raises(UsageError) as refused:
        intake(Request([one_way], PARAMS))
    assert main(["diagnose", str(one_way), "--json", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"parksteer diagnose: error: {refused.value}"]
    assert "one_way.csv: column 'rack_m': the rack never reverses" in err[0]


@pytest.mark.slow
def test_the_command_line_and_a_direct_intake_give_the_same_diagnosis(tmp_path, capsys):
    """Both doors, one diagnosis: a record whose torque channel lags its rack by 10 ms, diagnosed by `parksteer
    diagnose --torque-lag --json` and by intake (torque_lag) then diagnose, gives the same JSON, byte for byte once
    the machine's times are removed (the same keys the pipeline removes)."""
    hand, logger = variation_by_name("lag_10ms_50Hz").settings(3)
    path = tmp_path / "lagged.csv"
    write_measurement(path, variation_record(PARAMS, hand, logger), PARAMS)
    assert main(["diagnose", str(path), "--torque-lag", "--json", "--quiet", "--jobs", "1"]) == 0
    by_command = json.loads(capsys.readouterr().out)
    direct = diagnosis_dict(intake(Request([path], PARAMS, torque_lag=True)).diagnose())
    assert without_machine_times(by_command) != by_command  # the times removed are there to remove
    assert [f["torque_lag_s"] for f in by_command["files"]] != [0.0]  # the option reached the method
    as_text = [json.dumps(without_machine_times(r), indent=1, allow_nan=False) for r in (by_command, direct)]
    assert as_text[0] == as_text[1]
