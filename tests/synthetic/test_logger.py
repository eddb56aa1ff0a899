"""The logger: 8-bit quantisation, analog noise, resampling, clipping, and the metadata it records."""

from __future__ import annotations

import math

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure.converter import add_noise, quantisation_step, quantise
from parksteer.synthetic.logger import LoggerSettings, degrade, resample, synthetic_measurement

FULL_SCALE = 25.0


def test_eight_bit_levels_span_the_full_scale():
    """256 levels from -FS to +FS inclusive: the step is 2 FS / 255, both ends are levels, zero is not."""
    sweep = quantise(np.linspace(-FULL_SCALE, FULL_SCALE, 100_001), FULL_SCALE)
    levels = np.unique(sweep)
    assert levels.size == 256
    assert levels[0] == -FULL_SCALE and levels[-1] == pytest.approx(FULL_SCALE, rel=1e-15)
    np.testing.assert_allclose(np.diff(levels), 2 * FULL_SCALE / 255, rtol=1e-9)
    assert quantisation_step(FULL_SCALE) == 2 * FULL_SCALE / 255
    zero_reads = quantise(np.array([0.0]), FULL_SCALE)[0]
    assert abs(zero_reads) == pytest.approx(FULL_SCALE / 255), "zero reads half a step off"


def test_beyond_full_scale_saturates():
    """A saturated converter reads its end level, however far beyond full scale the input is."""
    np.testing.assert_array_equal(quantise(np.array([-1e3, -26.0, 26.0, 1e3]), FULL_SCALE), [-25.0, -25.0, 25.0, 25.0])


def test_quantisation_error_is_uniform_with_rms_step_over_root_12():
    """For a signal busy over many steps, the rounding error is uniform on +-step/2 with RMS step/sqrt(12)."""
    rng = np.random.default_rng(11)
    x = rng.uniform(-0.9 * FULL_SCALE, 0.9 * FULL_SCALE, 200_000)
    step = 2 * FULL_SCALE / 255
    error = quantise(x, FULL_SCALE) - x
    assert np.abs(error).max() <= step / 2 * (1 + 1e-12)
    assert math.sqrt(np.mean(error**2)) == pytest.approx(step / math.sqrt(12), rel=0.005)
    counts, _ = np.histogram(error, bins=10, range=(-step / 2, step / 2))
    expected = x.size / 10
    chi2 = float(np.sum((counts - expected) ** 2 / expected))
    assert chi2 < 27.9, "chi-square, 9 degrees of freedom, 0.1 % level"


def test_noise_is_gaussian_with_the_stated_rms_and_reproducible():
    """Added noise has the stated RMS and zero mean; one seed gives one sequence."""
    values = np.full(100_000, 3.0)
    noisy = add_noise(values, 0.2, np.random.default_rng(5))
    assert np.std(noisy - 3.0) == pytest.approx(0.2, rel=0.01)
    assert abs(np.mean(noisy - 3.0)) < 4 * 0.2 / math.sqrt(values.size)
    np.testing.assert_array_equal(noisy, add_noise(values, 0.2, np.random.default_rng(5)))
    with pytest.raises(UsageError):
        add_noise(values, -0.1, np.random.default_rng(5))


def test_resampling_keeps_a_linear_signal_exact_on_a_uniform_grid():
    """Sampling at 40 Hz gives times t0 + k/40 inside the record, where a linear signal is reproduced exactly."""
    t = np.sort(np.random.default_rng(2).uniform(0.0, 3.0, 500))
    new_t, cols = resample(t, {"rack_m": 0.015 * t - 0.02}, 40.0)
    np.testing.assert_allclose(np.diff(new_t), 1 / 40, rtol=1e-9)
    assert new_t[0] == t[0] and new_t[-1] <= t[-1] < new_t[-1] + 1 / 40
    np.testing.assert_allclose(cols["rack_m"], 0.015 * new_t - 0.02, atol=1e-15)


def settings(seed: int = 1) -> LoggerSettings:
    return LoggerSettings(
        sample_rate_hz=50.0,
        full_scale={"rack_m": 0.1, "handwheel_torque_Nm": FULL_SCALE},
        noise_rms={"rack_m": 2e-4, "handwheel_torque_Nm": 0.15},
        seed=seed,
    )


def clean_ramp():
    t = np.linspace(0.0, 4.0, 4001)
    return t, {"rack_m": 0.015 * t, "handwheel_torque_Nm": np.minimum(4.0 + 10.0 * t, 15.0)}


def test_degraded_channels_sit_on_the_logger_levels_and_metadata_records_every_setting():
    """Every degraded sample is a converter level; the metadata carry full scales, noise, seed, rate, bits."""
    t, cols = clean_ramp()
    out, meta = degrade(t, cols, settings())
    for name, fs in (("rack_m", 0.1), ("handwheel_torque_Nm", FULL_SCALE)):
        level = (out[name] + fs) / (2 * fs / 255)
        np.testing.assert_allclose(level, np.rint(level), atol=1e-9)
    assert len(out["time_s"]) == 201
    assert meta["synthetic"] is True and meta["bits"] == 8 and meta["sample_rate_hz"] == 50.0
    assert meta["noise_seed"] == 1
    assert meta["full_scale_rack_m"] == 0.1 and meta["noise_rms_handwheel_torque_Nm"] == 0.15


def test_degradation_is_reproducible_and_refuses_a_clipped_clean_signal():
    """One seed gives one measurement; a clean signal beyond full scale means the full scale is wrong."""
    t, cols = clean_ramp()
    a = synthetic_measurement(t, cols, settings(4), case="unladen", surface="ground", source="test")
    b = synthetic_measurement(t, cols, settings(4), case="unladen", surface="ground", source="test")
    c = synthetic_measurement(t, cols, settings(5), case="unladen", surface="ground", source="test")
    np.testing.assert_array_equal(a.handwheel_torque_Nm, b.handwheel_torque_Nm)
    assert not np.array_equal(a.handwheel_torque_Nm, c.handwheel_torque_Nm)
    assert a.is_synthetic and a.metadata["noise_seed"] == "4" and a.quantisation_step("rack_m") == 0.2 / 255
    cols["handwheel_torque_Nm"] = cols["handwheel_torque_Nm"] * 2.0
    with pytest.raises(UsageError, match="beyond the full scale 25"):
        degrade(t, cols, settings())


def test_noise_beyond_full_scale_is_clipped_and_counted():
    """Noise that pushes a near-full-scale signal past the range saturates, and the count is recorded."""
    t = np.linspace(0.0, 2.0, 101)
    cols = {"rack_m": np.zeros_like(t), "handwheel_torque_Nm": np.full_like(t, 24.9)}
    out, meta = degrade(t, cols, settings())
    assert out["handwheel_torque_Nm"].max() == pytest.approx(FULL_SCALE)
    # P(noise > 0.1 N m) = P(z > 0.67) = 25 %: about 25 of 101 samples
    assert 12 < meta["clipped_samples_handwheel_torque_Nm"] < 40
