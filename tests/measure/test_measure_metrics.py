"""Comparison metrics: residual statistics per phase, and the noise floor the data allow."""

from __future__ import annotations

import math

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure.converter import quantisation_step, quantise
from parksteer.synthetic.logger import resample
from parksteer.measure.metrics import (
    compare,
    compare_measurement,
    error_stats,
    estimate_noise_rms,
    interpolate_onto,
    noise_floor,
)
from parksteer.measure.phases import PHASES, find_phases
from parksteer.synthetic.example import example_hand, example_logger
from parksteer.synthetic.standin import quasi_static_cycle
from parksteer.synthetic.hand import irregular_hand_profile
from parksteer.synthetic.logger import synthetic_measurement

FULL_SCALE_NM = 25.0


@pytest.fixture(scope="module")
def clean_cycle(params):
    """A smooth torque cycle with reversal drops, wind-up knees and Hooke ripple (the stand-in), at 500 Hz."""
    hand = irregular_hand_profile(params, example_hand(params), output_dt_s=0.002)
    return quasi_static_cycle(params, "unladen", hand, "ground")


@pytest.fixture(scope="module")
def cycle_50hz(clean_cycle):
    t, cols = resample(clean_cycle["time_s"], clean_cycle, 50.0)
    return t, cols


def test_identical_signals_have_zero_error_in_every_phase(cycle_50hz):
    """A model equal to the measurement leaves no residual, overall or in any phase."""
    t, cols = cycle_50hz
    torque = cols["handwheel_torque_Nm"]
    phases = find_phases(t, cols["rack_m"], torque)
    result = compare(t, torque, torque.copy(), phases=phases)
    assert result.overall.rms == 0.0 and result.overall.peak == 0.0 and result.overall.mean == 0.0
    assert set(result.by_phase) == {"wind_up", "plateau", "reversal", "return"}
    for stats in result.by_phase.values():
        assert stats.rms == 0.0 and stats.peak == 0.0
    assert sum(s.samples for s in result.by_phase.values()) == t.size, "the phases partition the samples"


def test_a_known_offset_is_reported_as_that_offset(cycle_50hz):
    """Measured = model + 0.7 N m: bias, RMS and peak are 0.7 N m overall and in every phase."""
    t, cols = cycle_50hz
    model = cols["handwheel_torque_Nm"]
    phases = find_phases(t, cols["rack_m"], model)
    result = compare(t, model + 0.7, model, phases=phases)
    for stats in [result.overall, *result.by_phase.values()]:
        assert stats.mean == pytest.approx(0.7) and stats.rms == pytest.approx(0.7) and stats.peak == pytest.approx(0.7)
    below = compare(t, model - 0.7, model, phases=phases)
    assert below.overall.mean == pytest.approx(-0.7) and below.overall.rms == pytest.approx(0.7)


def test_error_stats_of_a_known_residual():
    """Residual (3, -4) at (1, 2) s: mean -0.5, RMS sqrt(12.5), peak 4 at 2 s; no samples gives NaN."""
    stats = error_stats(np.array([1.0, 2.0]), np.array([3.0, -4.0]))
    assert (stats.samples, stats.mean, stats.peak, stats.peak_time_s) == (2, -0.5, 4.0, 2.0)
    assert stats.rms == pytest.approx(math.sqrt(12.5))
    assert math.isnan(error_stats(np.array([]), np.array([])).rms)


@pytest.mark.parametrize("noise_rms", [0.1, 0.15, 0.3])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_noise_estimator_recovers_injected_analog_noise(cycle_50hz, noise_rms, seed):
    """Analog noise injected before 8-bit quantisation (step 0.196 N m) is recovered within 15 %,

    although the signal carries reversal drops, wind-up knees and Hooke ripple."""
    t, cols = cycle_50hz
    rng = np.random.default_rng(seed)
    measured = quantise(cols["handwheel_torque_Nm"] + rng.normal(0.0, noise_rms, t.size), FULL_SCALE_NM)
    floor = noise_floor(measured, quantisation_step(FULL_SCALE_NM))
    assert floor.analog_rms == pytest.approx(noise_rms, rel=0.15)
    assert floor.quantisation_rms == pytest.approx(2 * FULL_SCALE_NM / 255 / math.sqrt(12))
    assert floor.total_rms == pytest.approx(math.hypot(floor.quantisation_rms, floor.analog_rms))


def test_noise_estimator_without_quantisation_and_on_white_noise_alone():
    """On pure white noise the estimate is the noise RMS; a straight line has none."""
    rng = np.random.default_rng(4)
    assert estimate_noise_rms(rng.normal(0.0, 0.2, 5000)) == pytest.approx(0.2, rel=0.05)
    assert estimate_noise_rms(np.linspace(-3.0, 5.0, 500)) == pytest.approx(0.0, abs=1e-12)


def test_quantisation_alone_leaves_no_analog_noise(cycle_50hz):
    """A noiseless smooth signal after 8 bits shows almost no analog noise: the floor is the quantisation."""
    t, cols = cycle_50hz
    step = quantisation_step(FULL_SCALE_NM)
    floor = noise_floor(quantise(cols["handwheel_torque_Nm"], FULL_SCALE_NM), step)
    assert floor.analog_rms < 0.25 * step / math.sqrt(12)


def test_a_perfect_model_of_a_synthetic_measurement_sits_on_the_noise_floor(params, clean_cycle):
    """The clean source of a synthetic measurement, compared with it, misses by the noise floor alone:

    RMS residual / floor is 1 within the 15 % of the noise estimate."""
    time_s = clean_cycle["time_s"]
    columns = {k: v for k, v in clean_cycle.items() if k != "time_s"}
    measurement = synthetic_measurement(
        time_s, columns, example_logger(params), case="unladen", surface="ground", source="test"
    )
    result = compare_measurement(measurement, clean_cycle)
    assert result.noise_floor.quantisation_step == pytest.approx(2 * 25.0 / 255)
    assert result.overall.rms / result.noise_floor.total_rms == pytest.approx(1.0, abs=0.15)
    assert abs(result.overall.mean) < 3 * result.noise_floor.total_rms / math.sqrt(measurement.n_samples)
    summary = result.summary()
    assert set(summary["by_phase"]) <= set(PHASES) and summary["channel"] == "handwheel_torque_Nm"
    loads = compare_measurement(measurement, clean_cycle, channel="load_left_N")
    assert loads.overall.rms / loads.noise_floor.total_rms == pytest.approx(1.0, abs=0.15)


def test_a_model_that_does_not_cover_the_measurement_is_refused():
    """Interpolation never extrapolates: the model must be simulated over the whole measured time."""
    inside = interpolate_onto(np.array([0.5, 1.5]), np.array([0.0, 2.0]), np.array([0.0, 4.0]))
    np.testing.assert_allclose(inside, [1.0, 3.0])
    with pytest.raises(UsageError, match="the model covers 0 to 2 s but the measurement runs from 0 to 2.5 s"):
        interpolate_onto(np.array([0.0, 2.5]), np.array([0.0, 2.0]), np.array([0.0, 4.0]))
