"""The held form with no share in what the calibration carries (parksteer.diagnose.baseline_share): its strengths
confined to the directions whose torque the calibrated values reproduce for at most half. Checked on linear
models whose answers are known in closed form: a friction of knots that form a partition of unity (their sum is
a uniform force, a Coulomb rack friction), where the healthy data fix only the sum of the rack friction and the
knots' uniform part."""

from __future__ import annotations

import numpy as np

from parksteer.diagnose.baseline_share import (CARRIED_SHARE, COORDINATE, CoordinateEngine, ShareFreeBasis,
                                               carried_shares, coordinate_key, share_free_basis)

KNOTS = 9


def _hats(x: np.ndarray) -> np.ndarray:
    """KNOTS piecewise-linear hats over [0, 1] (columns): at every x they sum to exactly 1."""
    centres = np.linspace(0.0, 1.0, KNOTS)
    width = centres[1] - centres[0]
    return np.clip(1.0 - np.abs(x[:, None] - centres[None, :]) / width, 0.0, None)


def test_a_partition_of_unity_friction_against_a_coulomb_rack_friction_confines_the_uniform_direction_alone():
    """Knots whose hats sum to one, against a Coulomb rack friction (a uniform force): the uniform direction's
    torque is the rack friction's column exactly (share 1), every direction torque-orthogonal to it has none of it
    (share 0), so exactly one direction is confined, the uniform one, and the free basis is the K - 1 directions
    whose force has zero mean over the samples."""
    x = np.linspace(0.0, 1.0, 400)
    hats = _hats(x)
    jacobian = np.column_stack([np.ones_like(x), hats])
    shares, directions = carried_shares(jacobian, [0], list(range(1, KNOTS + 1)))
    assert abs(shares[0] - 1.0) < 1e-12 and np.abs(shares[1:]).max() < 1e-12
    uniform = directions[:, 0] / directions[0, 0]
    assert np.allclose(uniform, 1.0, atol=1e-12)
    share = share_free_basis(jacobian, [0], list(range(1, KNOTS + 1)), [f"s{k}" for k in range(KNOTS)], ["R"])
    assert share.basis.shape == (KNOTS, KNOTS - 1) and np.linalg.matrix_rank(share.basis) == KNOTS - 1
    assert np.abs(np.sum(hats @ share.basis, axis=0)).max() < 1e-12 * np.abs(hats @ share.basis).max()


def test_a_share_is_the_fraction_of_a_directions_torque_the_calibration_reproduces():
    """For every direction v, share = |P_c J_s v|^2 / |J_s v|^2 (P_c the projector on the calibrated columns, here
    computed by numpy's least squares), the shares in [0, 1]; the directions' torques are mutually orthogonal;
    a direction is confined exactly when its share exceeds one half; a knot that moves no torque stays free."""
    rng = np.random.default_rng(3)
    calibrated = rng.normal(size=(200, 2))
    strengths = np.column_stack([calibrated @ [1.0, 0.5] + 0.3 * rng.normal(size=200),
                                 calibrated @ [0.2, 0.0] + rng.normal(size=200), rng.normal(size=200),
                                 np.zeros(200)])
    jacobian = np.column_stack([calibrated, strengths])
    shares, directions = carried_shares(jacobian, [0, 1], [2, 3, 4, 5])
    torques = strengths @ directions
    moving = np.abs(torques).max(axis=0) > 0.0
    assert moving.sum() == 3 and shares[~moving].tolist() == [0.0]
    projected = calibrated @ np.linalg.lstsq(calibrated, torques, rcond=None)[0]
    expected = np.sum(projected[:, moving] ** 2, axis=0) / np.sum(torques[:, moving] ** 2, axis=0)
    assert np.allclose(shares[moving], expected, atol=1e-12) and np.all((shares >= 0.0) & (shares <= 1.0))
    gram = torques[:, moving].T @ torques[:, moving]
    assert np.allclose(gram - np.diag(np.diagonal(gram)), 0.0, atol=1e-9 * np.abs(gram).max())
    share = share_free_basis(jacobian, [0, 1], [2, 3, 4, 5], ["a", "b", "c", "d"], ["R", "D"])
    assert share.basis.shape[1] == int(np.sum(shares <= CARRIED_SHARE)) == 3
    assert np.allclose(share.basis[:, np.abs(share.basis[3]) > 0.5][:, 0], [0.0, 0.0, 0.0, 1.0])


def test_a_partition_of_unity_friction_leaves_its_mean_to_the_rack_friction():
    """Data: a uniform friction R plus a bump along the rack. Fitted with R and the knots together, the two trade
    without end (the knots' sum is R's column: J^T J is singular). Confined to the free directions, the fit
    is unique: R is the least-squares uniform fit of the data alone (the calibration without the form, to first
    order exactly), the knots carry only what no uniform force can (their force has zero mean over the samples),
    and together they reproduce the data as the unconfined fit does."""
    x = np.linspace(0.0, 1.0, 400)
    hats = _hats(x)
    rack = np.ones_like(x)  # R's sensitivity: a uniform force
    data = 730.0 * rack + 60.0 * np.exp(-((x - 0.7) / 0.08) ** 2)
    jacobian = np.column_stack([rack, hats])
    assert np.linalg.matrix_rank(jacobian) == KNOTS  # one column too many: the valley
    share = share_free_basis(jacobian, [0], list(range(1, KNOTS + 1)), [f"s{k}" for k in range(KNOTS)], ["R"])
    confined = np.column_stack([rack, hats @ share.basis])
    solution, *_ = np.linalg.lstsq(confined, data, rcond=None)
    strengths = share.basis @ solution[1:]
    assert abs(solution[0] - data.mean()) < 1e-9 * data.mean()
    assert abs(np.mean(hats @ strengths)) < 1e-9 * np.abs(hats @ strengths).max()
    free, *_ = np.linalg.lstsq(jacobian, data, rcond=None)
    assert np.allclose(confined @ solution, jacobian @ free, atol=1e-9 * data.max())


def test_the_engine_replays_the_strengths_the_coordinates_stand_for():
    """Coordinates in the overrides reach the replay as the strengths origin + basis @ z, nothing else changed and
    no coordinate key passed on (the model has no such quantity)."""
    seen = {}

    class Recording:
        evaluations = 7

        def predict(self, problem, effects, overrides):
            seen.update(overrides)
            return ["prediction"]

    basis = np.array([[1.0, 0.0], [-1.0, 1.0], [0.0, -1.0]])
    share = ShareFreeBasis(("a.s0", "a.s1", "a.s2"), basis, ("R",))
    engine = CoordinateEngine(Recording(), share, np.array([10.0, 20.0, 30.0]))
    out = engine.predict(None, [], {"R": 700.0, coordinate_key(0): 2.0, coordinate_key(1): -3.0})
    assert out == ["prediction"] and engine.evaluations == 7
    assert seen == {"R": 700.0, "a.s0": 12.0, "a.s1": 15.0, "a.s2": 33.0}
    assert not any(k.startswith(COORDINATE) for k in seen)
