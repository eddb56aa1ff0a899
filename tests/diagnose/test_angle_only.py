"""Records with no rack channel (a car's own bus: handwheel angle and torque): the rack is derived from the angle.

The records are variations of :mod:`parksteer.synthetic.variations` (the hand drives the rack, the model's
prescribed-rack solve gives the torque and the handwheel angle, a logger rounds them: an 8-bit torque, a 14-bit
angle on +-16 rad), written without their rack column. What each test checks is the physics the derivation and the
diagnosis must respect: the rack follows the pinion, not the handwheel, and the column's twist between them lags
the torque through the column's damper; with the rack derived so, a record with nothing hidden is at its floor and
a hidden rack friction is named, as they are with the rack channel.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json

import numpy as np
import pytest

from parksteer.cli import main
from parksteer.measure.column import rack_from_angle
from parksteer.experiments.variations import hidden_strength
from parksteer.geometry import rack_from_handwheel
from parksteer.measure.io import Measurement, format_measurement
from parksteer.model.numeric.simulate import simulate
from parksteer.parameters import load_parameters
from parksteer.measure.converter import quantisation_step
from parksteer.synthetic.variations import variation_by_name, variation_rack, variation_record

SEED = 1


def _angle_only_record(params, effects=None, overrides=None) -> Measurement:
    """The angle_channel variation (50 Hz, 8-bit torque, 14-bit angle), its rack column removed."""
    hand, logger = variation_by_name("angle_channel").settings(SEED)
    record = variation_record(params, hand, logger, effects=effects, overrides=overrides)
    return Measurement(None, {k: v for k, v in record.columns.items() if k != "rack_m"}, record.metadata)


def _diagnose(tmp_path, record: Measurement) -> dict:
    path = tmp_path / "angle_only.csv"
    path.write_text(format_measurement(record), encoding="utf-8")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["diagnose", str(path), "--jobs", "1", "--quiet", "--json"]) == 0
    return json.loads(out.getvalue())


def test_the_rack_follows_the_pinion_through_the_damped_column():
    """The handwheel angle is the column angle plus a twist that obeys c dtwist/dt + k twist = T: through the
    damper the twist lags the torque by c / k (0.2 s), so at a reversal, where the torque swings, the static twist
    T / k is off by (c / k) dtwist/dt. Derived through the damped column (and the Hooke joint) the rack is the one
    that drove the car; through the static law it is off by more than the 14-bit angle's step over the ratio."""
    params = load_parameters()
    hand, _logger = variation_by_name("angle_channel").settings(SEED)
    result = simulate("unladen", surface="ground", rack_drive=variation_rack(params, hand), params=params,
                      output_dt_s=0.002)
    columns = {k: np.asarray(result.columns[k], dtype=float)
               for k in ("time_s", "rack_m", "handwheel_torque_Nm", "handwheel_angle_rad")}
    true_rack = columns.pop("rack_m")
    derived = rack_from_angle(Measurement(None, {**columns, "rack_m": np.zeros_like(true_rack)},
                                          {"rack_derived": "test"}), params).rack_m
    assert np.max(np.abs(derived - true_rack)) < 1e-9
    static = rack_from_handwheel(columns["handwheel_angle_rad"], columns["handwheel_torque_Nm"], params)
    angle_step_m = quantisation_step(16.0, 14) / params["steering.handwheel_to_rack_ratio"]
    assert np.max(np.abs(static - true_rack)) > 2.0 * angle_step_m


@pytest.mark.slow
def test_a_null_angle_only_record_is_adequate(tmp_path):
    """With nothing hidden the model replayed on the rack the angle gives explains the torque to its noise floor:
    the derived rack is the true one within the angle's rounding, and the replay's uncertainty is the angle
    logger's (its step and noise over the gear ratio)."""
    result = _diagnose(tmp_path, _angle_only_record(load_parameters()))
    assert result["verdict"] == "adequate", result["selection"]["calibrated_over_floor"]
    assert result["selection"]["calibrated_over_floor"] < 1.15


@pytest.mark.slow
def test_a_hidden_rack_friction_in_an_angle_only_record_is_named(tmp_path):
    """A rack stiction (breakaway above the sliding rack friction) changes the torque at every reversal of the
    rack; hidden at 3.5 torque converter steps RMS it is named from the angle-derived rack, as it is from a
    measured one (tests/diagnose: the variation benchmark)."""
    params = load_parameters()
    hand, logger = variation_by_name("angle_channel").settings(SEED)
    step = quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
    key, strength, _change, _observable = hidden_strength(params, [("unladen", "ground", hand, logger)], {},
                                                          "rack_stiction", 3.5 * step)
    result = _diagnose(tmp_path, _angle_only_record(params, "+rack_stiction", {key: strength}))
    assert result["verdict"] == "missing"
    assert result["effect"] == "rack_stiction"
