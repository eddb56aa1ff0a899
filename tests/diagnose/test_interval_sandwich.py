"""The block sandwich of parksteer.diagnose.calibrate: intervals that hold when the residual is not white noise.

Checked by Monte Carlo on a linear least-squares problem whose true coefficients are known
(the sandwich is a statement about least squares, not about the car): an 18 s record at 50 Hz,
two regressors shaped like the cycle's slow signals, and an error that is a slow misfit (an AR(1)
process with a correlation time of half a second, a quarter of a block; with a correlation time of a
second the coverage of 2 s blocks falls to about 0.87) rather than white noise.
"""

from dataclasses import dataclass

import numpy as np
from scipy.stats import t as student_t

from parksteer.diagnose.fitting import Z95
from parksteer.diagnose.statistics import block_sandwich


@dataclass
class _File:
    time_s: np.ndarray
    signals: int = 1  # the torque alone

    @property
    def n(self) -> int:
        return len(self.time_s)


@dataclass
class _Problem:
    files: list


def _simulate(rng, time_s, design, rho, truth):
    e = np.empty(len(time_s))
    e[0] = rng.normal()
    for i in range(1, len(e)):
        e[i] = rho * e[i - 1] + np.sqrt(1 - rho**2) * rng.normal()
    y = design @ truth + e
    coefficients, *_ = np.linalg.lstsq(design, y, rcond=None)
    return coefficients, y - design @ coefficients


def test_sandwich_covers_where_the_white_noise_interval_does_not():
    """With a slow misfit, the white-noise 95 % interval covers the true coefficient far less than 95 % of the
    time, and the block sandwich (2 s blocks, Student's t over the blocks) covers it close to 95 %."""
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 18.0, 0.02)
    design = np.column_stack([np.sin(2 * np.pi * t / 18.0), np.tanh(np.cos(2 * np.pi * t / 9.0) * 5.0)])
    truth = np.array([1.0, -0.5])
    problem = _Problem([_File(t)])
    hits_white = hits_sandwich = 0
    trials = 300
    for _ in range(trials):
        coefficients, residual = _simulate(rng, t, design, np.exp(-0.02 / 0.5), truth)
        white = np.var(residual, ddof=2) * np.linalg.inv(design.T @ design)
        sandwich, blocks = block_sandwich(design, residual, problem, 2.0)
        q = student_t.ppf(0.975, blocks - 2)
        hits_white += abs(coefficients[0] - truth[0]) <= Z95 * np.sqrt(white[0, 0])
        hits_sandwich += abs(coefficients[0] - truth[0]) <= q * np.sqrt(sandwich[0, 0])
    assert hits_white / trials < 0.6
    assert 0.88 <= hits_sandwich / trials <= 1.0


def test_sandwich_agrees_with_white_noise_when_the_residual_is_white():
    """For white noise the sandwich estimates the same variance as s^2 (J^T J)^-1 (within the scatter of an
    estimate from 9 blocks): it widens intervals only when the residual asks for it."""
    rng = np.random.default_rng(6)
    t = np.arange(0.0, 18.0, 0.02)
    design = np.column_stack([np.sin(2 * np.pi * t / 18.0), np.ones_like(t)])
    problem = _Problem([_File(t)])
    ratios = []
    for _ in range(100):
        _, residual = _simulate(rng, t, design, 0.0, np.array([1.0, 0.0]))
        white = np.var(residual, ddof=2) * np.linalg.inv(design.T @ design)
        sandwich, _ = block_sandwich(design, residual, problem, 2.0)
        ratios.append(sandwich[0, 0] / white[0, 0])
    assert 0.85 < np.mean(ratios) < 1.3


@dataclass
class _ReplayFile:  # a torque-only file: its fitted signals are the torque's
    replay_draws: np.ndarray
    sigma: np.ndarray


def test_replay_covariance_is_the_spread_of_the_shifts_the_racks_would_cause():
    """If each replayed rack changed the torque exactly as a parameter change a_d would (d = sigma J a_d), a fit
    would absorb it as that change: the replay's covariance is then the sample covariance of the a_d."""
    from parksteer.diagnose.statistics import replay_covariance

    rng = np.random.default_rng(7)
    t = np.arange(0.0, 18.0, 0.02)
    jacobian = np.column_stack([np.sin(2 * np.pi * t / 18.0), np.cos(2 * np.pi * t / 9.0)])
    sigma = 0.2 + 0.1 * np.abs(np.sin(t))
    shifts = rng.normal(size=(8, 2)) * [0.3, 0.05]
    shifts -= shifts.mean(axis=0)
    draws = (jacobian @ shifts.T).T * sigma
    covariance = replay_covariance(jacobian, _Problem([_ReplayFile(draws, sigma)]))
    assert np.allclose(covariance, np.cov(shifts.T, ddof=1), rtol=1e-9, atol=1e-12)
