"""The parts one healthy record is cut into for the threshold of "as the baseline" (parksteer.diagnose.baseline_learn):
its samples cut into blocks, each a fold, a fold weighted out of a fit, and the one-sided prediction bounds over the
parts. No replay: these are facts about the cutting, the weights and Student's t."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from parksteer.diagnose.baseline_form import Threshold
from parksteer.diagnose.baseline_learn import blocks_of, fold_of, left_out, pooled_bound, prediction_bound
from parksteer.diagnose.settings import DEFAULT_SETTINGS


def _record(duration_s: float = 18.0, rate_hz: float = 50.0):
    return SimpleNamespace(time_s=np.arange(0.0, duration_s, 1.0 / rate_hz) + 3.0)


def test_every_block_of_a_record_is_a_fold_of_its_own():
    """An 18 s record in 2 s blocks: nine blocks, every sample in exactly one, each block 2 s of consecutive
    samples (a ninth of them); a record of 19.5 s has a tenth, shorter block."""
    f = _record()
    folds = blocks_of(f, 2.0)
    fold = fold_of(f, folds, 2.0)
    assert folds == 9 and set(np.unique(fold)) == set(range(folds))
    t = f.time_s - f.time_s[0]
    for k in range(folds):
        chosen = fold == k
        assert chosen.sum() == pytest.approx(f.time_s.size / folds, abs=1)
        assert t[chosen].min() >= 2.0 * k and t[chosen].max() < 2.0 * (k + 1)
    assert blocks_of(_record(19.5), 2.0) == 10


def test_dealt_to_three_folds_each_fold_reaches_along_the_whole_record():
    """Blocks dealt to three folds in turn (leave-one-out over records uses none, a record's blocks each their own):
    each fold holds three whole blocks and samples in the first and the last third of the record."""
    f = _record()
    fold = fold_of(f, 3, 2.0)
    t = f.time_s - f.time_s[0]
    for k in range(3):
        chosen = fold == k
        assert t[chosen].min() < 6.0 and t[chosen].max() > 12.0
        assert len(set(np.floor(t[chosen] / 2.0).astype(int))) == 3


def test_a_fold_left_out_takes_no_part_in_a_fit():
    """A fold left out gets an attainable error a million noise floors (its weighted residual, and so its share of
    any weighted sum of squares, falls by 10^12 against the others'), and the other samples keep the noise floor
    alone."""
    n = 900
    floor = 0.004
    noise = SimpleNamespace(total_rms=floor)
    from parksteer.diagnose.problem import FileData

    measurement = SimpleNamespace(time_s=np.arange(n) / 50.0, n_samples=n)
    f = FileData("r.csv", measurement, "unladen", "ground", None, None, noise)
    held = np.zeros(n, dtype=bool)
    held[100:200] = True
    out = left_out(f, held)
    assert np.allclose(out.sigma_Nm[~held], floor)
    assert np.all(out.sigma_Nm[held] >= 1e6 * floor)
    assert f.replay_uncertainty_Nm is None  # the record given is not changed


def test_the_threshold_is_a_prediction_bound_over_the_parts():
    """Student's one-sided 95 % bound for one more part: mean + t(0.95, k-1) s sqrt(1 + 1/k); at three parts
    t = 2.920 (published tables), so three parts of 1.2, 1.5, 1.8 give 1.5 + 2.920 * 0.3 * sqrt(4/3) = 2.5115."""
    assert prediction_bound([1.2, 1.5, 1.8]) == pytest.approx(1.5 + 2.919986 * 0.3 * math.sqrt(4.0 / 3.0), rel=1e-5)


def test_the_pooled_bound_is_the_bound_on_a_mean_of_as_many_blocks():
    """Student's one-sided 95 % bound for the mean of m more blocks: mean + t(0.95, k-1) s sqrt(1/m + 1/k); at ten
    blocks t(0.95, 9) = 1.833 (published tables), so ten values of mean 2 and standard deviation s, judged for a
    record of ten blocks, give 2 + 1.833 s sqrt(0.2). Against the bound for one more draw it is narrower by
    sqrt((1/m + 1/k) / (1 + 1/k)), and as m grows it tends to the bound on the blocks' mean alone."""
    values = np.array([1.0, 3.0] * 5)
    s = values.std(ddof=1)
    assert pooled_bound(values, 10) == pytest.approx(2.0 + 1.833113 * s * math.sqrt(0.2), rel=1e-5)
    assert pooled_bound(values, 1) == pytest.approx(prediction_bound(values), rel=1e-12)
    assert pooled_bound(values, 10**9) == pytest.approx(2.0 + 1.833113 * s / math.sqrt(10.0), rel=1e-5)
    assert pooled_bound([2.5], 10) == 2.5


def test_against_a_baseline_no_interval_holding_zero_is_the_headline():
    """The settings a later record is judged with: the adequate factor the larger of the sensor's and the healthy
    spread, the BIC gain the larger of the sensor's and the healthy parts' per sample times the samples, and the
    headline rule that names no candidate whose 95 % interval holds 0 (the held strengths are uncertain); and
    nothing calibrated again, the car's calibrated values being the baseline's."""
    threshold = Threshold(2.0, 0.01, "folds")
    settings = threshold.settings_for(DEFAULT_SETTINGS, 2000)
    assert DEFAULT_SETTINGS.calibrated_parameters and DEFAULT_SETTINGS.calibrated_with_angle
    assert settings.calibrated_parameters == settings.calibrated_with_angle == ()
    assert settings.calibrated_with_angle_offsets == ()
    assert settings.adequate_rms_factor == 2.0
    assert settings.bic_missing_threshold == pytest.approx(20.0)
    assert settings.headline_interval_clear_of_zero
    assert not DEFAULT_SETTINGS.headline_interval_clear_of_zero
    low = Threshold(1.0, 0.0, "folds").settings_for(DEFAULT_SETTINGS, 2000)
    assert low.adequate_rms_factor == DEFAULT_SETTINGS.adequate_rms_factor
    assert low.bic_missing_threshold == DEFAULT_SETTINGS.bic_missing_threshold


def test_a_later_record_is_given_the_baselines_calibrated_values():
    """Against a baseline nothing is calibrated again, so the car a later record is replayed with must carry the
    baseline's calibrated values: a rack friction calibrated to 650 N on the healthy record (the file says
    otherwise) is the later record's rack friction, and every other value is the file's."""
    from parksteer.diagnose.baseline import Baseline
    from parksteer.parameters import load_parameters

    params = load_parameters()
    key = "steering.rack_friction_force"
    assert params.value(key, "unladen") != 650.0
    baseline = Baseline(None, "0" * 16, ("healthy.csv",), (), {key: {"value": 650.0}}, "adequate", 1.0, None,
                        Threshold(1.0, 0.0, "blocks"))
    later = baseline.parameters(params)
    assert later.value(key, "unladen") == 650.0
    other = "tyre.friction_coefficient"
    assert later.value(other, "unladen") == params.value(other, "unladen")
