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
    return _de_boor(knots, x, intervals, degree, derivative)


def _de_boor(knots: np.ndarray, x: np.ndarray, intervals: np.ndarray, degree: int, derivative: int = 0,
             steps: list | None = None) -> np.ndarray:
    """:func:`basis`; into `steps`, if given, the values after each step of the recurrence, from none to `degree`:
    without a derivative, step j's are the B-splines of degree j (step j reads only the j columns the steps before
    it wrote, and writes j + 1)."""
    x = np.asarray(x, dtype=float)
    h = np.zeros((len(x), degree + 1))
    h[:, 0] = 1.0
    if steps is not None:
        steps.append(h[:, :1].copy())
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
        if steps is not None:
            steps.append(h[:, : j + 1].copy())
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


def _derivative_coefficients(knots: np.ndarray, coefficients: np.ndarray, degree: int) -> list[np.ndarray]:
    """The B-spline coefficients of the spline's derivatives of order 0 ... `degree` (FITPACK's splder: repeated
    differences), each the array the one before it becomes after one more difference (only its leading entries,
    which the derivative's fewer B-splines read, are new)."""
    work = np.array(coefficients, dtype=float)
    out = [work.copy()]
    count = len(knots) - degree - 1
    for j in range(1, degree + 1):
        kk = degree - j + 1
        count -= 1
        i = np.arange(count)
        span = knots[j + i + kk] - knots[j + i]
        step = float(kk) * (work[1 : count + 1] - work[:count]) / np.where(span > 0.0, span, 1.0)
        work[:count] = np.where(span > 0.0, step, work[:count])
        out.append(work.copy())
    return out


def piecewise_cubic(knots: np.ndarray, coefficients: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cubic spline with these clamped `knots` and B-spline `coefficients` as a piecewise polynomial: (breaks,
    coefficients with the highest power first, one column per piece), pieces of zero length left out (the form
    of :class:`parksteer.measure.rack_spline.RackSpline`, with PPoly.from_spline's bits).

    Each derivative at the left end of each piece as FITPACK's splev/splder take it: the derivative's B-spline
    coefficients by repeated differences, then the B-splines of its degree at the point (the differences and the
    recurrence of the lower degrees are the first steps of the higher ones, so each is made once)."""
    knots = np.asarray(knots, dtype=float)
    degree = 3
    pieces = np.flatnonzero(np.diff(knots) > 0.0)
    derivatives = _derivative_coefficients(knots, coefficients, degree)
    values: list[np.ndarray] = []  # the B-splines of degree 0 ... 3 at the breaks
    _de_boor(knots, knots[pieces], pieces, degree, steps=values)
    out = np.empty((degree + 1, len(pieces)))
    factorial = 1.0
    for order in range(degree + 1):
        work = derivatives[order]
        if order == degree:
            at_breaks = work[pieces - degree]
        else:
            h = values[degree - order]
            at_breaks = np.zeros(len(pieces))
            for a in range(degree - order + 1):
                at_breaks = at_breaks + work[pieces - degree + a] * h[:, a]
        out[degree - order] = at_breaks / factorial
        factorial *= order + 1
    return np.concatenate([knots[pieces], [knots[-1]]]), out
