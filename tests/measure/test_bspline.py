"""The B-splines of the rack smoothing written out in numpy (parksteer.measure.bspline) against scipy.interpolate's.

The smoothing dropped scipy.interpolate (a second of every diagnosis's imports) on the promise that its own
arithmetic is scipy's, operation for operation: these tests hold it to the bit, on the knot vectors the smoothing
builds for a real record (evenly spaced knots, a knot at each reversal, a pair at each pause) and on knot vectors
with repeated interior knots, and check the basis against the B-splines' closed-form facts.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from parksteer.measure import bspline
from parksteer.measure.importers import load_record
from parksteer.measure.metrics import estimate_noise_rms
from parksteer.measure.rack_fit import _knot_vector, knot_spacings, rest_intervals, turning_times

ROOT = Path(__file__).resolve().parents[2]
interpolate = pytest.importorskip("scipy.interpolate")


def _bits(a) -> bytes:
    return np.ascontiguousarray(np.asarray(a, dtype=float)).tobytes()


def _record_cases():
    """(sample times, knot vector) pairs the smoothing builds for the README's example and a sample car record."""
    cases = []
    for name in ("data/measurements/example_unladen.csv", "data/samples/car/unladen__ground.csv"):
        record = load_record(ROOT / name)
        t, x = np.asarray(record.time_s, dtype=float), np.asarray(record.rack_m, dtype=float)
        turns, rests = turning_times(t, x), rest_intervals(t, x, estimate_noise_rms(x))
        spacings = knot_spacings(t)
        for spacing in (spacings[0], spacings[-1]):
            for held in (rests, ()):
                cases.append((t, x, _knot_vector(t, spacing, turns, held)))
    return cases


def _repeated_knot_case():
    """Uneven samples and a knot vector with a double and a triple interior knot, two of them at samples."""
    rng = np.random.default_rng(7)
    t = np.sort(rng.uniform(0.0, 3.0, 120))
    t[0], t[-1] = 0.0, 3.0
    interior = [0.4, 0.9, 0.9, t[50], t[50], t[50], 2.2, t[100]]
    knots = np.concatenate([[0.0] * 4, sorted(interior), [3.0] * 4])
    return t, np.sin(2.0 * t) + 0.01 * rng.standard_normal(len(t)), knots


CASES = _record_cases() + [_repeated_knot_case()]


@pytest.mark.parametrize("case", range(len(CASES)))
def test_design_matrix_products_are_scipys_to_the_bit(case):
    """D^T D, D^T y and D c from the written-out design matrix equal scipy's BSpline.design_matrix and its sparse
    products bit for bit (the least-squares rack's coefficients depend on nothing else)."""
    t, x, knots = CASES[case]
    sparse = interpolate.BSpline.design_matrix(t, knots, 3).tocsr()
    mine = bspline.DesignMatrix(t, knots)
    c = np.random.default_rng(case).standard_normal(sparse.shape[1])
    assert _bits(mine.gram()) == _bits((sparse.T @ sparse).toarray())
    assert _bits(mine.transpose_times(x)) == _bits(sparse.T @ x)
    assert _bits(mine.times(c)) == _bits(sparse @ c)


@pytest.mark.parametrize("case", range(len(CASES)))
def test_end_speeds_and_piecewise_form_are_scipys_to_the_bit(case):
    """Each B-spline's speed at the record's ends equals BSpline(..., e_j)(x, 1), and the piecewise cubic of a
    spline equals PPoly.from_spline's pieces of nonzero length, bit for bit."""
    t, _, knots = CASES[case]
    count = len(knots) - 4
    ends = np.array([t[0], t[-1]])
    expected = np.array([interpolate.BSpline(knots, np.eye(count)[j], 3)(ends, 1) for j in range(count)]).T
    assert _bits(bspline.derivative_rows(knots, ends)) == _bits(expected)
    c = np.random.default_rng(case + 100).standard_normal(count)
    pp = interpolate.PPoly.from_spline(interpolate.BSpline(knots, c, 3, extrapolate=False))
    keep = np.diff(pp.x) > 0.0
    breaks, coefficients = bspline.piecewise_cubic(knots, c)
    assert _bits(breaks) == _bits(np.concatenate([pp.x[:-1][keep], [pp.x[-1]]]))
    assert _bits(coefficients) == _bits(pp.c[:, keep])


def test_the_basis_is_a_partition_of_unity_and_its_derivatives_sum_to_zero():
    """Cubic B-splines on a clamped knot vector sum to one everywhere in the base interval, so their derivatives
    sum to zero; each is nonnegative."""
    t, _, knots = _repeated_knot_case()
    x = np.linspace(0.0, 3.0, 301)
    intervals = bspline.find_intervals(knots, x, 3)
    values = bspline.basis(knots, x, intervals, 3)
    assert np.all(values >= 0.0)
    np.testing.assert_allclose(values.sum(axis=1), 1.0, rtol=0, atol=1e-14)
    for order in (1, 2):
        derivatives = bspline.basis(knots, x, intervals, 3, order)
        scale = np.abs(derivatives).max()
        np.testing.assert_allclose(derivatives.sum(axis=1), 0.0, rtol=0, atol=1e-12 * scale)


def test_a_cubic_is_reproduced_exactly_by_its_piecewise_form():
    """A cubic polynomial lies in the spline space: fitted through its values by least squares it comes back, and
    its piecewise form has on every piece the polynomial's own Taylor coefficients at the piece's start."""
    t = np.linspace(0.0, 2.0, 200)
    knots = np.concatenate([[0.0] * 4, [0.5, 0.8, 1.3], [2.0] * 4])
    poly = lambda s: 0.3 * s**3 - s**2 + 2.0 * s - 0.5  # noqa: E731
    design = bspline.DesignMatrix(t, knots)
    coefficients = np.linalg.solve(design.gram(), design.transpose_times(poly(t)))
    np.testing.assert_allclose(design.times(coefficients), poly(t), atol=1e-12)
    breaks, pieces = bspline.piecewise_cubic(knots, coefficients)
    start = breaks[:-1]
    np.testing.assert_allclose(pieces[0], 0.3, atol=1e-10)
    np.testing.assert_allclose(pieces[1], 0.9 * start - 1.0, atol=1e-10)
    np.testing.assert_allclose(pieces[2], 0.9 * start**2 - 2.0 * start + 2.0, atol=1e-10)
    np.testing.assert_allclose(pieces[3], poly(start), atol=1e-10)


def test_the_assisted_replays_rack_speed_is_ppolys_derivative_to_the_bit():
    """parksteer.model.numeric.assisted.rack_speed_mps (the rack speed the assist's law reads) equals scipy's
    PPoly(...).derivative() of the same pieces bit for bit, at the samples, at the breaks themselves and beyond
    the record's ends (where the rack is held: speed 0), and is the derivative of the position."""
    from parksteer.measure.smoothing import smooth_rack
    from parksteer.model.numeric.assisted import rack_speed_mps

    t, x, _ = CASES[0]
    rack = smooth_rack(t, x)
    for times in (t, rack.breaks.copy(), np.linspace(rack.start_s - 1.0, rack.end_s + 1.0, 2001)):
        inside = (times >= rack.start_s) & (times <= rack.end_s)
        expected = np.where(inside, interpolate.PPoly(rack.coefficients, rack.breaks).derivative()(times), 0.0)
        assert _bits(rack_speed_mps(rack, times)) == _bits(expected)
    np.testing.assert_allclose(rack_speed_mps(rack, t), rack.evaluate(t)[1], rtol=1e-9, atol=1e-12)
