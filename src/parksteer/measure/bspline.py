"""Cubic B-splines on a clamped knot vector, written out in numpy: the basis and its derivatives (Cox-de Boor), the
least-squares products of the design matrix, and the piecewise-polynomial form of a spline.

The rack smoothing (:mod:`parksteer.measure.rack_fit`, :mod:`parksteer.measure.smoothing`) needs only these few
operations, and importing ``scipy.interpolate`` for them costs about a second of every diagnosis (it pulls in
scipy.special, scipy.linalg, scipy.sparse and scipy.optimize). Each function does, operation for operation and in
the same order, what scipy's does (``BSpline.design_matrix``, the sparse products of that matrix, ``BSpline``'s
derivative, ``PPoly.from_spline``), so the bits are the same: ``tests/measure/test_bspline.py`` compares them.
Only elementwise IEEE operations are used, so the bits do not depend on the machine either.
"""

from __future__ import annotations

import numpy as np


def find_intervals(knots: np.ndarray, x: np.ndarray, degree: int) -> np.ndarray:
    """For each of `x`, the index l of its knot interval, knots[l] <= x < knots[l + 1], kept within the spline's
    base interval [degree, len(knots) - degree - 2] (its right end belongs to the last interval)."""
    last = len(knots) - degree - 2
    return np.clip(np.searchsorted(knots, x, side="right") - 1, degree, last)


def basis(knots: np.ndarray, x: np.ndarray, intervals: np.ndarray, degree: int, derivative: int = 0) -> np.ndarray:
    """The degree + 1 B-splines nonzero on each interval (columns intervals - degree ... intervals), or their
    `derivative`-th derivatives, at `x`: one row per point.

    De Boor's recurrence: degree - derivative steps raising the degree of the values, then `derivative` steps of
    differences that turn them into the derivative's values (a zero-length knot span contributes zero)."""
    x = np.asarray(x, dtype=float)
    h = np.zeros((len(x), degree + 1))
    h[:, 0] = 1.0
    for j in range(1, degree + 1):
        previous = h[:, :j].copy()
        h[:, 0] = 0.0
        for n in range(1, j + 1):
            right = knots[intervals + n]
            left = knots[intervals + n - j]
            same = right == left
            span = np.where(same, 1.0, right - left)
            if j <= degree - derivative:
                w = previous[:, n - 1] / span
                h[:, n - 1] = np.where(same, h[:, n - 1], h[:, n - 1] + w * (right - x))
                h[:, n] = np.where(same, 0.0, w * (x - left))
            else:
                w = float(j) * previous[:, n - 1] / span
                h[:, n - 1] = np.where(same, h[:, n - 1], h[:, n - 1] - w)
                h[:, n] = np.where(same, 0.0, w)
    return h


class DesignMatrix:
    """The least-squares design matrix of a cubic spline at the points `x`: each row's four nonzero B-splines
    (``values``) from column ``offsets`` on, and the products a least-squares fit needs, each sum taken over the
    points in their order (as a sparse product takes it, so with the same bits)."""

    def __init__(self, x: np.ndarray, knots: np.ndarray, degree: int = 3):
        self.x = np.asarray(x, dtype=float)
        self.knots = np.asarray(knots, dtype=float)
        self.degree = degree
        self.columns = len(self.knots) - degree - 1
        intervals = find_intervals(self.knots, self.x, degree)
        self.values = basis(self.knots, self.x, intervals, degree)
        self.offsets = intervals - degree

    def _column_index(self) -> np.ndarray:
        return self.offsets[:, None] + np.arange(self.degree + 1)

    def gram(self) -> np.ndarray:
        """D^T D, dense."""
        width = self.degree + 1
        cols = self._column_index()
        rows = np.repeat(cols, width, axis=1)  # sample-major: each point's 16 products in turn
        others = np.tile(cols, (1, width))
        products = np.repeat(self.values, width, axis=1) * np.tile(self.values, (1, width))
        out = np.zeros((self.columns, self.columns))
        np.add.at(out, (rows.ravel(), others.ravel()), products.ravel())  # unbuffered: summed in the points' order
        return out

    def transpose_times(self, y: np.ndarray) -> np.ndarray:
        """D^T y."""
        out = np.zeros(self.columns)
        np.add.at(out, self._column_index().ravel(), (self.values * np.asarray(y, dtype=float)[:, None]).ravel())
        return out

    def times(self, coefficients: np.ndarray) -> np.ndarray:
        """D c: the spline with B-spline `coefficients` at the points."""
        c = np.asarray(coefficients, dtype=float)
        out = np.zeros(len(self.x))
        for a in range(self.degree + 1):
            out = out + self.values[:, a] * c[self.offsets + a]
        return out


def derivative_rows(knots: np.ndarray, x: np.ndarray, degree: int = 3, derivative: int = 1) -> np.ndarray:
    """The `derivative`-th derivative of every B-spline at each of `x`: a dense (len(x), number of B-splines) matrix,
    row i times a spline's coefficients being that spline's derivative at x[i]."""
    knots = np.asarray(knots, dtype=float)
    x = np.asarray(x, dtype=float)
    intervals = find_intervals(knots, x, degree)
    values = basis(knots, x, intervals, degree, derivative)
    out = np.zeros((len(x), len(knots) - degree - 1))
    for i, (first, row) in enumerate(zip(intervals - degree, values)):
        out[i, first : first + degree + 1] = row
    return out


def _spline_derivative_at_breaks(knots: np.ndarray, coefficients: np.ndarray, degree: int, order: int,
                                 intervals: np.ndarray) -> np.ndarray:
    """The `order`-th derivative of the spline at the left end of each of `intervals` (FITPACK's splev/splder: the
    derivative's B-spline coefficients by repeated differences, then its basis at the point)."""
    work = np.array(coefficients, dtype=float)
    count = len(knots) - degree - 1
    for j in range(1, order + 1):
        kk = degree - j + 1
        count -= 1
        i = np.arange(count)
        span = knots[j + i + kk] - knots[j + i]
        step = float(kk) * (work[1 : count + 1] - work[:count]) / np.where(span > 0.0, span, 1.0)
        work[:count] = np.where(span > 0.0, step, work[:count])
    if order == degree:
        return work[intervals - degree]
    x = knots[intervals]
    h = basis(knots, x, intervals, degree - order)
    total = np.zeros(len(intervals))
    for a in range(degree - order + 1):
        total = total + work[intervals - degree + a] * h[:, a]
    return total


def piecewise_cubic(knots: np.ndarray, coefficients: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cubic spline with these clamped `knots` and B-spline `coefficients` as a piecewise polynomial: (breaks,
    coefficients with the highest power first, one column per piece), pieces of zero length left out (the form
    of :class:`parksteer.measure.rack_spline.RackSpline`, with PPoly.from_spline's bits)."""
    knots = np.asarray(knots, dtype=float)
    degree = 3
    pieces = np.flatnonzero(np.diff(knots) > 0.0)
    out = np.empty((degree + 1, len(pieces)))
    factorial = 1.0
    for order in range(degree + 1):
        out[degree - order] = _spline_derivative_at_breaks(knots, coefficients, degree, order, pieces) / factorial
        factorial *= order + 1
    return np.concatenate([knots[pieces], [knots[-1]]]), out
