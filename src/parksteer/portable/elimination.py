"""Gaussian elimination with partial pivoting and Cholesky's factorisation, as LAPACK does them, written out with
sums in a fixed order (:mod:`parksteer.portable` says why), touching only the band of a banded matrix."""

from __future__ import annotations

import math

import numpy as np

LinAlgError = np.linalg.LinAlgError

# np.sum without its Python wrapper (np.sum(x, axis=a) calls exactly this)
_sum = np.add.reduce


def _f64(a) -> np.ndarray:
    return np.asarray(a, dtype=float)


# Banded systems (the Gram matrix of a B-spline fit has three diagonals either side of the main one): elimination
# restricted to the band does every operation of the dense one whose result can differ from its operand. Why the
# others change nothing, to the bit, when no entry is -0.0 and every number stays finite:
# - outside the band every entry is +0.0 and stays so, and an entry that is not -0.0 is unchanged by subtracting a
#   product that is zero (finite times +-0 is +-0; x - (+-0) is x for x nonzero, and +0 - (+-0) is +0);
# - subtraction, the only update, makes -0.0 only from -0.0, so no -0.0 ever appears in the matrix or (in the
#   forward pass) the right-hand side;
# - a row's back-substitution sum over more than one column is a sequential one (numpy's reduction over the
#   first axis) that starts from +0.0, so the terms past the band, all +-0, leave it as it is;
# - the pivot search's first largest |entry| lies in the band (the rest are zeros).
# A non-finite number, once made, stays in the factors or the solution; one there means the argument does not
# hold, and the dense elimination (bands as wide as the matrix) is run instead. So is an input with a -0.0.


def _bandwidths(a: np.ndarray) -> tuple[int, int]:
    """(lower, upper): how far below and above the main diagonal the nonzero entries reach (a NaN is nonzero);
    the whole width when an entry is -0.0, where only the dense elimination is known to give the same bits."""
    n = a.shape[0]
    if n == 0 or bool(np.any((a == 0.0) & np.signbit(a))):
        return max(n - 1, 0), max(n - 1, 0)
    rows, cols = np.nonzero(a)
    if rows.size == 0:
        return 0, 0
    offsets = cols - rows
    return max(0, -int(offsets.min())), max(0, int(offsets.max()))


def _first_largest(column: list[float]) -> int:
    """np.argmax(np.abs(column)): the first largest magnitude, or the first NaN if there is one."""
    best, largest = 0, -1.0
    for i, value in enumerate(column):
        size = abs(value)
        if size != size:
            return i
        if size > largest:
            best, largest = i, size
    return best


def _eliminate(lu: np.ndarray, x: np.ndarray, lower: int, upper: int, identity: bool
               ) -> tuple[np.ndarray, np.ndarray]:
    """Solve lu y = x (x two-dimensional; neither overwritten) by Gaussian elimination with partial pivoting,
    touching only the band of `lower` diagonals below and `upper` above the main one (which a row swap widens to
    lower + upper above). With `identity` (x is the identity) a row of x is zero beyond the band too. Returns y and
    the working array (the factors in its first n columns, y in the rest)."""
    n = lu.shape[0]
    work = np.concatenate([lu, x], axis=1)  # a row of the matrix and of b, swapped and reduced as one
    stop = work.shape[1]
    sequential = stop - n > 1  # see the note on banded systems above
    for k in range(n):
        bottom = min(n, k + lower + 1)
        p = k + _first_largest(work[k:bottom, k].tolist())
        if work[p, k] == 0.0:
            raise LinAlgError("Singular matrix")
        if p != k:
            work[[k, p]] = work[[p, k]]
        if k + 1 < bottom:
            # the columns between the band and b (or b's columns past the band), zero in row k, change nothing
            end = n + bottom if identity else stop
            factor = work[k + 1:bottom, k] / work[k, k]
            work[k + 1:bottom, k:end] -= np.multiply.outer(factor, work[k, k:end])
    solution = work[:, n:]
    for k in range(n - 1, -1, -1):
        row = solution[k]
        if k + 1 < n:
            end = min(n, k + lower + upper + 1) if sequential else n
            np.subtract(row, _sum(work[k, k + 1:end, None] * solution[k + 1:end], axis=0), out=row)
        else:
            np.subtract(row, 0.0, out=row)
        np.divide(row, work[k, k], out=row)
    return solution, work


def _solve(a, b, identity: bool) -> np.ndarray:
    lu = np.array(a, dtype=float)
    x = np.array(b, dtype=float)
    n = lu.shape[0]
    if lu.shape != (n, n) or x.shape[0] != n:
        raise ValueError(f"solve: shapes {lu.shape} and {x.shape} do not align")
    vector = x.ndim == 1
    if vector:
        x = x[:, None]
    lower, upper = _bandwidths(lu)
    if lower + upper < 2 * n - 2 and not bool(np.any((x == 0.0) & np.signbit(x))):
        try:
            out, work = _eliminate(lu, x, lower, upper, identity)
        except LinAlgError:
            pass  # the dense elimination below says whether it is singular
        else:
            if bool(np.all(np.isfinite(work))):
                return np.ascontiguousarray(out[:, 0] if vector else out)
    out, _ = _eliminate(lu, x, max(n - 1, 0), max(n - 1, 0), identity)
    return np.ascontiguousarray(out[:, 0] if vector else out)


def solve(a, b) -> np.ndarray:
    """x with a x = b (a square); Gaussian elimination with partial pivoting. Raises LinAlgError if singular."""
    return _solve(a, b, identity=False)


def inv(a) -> np.ndarray:
    """The inverse of a square matrix (:func:`solve` against the identity)."""
    a = _f64(a)
    return _solve(a, np.eye(a.shape[0]), identity=True)


def _cholesky(a: np.ndarray, lower: int) -> np.ndarray:
    """Cholesky's columns, each computed only down to `lower` rows below the diagonal (the rest stay +0.0)."""
    n = a.shape[0]
    low = np.zeros((n, n))
    for j in range(n):
        bottom = min(n, j + lower + 1)
        # row j's sum of squares and the rows below's sums of products, each numpy's pairwise sum over its row
        sums = _sum(low[j:bottom, :j] * low[j, :j], axis=1)
        d = a[j, j] - float(sums[0])
        if not d > 0.0:
            raise LinAlgError("Matrix is not positive definite")
        low[j, j] = math.sqrt(d)
        if j + 1 < bottom:
            low[j + 1:bottom, j] = (a[j + 1:bottom, j] - sums[1:]) / low[j, j]
    return low


def cholesky(a) -> np.ndarray:
    """Lower-triangular L with L L^T = a; raises LinAlgError unless a is positive definite.

    Only the band of a banded ``a`` is computed: below it the dense algorithm's entries are (+0 - (+-0)) / (a
    positive pivot) = +0.0 (no -0.0 in ``a``, every number finite, else the dense algorithm runs), and each
    entry in the band is the same pairwise sum over the same row as the dense one's."""
    a = _f64(a)
    n = a.shape[0]
    lower, _ = _bandwidths(np.tril(a))
    if lower < n - 1:
        try:
            low = _cholesky(a, lower)
        except LinAlgError:
            low = None
        if low is not None and bool(np.all(np.isfinite(low))):
            return low
    return _cholesky(a, max(n - 1, 0))
