"""The measured handwheel angle as a second signal of the diagnosis (DiagnosisSettings.use_handwheel_angle).

The records are made by a free simulation (the hand turns the wheel, the column twists, the rack follows:
the other drive mode than the replay that analyses them), logged with the torque on the paper's 8-bit
converter, the rack on a 12-bit one and the angle on a sensor of its own (14 bits over +-16 rad: a step of
0.11 degree). With the rack prescribed a rack lash cannot change the torque (the lash sits between the rack
and the hand), and the column's stiffness does not enter the replayed torque at all: only the angle against
the rack shows either. What each test checks is the physics the diagnosis must recover: a hidden lash is named
and sized, a record with nothing hidden is at its floor, a column 30 % softer than the parameter file's is
measured as such.
"""

from __future__ import annotations

import dataclasses
import json
import math

import jsonschema
import numpy as np
import pytest

from parksteer.cli import main
from parksteer.diagnose.problem import prepare_file
from parksteer.reporting.report import SCHEMA_PATH, diagnosis_dict
from parksteer.reporting.pages import html_report, markdown_report
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.measure.io import write_measurement
from parksteer.model.symbolic.components import discover_effects
from parksteer.synthetic.datasets import clean_run, hand
from parksteer.synthetic.example import example_logger
from parksteer.synthetic.logger import synthetic_measurement

WITH_ANGLE = dataclasses.replace(DEFAULT_SETTINGS, use_handwheel_angle=True)
ANGLE_BITS, ANGLE_NOISE_RAD = 14, 2e-4  # a 0.11-degree steering angle sensor with a little noise
RACK_BITS, RACK_NOISE_M = 12, 2e-5  # a 12-bit rack (0.05 mm): an 8-bit rack's smoothing is off by 0.3 mm at the
# locks, 0.07 rad of handwheel angle, more than the replay ensemble's spread shows (the angle sees G = 186 rad/m)
# Base parameters moved off the parameter file's values, as a real car's would be: a diagnosis must calibrate them.
OFF_NOMINAL = {"tyre.friction_coefficient": 0.70, "steering.rack_friction_force": 650.0,
               "tyre.carcass_torsional_stiffness": 800.0}


def angle_record(params, effects=None, overrides=None, seed: int = 11):
    """One unladen cycle on the ground, hand-driven, logged with its own angle and rack converters."""
    clean = clean_run(params, "unladen", "ground", hand(params, seed), effects, overrides)
    logger = example_logger(params)
    logger = dataclasses.replace(logger, seed=seed + 50, column_bits={"handwheel_angle_rad": ANGLE_BITS,
                                                                      "rack_m": RACK_BITS},
                                 noise_rms={**logger.noise_rms, "handwheel_angle_rad": ANGLE_NOISE_RAD,
                                            "rack_m": RACK_NOISE_M})
    return synthetic_measurement(clean["time_s"], {k: v for k, v in clean.items() if k != "time_s"}, logger,
                                 case="unladen", surface="ground", source="synthetic: tests/diagnose/test_angle.py")


@pytest.fixture(scope="module")
def lash_record(params):
    lash_m = 0.0002
    return angle_record(params, "+rack_lash", {**OFF_NOMINAL, "rack_lash.lash": lash_m}), lash_m


def test_a_hidden_lash_is_named_and_sized_with_the_angle_and_unobservable_without(lash_record, params):
    """A lash of 0.2 mm (a band of 0.075 rad of handwheel angle) hidden in a free run. Without the angle the
    replayed torque cannot see it (it is listed unobservable); with the angle the diagnosis names rack_lash, by a
    BIC gain far above the threshold of 10, its fitted size is the hidden 0.2 mm within 10 % (the hand's crossing
    of the band, which the rack and torque do not time, is fitted as a quick one), and the refit's column
    stiffness is the parameter file's (within 10 %: the calibrated base column had softened to mimic the band)."""
    measurement, lash_m = lash_record
    registry = {k: v for k, v in discover_effects().items() if k in ("rack_lash", "column_friction", "rack_damping")
                or v.in_default_set}
    torque_only = diagnose([prepare_file(measurement, label="lash")], params, registry=registry)
    assert "rack_lash" in torque_only.unobservable

    found = diagnose([prepare_file(measurement, label="lash")], params, registry=registry, settings=WITH_ANGLE)
    result = diagnosis_dict(found)
    assert result["verdict"] == "missing" and result["effect"] == "rack_lash", result["verdict"]
    best = result["ranking"][0]
    assert best["effect"] == "rack_lash" and best["delta_bic"] > 100.0
    fitted = best["parameters"]["rack_lash.lash"]
    low, high = fitted["ci95"]
    assert abs(fitted["value"] / lash_m - 1.0) < 0.1 and high - low < 0.3 * lash_m
    stiffness = best["parameters"]["steering.column_torsional_stiffness"]["value"]
    assert abs(stiffness / params["steering.column_torsional_stiffness"] - 1.0) < 0.1
    assert result["angle"]["files"] == ["lash"]
    assert result["selection"]["samples"] == 2 * measurement.n_samples  # n counts both signals


