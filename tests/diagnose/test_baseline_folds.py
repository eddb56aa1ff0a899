"""The parts one healthy record is cut into for the threshold of "as the baseline" (parksteer.diagnose.baseline_learn):
its samples dealt in blocks to folds in turn, a fold weighted out of a fit, and the one-sided prediction bound over
the parts. No replay: these are facts about the cutting and the weights."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from parksteer.diagnose.baseline_form import Threshold
from parksteer.diagnose.baseline_learn import FOLDS, fold_of, left_out, prediction_bound
from parksteer.diagnose.settings import DEFAULT_SETTINGS


def _record(duration_s: float = 18.0, rate_hz: float = 50.0):
    return SimpleNamespace(time_s=np.arange(0.0, duration_s, 1.0 / rate_hz) + 3.0)


def test_every_fold_reaches_along_the_whole_record():
    """An 18 s record in 2 s blocks dealt to three folds: every sample is in exactly one fold, each fold holds
    three whole blocks (a third of the samples), and each fold has samples in the first and in the last third of
    the record, so the form fitted without a fold still sees every stretch of both strokes."""
    f = _record()
    fold = fold_of(f, FOLDS, 2.0)
    assert FOLDS == 3 and set(np.unique(fold)) == set(range(FOLDS))
    t = f.time_s - f.time_s[0]
    for k in range(FOLDS):
        chosen = fold == k
        assert chosen.sum() == pytest.approx(f.time_s.size / FOLDS, abs=1)
        assert t[chosen].min() < 6.0 and t[chosen].max() > 12.0
        # whole blocks: within a block of 2 s every sample is in the same fold
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


def test_against_a_baseline_no_interval_holding_zero_is_the_headline():
    """The settings a later record is judged with: the adequate factor the larger of the sensor's and the healthy
    spread, the BIC gain the larger of the sensor's and the healthy parts' per sample times the samples, and the
    headline rule that names no candidate whose 95 % interval holds 0 (the held strengths are uncertain)."""
    threshold = Threshold(2.0, 0.01, "folds")
    settings = threshold.settings_for(DEFAULT_SETTINGS, 2000)
    assert settings.adequate_rms_factor == 2.0
    assert settings.bic_missing_threshold == pytest.approx(20.0)
    assert settings.headline_interval_clear_of_zero
    assert not DEFAULT_SETTINGS.headline_interval_clear_of_zero
    low = Threshold(1.0, 0.0, "folds").settings_for(DEFAULT_SETTINGS, 2000)
    assert low.adequate_rms_factor == DEFAULT_SETTINGS.adequate_rms_factor
    assert low.bic_missing_threshold == DEFAULT_SETTINGS.bic_missing_threshold
