"""Bands on the headline numbers (parksteer.figures.bands): each number checked against physics, and each band
against what its input can and cannot move."""

from __future__ import annotations

import math

import numpy as np
import pytest

from parksteer.figures.bands import NUMBERS, band_table, compute_bands, hooke_speed_ratio
from parksteer.figures.model import cycle_summary, reversal_step
from parksteer.geometry import pinion_angle_from_column
from parksteer.model.numeric.simulate import simulate
from parksteer.tables import read_csv, write_csv


@pytest.fixture(scope="module")
def bands(params):
    return compute_bands(params)


@pytest.fixture(scope="module")
def nominal_run(params):
    return simulate("unladen", params=params).columns


def test_hooke_speed_ratio_is_the_derivative_of_the_joint_map(params):
    """Independent derivation: the closed-form speed ratio equals the numerical derivative of the geometry's
    pinion(column) map, and is 1/cos(alpha) with the yokes in the joint's plane, cos(alpha) a quarter turn on."""
    a = params["steering.hooke_joint_angle"]
    for phase in (0.0, 0.7):
        p = params.with_overrides({"steering.hooke_joint_phase": phase})
        column = np.linspace(-7.0, 7.0, 20001)
        numeric = np.gradient(pinion_angle_from_column(column, a, phase), column)
        assert np.max(np.abs(hooke_speed_ratio(p, column) - numeric)[1:-1]) < 1e-5
        assert hooke_speed_ratio(p, phase) == pytest.approx(1 / math.cos(a), rel=1e-12)
        assert hooke_speed_ratio(p, phase + math.pi / 2) == pytest.approx(math.cos(a), rel=1e-12)


def test_reversal_step_is_the_rack_friction_step_where_it_happens(params, nominal_run):
    """Physical fact: when the rack reverses, its friction F tanh(beta v) swings from +F to -F, a step of 2F at the
    rack, 2F/186.47 times the Hooke speed ratio at the handwheel. Measured across that swing (tanh from +0.99 to
    -0.99) the torque step is this within 2 %; the earlier T(lock - 0.2 s) - T(lock + 0.2 s) (9.97 N m) also holds
    the carcasses' unwinding and is more than 1 N m larger."""
    step = reversal_step(nominal_run, params)
    i_lock = int(np.argmax(nominal_run["rack_m"]))
    ratio = hooke_speed_ratio(params, nominal_run["column_angle_rad"][i_lock])
    expected = STEP * 2 * params["steering.rack_friction_force"] / params["steering.handwheel_to_rack_ratio"] * ratio
    assert step["step_Nm"] == pytest.approx(expected, rel=0.02)
    assert step["rack_friction_step_Nm"] == pytest.approx(expected, rel=0.005)
    assert step["window_s"][1] - step["window_s"][0] < 0.1  # the step happens within a tenth of a second
    summary = cycle_summary(nominal_run, params)
    assert summary["reversal_step_at_right_lock_Nm"] == step["step_Nm"]
    assert summary["drop_at_right_lock_reversal_Nm"] - step["step_Nm"] > 1.0


STEP = 0.99  # tanh(beta v) at the ends of the measured step: the rack friction share's swing is 0.99 of 2F


def test_lifting_share_agrees_with_a1_and_the_air_bearing_curve_holds_rack_friction(bands, params):
    """Physical facts: with the assembly's mass centre on the king-pin axis, the model's lifting share is equation
    (A1) through the Hooke joint to within a few per cent (the tread rings' 5 kg lift differently); the air-bearing
    torque as plotted in Fig. 16 sits above Fig. A3 by the rack friction, F/G_rack times the joint's speed ratio
    on the plateau (between cos(alpha) and 1/cos(alpha) of F/186.47)."""
    nominal = bands["nominal"]
    assert -3.0 < nominal["a1_deviation_pct"] < 0.0
    rack = params["steering.rack_friction_force"] / params["steering.handwheel_to_rack_ratio"]
    a = params["steering.hooke_joint_angle"]
    assert rack * math.cos(a) < nominal["air_bearing_above_a1_Nm"] < rack / math.cos(a)


def test_bands_contain_nominal_and_move_what_their_inputs_move(bands, params):
    """Each band spans its nominal value. The Hooke phase moves the near-lock torque by more than 2 N m (peak
    against trough of the speed ratio at the locks) and the reversal step by the ratio 1/cos^2(alpha) between
    its extremes; the wheel radius (0.263 against 0.30 m) changes the sign of the ground scrub and, with the
    wheels free to roll, nothing the model computes; the assembly's mass centre moves the lifting share only."""
    for key, _, _ in NUMBERS:
        low, high = bands["band"][key]
        assert low <= bands["nominal"][key] <= high
    phase = bands["inputs"]["hooke_phase"]["values"]
    assert max(phase["near_lock_Nm"]) - min(phase["near_lock_Nm"]) > 2.0
    a = params["steering.hooke_joint_angle"]
    assert max(phase["reversal_step_Nm"]) / min(phase["reversal_step_Nm"]) == pytest.approx(1 / math.cos(a) ** 2,
                                                                                              rel=0.03)
    radius = bands["inputs"]["wheel_radius"]["values"]
    assert bands["nominal"]["ground_scrub_mm"] < 0 < radius["ground_scrub_mm"][0]
    for key in ("plateau_Nm", "near_lock_Nm", "reversal_step_Nm", "lifting_share_Nm"):
        assert radius[key][0] == pytest.approx(bands["nominal"][key], rel=1e-3)
    cg = bands["inputs"]["assembly_cg"]["values"]
    assert cg["lifting_share_Nm"][0] < 0.95 * bands["nominal"]["lifting_share_Nm"]
    assert cg["tyre_share_Nm"][0] == pytest.approx(bands["nominal"]["tyre_share_Nm"], rel=1e-3)


def test_band_table_round_trips(bands, tmp_path):
    """The band table written as CSV reads back with one row per headline number, each input's low <= high."""
    path = tmp_path / "bands.csv"
    write_csv(path, band_table(bands))
    columns, _ = read_csv(path)
    assert len(columns["nominal"]) == len(NUMBERS)
    for name in bands["input_order"]:
        assert np.all(columns[f"{name}_low"] <= columns[f"{name}_high"])
    assert np.all(columns["band_low"] <= columns["nominal"]) and np.all(columns["nominal"] <= columns["band_high"])


def test_tyre_moment_about_the_steer_axis_scales_the_tyre_share_alone(bands, params):
    """Physical fact: the tread ring turns about the steer axis, so a patch moment M about the ground normal does
    work M n_z per unit turn, about the steer axis M; moving the moment's axis raises the tyre share by 1/n_z
    (n_z = cos(castor) cos(king-pin inclination) for a mirror-symmetric axis, 2.4 % here) and nothing else."""
    n_z = math.cos(params["geometry.castor_angle"]) * math.cos(params["geometry.kingpin_inclination"])
    axis = bands["inputs"]["tyre_moment_axis"]["values"]
    nominal = bands["nominal"]
    assert axis["tyre_share_Nm"][0] / nominal["tyre_share_Nm"] == pytest.approx(1 / n_z, rel=1e-3)
    assert axis["rack_share_Nm"][0] == pytest.approx(nominal["rack_share_Nm"], rel=1e-9)
    assert axis["plateau_Nm"][0] - nominal["plateau_Nm"] == pytest.approx(
        nominal["tyre_share_Nm"] * (1 / n_z - 1), rel=2e-3)
