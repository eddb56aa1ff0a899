"""The held form with no share in what the calibration carries (parksteer.diagnose.baseline_share): its strengths
confined to the directions whose torque is orthogonal to every calibrated value's sensitivity. Checked on linear
models whose answers are known in closed form: a friction of knots that form a partition of unity (their sum is
a uniform force, a Coulomb rack friction), where the healthy data fix only the sum of the rack friction and the
knots' uniform part."""

from __future__ import annotations

import numpy as np

from parksteer.diagnose.baseline_share import (COORDINATE, CoordinateEngine, ShareFreeBasis, coordinate_key,
                                               null_basis, share_free_basis)

KNOTS = 9


def _hats(x: np.ndarray) -> np.ndarray:
    """KNOTS piecewise-linear hats over [0, 1] (columns): at every x they sum to exactly 1."""
    centres = np.linspace(0.0, 1.0, KNOTS)
    width = centres[1] - centres[0]
    return np.clip(1.0 - np.abs(x[:, None] - centres[None, :]) / width, 0.0, None)


def test_the_basis_spans_exactly_the_strengths_the_constraints_leave_free():
    """Every basis vector satisfies C s = 0, the basis has K - rank(C) independent columns, and a row of zeros or
    a row repeating another adds no constraint (the null space of C, whatever its rows' scale)."""
    rng = np.random.default_rng(5)
    rows = rng.normal(size=(3, KNOTS))
    for constraints, rank in ((rows, 3), (np.vstack([rows, 2.5 * rows[0], np.zeros(KNOTS)]), 3),
                              (np.zeros((2, KNOTS)), 0)):
        basis = null_basis(constraints)
        assert basis.shape == (KNOTS, KNOTS - rank)
        assert np.linalg.matrix_rank(basis) == KNOTS - rank
        assert np.abs(constraints @ basis).max() < 1e-9 * max(np.abs(constraints).max(), 1.0)


def test_a_partition_of_unity_friction_leaves_its_mean_to_the_rack_friction():
    """Data: a uniform friction R plus a bump along the rack. Fitted with R and the knots together, the two trade
    without end (the knots' sum is R's column: J^T J is singular). Confined to the share-free directions, the fit
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
