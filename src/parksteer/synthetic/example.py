"""The example measurement file, data/measurements/example_unladen.csv: a synthetic measurement.

It is made from the multibody model (:func:`parksteer.model.numeric.simulate.simulate`) for the
``unladen`` case on the ground, as the paper's car test would have been logged:

- the hand turns the wheel through the Section 4 cycle with its speed wandering by up to 25 %
  (:func:`example_hand`, from the parameter file); the model takes that motion as the rack displacement it produces
  through a rigid column and the Hooke joint (:func:`parksteer.synthetic.standin.rack_of_hand`),
  and finds the handwheel torque, the handwheel angle (with the column twist) and the wheel
  loads that rack motion needs;
- the logger samples at 50 Hz with 8 bits over the full scales of :func:`example_logger` (from the parameter file), with
  analog noise of a few converter steps or less.

Every setting is written into the file's metadata. The full scales leave headroom over the
cycle's peaks (about 13 rad, 0.067 m, 19 N m, 2.9 kN).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..parameters import Parameters
from .hand import HandVariation, irregular_hand_profile
from .logger import LoggerSettings, synthetic_measurement
from ..measure.io import OPTIONAL_COLUMNS, REQUIRED_COLUMNS, Measurement, write_measurement
from ..measure.rack_spline import interpolate_rack
from .standin import rack_of_hand
from ..names import TORQUE



def example_logger(params: Parameters) -> LoggerSettings:
    """The logger of the synthetic measurements, from the [synthetic] section of the parameter file."""
    s = params.sections["synthetic"]
    full_scale = {
        "handwheel_angle_rad": s["full_scale_handwheel_angle"],
        "rack_m": s["full_scale_rack"],
        TORQUE: s["full_scale_torque"],
        "load_left_N": s["full_scale_load"],
        "load_right_N": s["full_scale_load"],
    }
    noise_rms = {
        "handwheel_angle_rad": s["noise_handwheel_angle"],
        "rack_m": s["noise_rack"],
        TORQUE: s["noise_torque"],
        "load_left_N": s["noise_load"],
        "load_right_N": s["noise_load"],
    }
    return LoggerSettings(
        sample_rate_hz=s["sample_rate"],
        full_scale=full_scale,
        noise_rms=noise_rms,
        seed=int(s["logger_seed"]),
        bits=int(s["logger_bits"]),
    )


def example_hand(params: Parameters) -> HandVariation:
    """The imperfect hand of the synthetic measurements, from the [synthetic] section of the parameter file."""
    s = params.sections["synthetic"]
    return HandVariation(
        speed_variation=s["hand_speed_variation"],
        components=int(s["hand_components"]),
        frequency_range_hz=tuple(s["hand_frequency_range"]),
        knots_per_stroke=int(s["hand_knots_per_stroke"]),
        seed=int(s["hand_seed"]),
    )


EXAMPLE_CASE = "unladen"


def example_measurement(params: Parameters, case: str = EXAMPLE_CASE) -> Measurement:
    """The example: the model driven by the rack of an irregular hand, logged by the example logger."""
    from ..model.numeric.simulate import simulate

    hand = irregular_hand_profile(params, example_hand(params), output_dt_s=0.002)
    # the hand's motion is smooth and finely sampled: a spline through its samples is the motion itself
    drive = interpolate_rack(hand.time_s, rack_of_hand(params, hand.angle_rad))
    result = simulate(case, surface="ground", rack_drive=drive, params=params, output_dt_s=0.01)
    kept = [name for name in REQUIRED_COLUMNS + OPTIONAL_COLUMNS if name != "time_s"]
    clean = {name: np.asarray(result.columns[name]) for name in kept}
    extra = dict(hand.metadata)
    extra["model"] = f"{result.header['model']}; components: {result.header['components']}"
    extra["model_key"] = result.header["model_key"]
    extra["drive"] = "the rack of the irregular hand (rigid column through the Hooke joint)"
    return synthetic_measurement(
        result.columns["time_s"],
        clean,
        example_logger(params),
        case=case,
        surface="ground",
        source="synthetic: parksteer.synthetic.example.example_measurement",
        extra_metadata=extra,
    )


def write_example(path: str | Path, params: Parameters) -> None:
    """Write the example measurement file."""
    write_measurement(path, example_measurement(params), params)