def test_a_soft_column_is_measured_and_nothing_else_is_found(params, tmp_path, capsys):
    """Nothing hidden but a column 30 % softer than the parameter file's (700 N m/rad) and off-nominal base
    parameters, diagnosed from the command line with --angle: the verdict is adequate (no candidate evidenced, the
    weighted error at the floor), the calibrated stiffness's 95 % interval holds 700 and not the file's 1000, the
    Hooke joint's phase (the file's 0, hidden) is found within 0.05 rad (the angle against the rack shows where
    the joint's ripple falls) and its angle (Appendix B's, hidden) within its interval, the angle's weighted error is within 30 % of its noise floor, and the report gives
    the angle's floor (a 14-bit step over +-16 rad, 32 / 16383 rad) and its residual in degrees. The JSON keeps to
    its schema; the markdown and HTML reports name the angle too."""
    path = tmp_path / "soft_column.csv"
    write_measurement(path, angle_record(params, None, {**OFF_NOMINAL, "steering.column_torsional_stiffness": 700.0},
                                         seed=23), params)
    assert main(["diagnose", str(path), "--angle", "--json", "--jobs", "1"]) == 0
    captured = capsys.readouterr()
    assert "handwheel angle fitted beside the torque in 1 of 1 file(s)" in captured.err
    result = json.loads(captured.out)
    jsonschema.validate(result, json.loads(SCHEMA_PATH.read_text(encoding="utf-8")))
    assert result["verdict"] == "adequate"
    low, high = result["calibrated"]["steering.column_torsional_stiffness"]["ci95"]
    assert low < 700.0 < high < 1000.0
    floor = result["files"][0]["angle"]["noise_floor"]
    assert floor["quantisation_step"] == pytest.approx(32.0 / (2**ANGLE_BITS - 1))
    phase_low, phase_high = result["calibrated"]["steering.hooke_joint_phase"]["ci95"]
    assert phase_low < params["steering.hooke_joint_phase"] < phase_high and phase_high - phase_low < 0.05
    # the joint's angle (Appendix B's 0.45 rad, hidden as it is) sets the ripple's depth: found within 10 %
    alpha = result["calibrated"]["steering.hooke_joint_angle"]
    assert alpha["ci95"][0] < params["steering.hooke_joint_angle"] < alpha["ci95"][1]
    assert alpha["ci95"][1] - alpha["ci95"][0] < 0.1 * params["steering.hooke_joint_angle"]
    angle = result["statistics"]["calibrated"]["angle"]
    assert angle["rms_deg"] == pytest.approx(math.degrees(angle["rms_rad"]))
    assert angle["weighted_rms_rad"] < 1.3 * angle["noise_floor_rad"]
    assert "## Handwheel angle" in markdown_report(result)  # the readable reports say it too
    assert "Handwheel angle fitted beside the torque in soft_column.csv" in html_report(result, [], [])


def test_without_the_angle_setting_an_angle_channel_changes_nothing(lash_record, params):
    """Off (the default), the diagnosis is the torque's alone: a record's JSON is the same with its angle channel as
    with the channel removed (the timings aside)."""
    measurement, _ = lash_record
    registry = {k: v for k, v in discover_effects().items() if v.in_default_set}  # the calibration is the test
    stripped = dataclasses.replace(measurement, columns={k: v for k, v in measurement.columns.items()
                                                         if k != "handwheel_angle_rad"})
    results = []
    for m in (measurement, stripped):
        result = diagnosis_dict(diagnose([prepare_file(m, label="record")], params, registry=registry))
        result["cost"]["timings_s"] = {}
        results.append(json.dumps(result, sort_keys=True))
    assert results[0] == results[1]
    assert "angle" not in json.loads(results[0])


def test_angle_asked_for_without_an_angle_is_one_line(params, tmp_path, capsys):
    """--angle on a record with no handwheel angle beside its rack is refused before any replay: one line naming
    the file, exit status 2."""
    measurement = angle_record(params, None, dict(OFF_NOMINAL), seed=5)
    path = tmp_path / "no_angle.csv"
    write_measurement(path, dataclasses.replace(measurement, columns={k: v for k, v in measurement.columns.items()
                                                                      if k != "handwheel_angle_rad"}), params)
    assert main(["diagnose", str(path), "--angle", "--json", "--jobs", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(path) in err and "--angle needs a handwheel angle" in err
