"""Linear algebra for the small systems of the model and the diagnosis, with sums in a fixed order: products,
norms, Householder QR with column pivoting (the algorithm LAPACK uses, written out) and what is built on them
(:mod:`parksteer.portable` says why; Gaussian elimination and Cholesky are in :mod:`.elimination`)."""

from __future__ import annotations

import math
from functools import reduce
from itertools import repeat
from operator import add, itemgetter, mul, sub

import numpy as np

LinAlgError = np.linalg.LinAlgError

# np.sum without its Python wrapper (np.sum(x, axis=a) calls exactly this)
_sum = np.add.reduce

_CHUNK_ELEMENTS = 1 << 21  # temporaries of matmul stay under 16 MB
_FLOATS_AT_MOST = 40  # least squares in Python floats up to this many entries of a and b (numpy's calls cost more)


def _f64(a) -> np.ndarray:
    return np.asarray(a, dtype=float)


def dot(a, b) -> float:
    """sum(a * b) of two vectors, pairwise in a fixed order."""
    return float(_sum(np.multiply(_f64(a), _f64(b)), axis=None))


def matmul(a, b) -> np.ndarray:
    """a @ b for 1-D and 2-D operands, each entry a pairwise sum of products in a fixed order."""
    a, b = _f64(a), _f64(b)
    if a.ndim == 1 and b.ndim == 1:
        return np.asarray(dot(a, b))
    a2 = a[None, :] if a.ndim == 1 else a
    b2 = b[:, None] if b.ndim == 1 else b
    if a2.ndim != 2 or b2.ndim != 2 or a2.shape[1] != b2.shape[0]:
        raise ValueError(f"matmul: shapes {a.shape} and {b.shape} do not align")
    m, n = a2.shape
    p = b2.shape[1]
    bt = np.ascontiguousarray(b2.T)
    out = np.empty((m, p))
    rows = max(1, _CHUNK_ELEMENTS // max(1, p * n))
    for start in range(0, m, rows):
        block = np.ascontiguousarray(a2[start:start + rows])
        # (rows, p, n), reduced over its last, contiguous axis: one pairwise sum per entry
        _sum(block[:, None, :] * bt[None, :, :], axis=-1, out=out[start:start + rows])
    if a.ndim == 1:
        out = out[0]
    if b.ndim == 1:
        out = out[..., 0]
    return out


def norm(a, axis: int | None = None):
    """Euclidean norm of a vector (or of a matrix's columns with ``axis=0``, rows with ``axis=1``)."""
    a = _f64(a)
    if axis is None:
        return math.sqrt(_sum(np.square(a.ravel()), axis=None))
    lines = np.ascontiguousarray(np.moveaxis(a, axis, -1))
    return np.sqrt(_sum(np.square(lines), axis=-1))


def _householder(r: np.ndarray, k: int, b: np.ndarray | None) -> np.ndarray | None:
    """Zero r[k+1:, k] by a reflection applied to r[k:, k:] (and b[k:]); returns the reflector's vector."""
    x = r[k:, k]
    length = norm(x)
    if length == 0.0:
        return None
    alpha = -length if x[0] >= 0.0 else length
    v = x.copy()
    v[0] -= alpha
    scale = 2.0 / float(_sum(np.square(v)))
    r[k:, k:] -= np.multiply.outer(v, _sum(v[:, None] * r[k:, k:], axis=0) * scale)
    if b is not None:
        b[k:] -= np.multiply.outer(v, _sum(v[:, None] * b[k:], axis=0) * scale)
    return v


def _pairwise_sum(terms: list[float]) -> float:
    """numpy's sum of a float64 vector of up to 128 terms, to the bit: one by one below 8 terms, else eight
    interleaved partial sums added as a tree, then the rest one by one (its pairwise_sum), after the identity +0."""
    count = len(terms)
    if count < 8:
        return 0.0 + reduce(add, terms, -0.0)
    partial = terms[:8]
    whole = count - count % 8
    for start in range(8, whole, 8):
        partial = list(map(add, partial, terms[start:start + 8]))
    p0, p1, p2, p3, p4, p5, p6, p7 = partial
    total = ((p0 + p1) + (p2 + p3)) + ((p4 + p5) + (p6 + p7))
    return 0.0 + reduce(add, terms[whole:], total)


def _sum_down(terms, columns: int) -> float:
    """numpy's sum of one column (an iterable of its terms) of an array of `columns` columns over its first axis:
    one row after another from +0 for more than one column, else the column's pairwise sum."""
    return reduce(add, terms, 0.0) if columns > 1 else _pairwise_sum(list(terms))


def _lstsq_in_floats(a: np.ndarray, rhs: np.ndarray, rcond: float) -> np.ndarray:
    """:func:`lstsq`'s operations, each the same IEEE operation on Python floats and each sum in numpy's order
    (:func:`_sum_down`, :func:`_pairwise_sum`): the same bits without numpy's cost per call, for small systems.
    Raises ZeroDivisionError where numpy would divide by zero (its caller then runs the numpy version)."""
    m, n = a.shape
    p = rhs.shape[1]
    columns = np.concatenate([a, rhs], axis=1).T.tolist()  # column-major: a swap moves two references
    order = list(range(n))
    rank = 0
    largest = 0.0
    for k in range(min(m, n)):
        tails = [column[k:] for column in columns[k:n]]
        if n - k > 1:
            lengths = [reduce(add, map(mul, tail, tail), 0.0) for tail in tails]
        else:
            lengths = [_pairwise_sum(list(map(mul, tails[0], tails[0])))]
        pivot = _pivot(lengths, k, largest, rcond)
        if pivot is None:
            break
        j, length, largest = pivot
        if j != k:
            columns[k], columns[j] = columns[j], columns[k]
            order[k], order[j] = order[j], order[k]
        rank = k + 1
        x = columns[k][k:]
        if m - k >= 8:
            length = math.sqrt(_pairwise_sum(list(map(mul, x, x))))
        if length == 0.0:
            continue
        alpha = -length if x[0] >= 0.0 else length
        v = list(x)
        v[0] = v[0] - alpha
        scale = 2.0 / _pairwise_sum(list(map(mul, v, v)))
        for c in range(k, n + p):
            column = columns[c]
            tail = column[k:]
            w = _sum_down(map(mul, v, tail), n - k if c < n else p) * scale
            column[k:] = map(sub, tail, map(mul, v, repeat(w)))  # t - v_i w, as numpy's outer product and update
    z = [[0.0] * n for _ in range(p)]  # column-major too
    for c in range(p):
        solution, right = z[c], columns[n + c]
        for k in range(rank - 1, -1, -1):
            row = map(itemgetter(k), columns[k + 1:rank])
            tail = _sum_down(map(mul, row, solution[k + 1:rank]), p) if k + 1 < rank else 0.0
            solution[k] = (right[k] - tail) / columns[k][k]
    x = np.zeros((n, p))
    x[order] = np.array(z).T
    return x


def _pivot(lengths: list[float], k: int, largest: float, rcond: float) -> tuple[int, float, float] | None:
    """Step `k`'s pivot column from the remaining columns' sums of squares `lengths`: (its index, its norm, the
    largest norm, which is the first step's), or None where it falls below `rcond` times the largest (rank k)."""
    j = k + _first_max(lengths)
    length = math.sqrt(lengths[j - k])
    largest = length if k == 0 else largest
    return (j, length, largest) if length > rcond * largest else None


def _first_max(values: list[float]) -> int:
    """np.argmax: the first largest value, or the first NaN if there is one."""
    best, largest = 0, -math.inf
    for i, value in enumerate(values):
        if value != value:
            return i
        if value > largest:
            best, largest = i, value
    return best


def _sums_down_in_order(rows: int, columns: int) -> bool:
    """Whether numpy sums a (rows x columns) array over its first axis one row after another from +0.0: it does
    for more than one column, and for one column of fewer than 8 rows (its pairwise sum starts with eight
    partial sums)."""
    return columns > 1 or rows < 8


def lstsq(a, b, rcond: float | None = None) -> np.ndarray:
    """Least-squares solution of a x = b by Householder QR with column pivoting.

    Columns whose pivot falls below ``rcond`` times the largest (default: machine epsilon times max(m, n), as
    numpy's) are left out and their unknowns set to zero: the basic solution, which for a column of zeros (an
    unknown nothing depends on) is also the minimum-norm one.
    """
    r = np.array(a, dtype=float)
    rhs = np.array(b, dtype=float)
    m, n = r.shape
    vector = rhs.ndim == 1
    if vector:
        rhs = rhs[:, None]
    if rcond is None:
        rcond = np.finfo(float).eps * max(m, n)
    p = rhs.shape[1]
    if m <= 128 and m * (n + p) <= _FLOATS_AT_MOST:
        try:
            x = _lstsq_in_floats(r, rhs, rcond)
            return x[:, 0] if vector else x
        except ZeroDivisionError:
            pass
    # a and b side by side: one reflection, one reduction and one update for both where the columns' sums are
    # the same sequential ones as each block's on its own
    work = np.concatenate([r, rhs], axis=1)
    order = list(range(n))
    rank = 0
    largest = 0.0
    for k in range(min(m, n)):
        lengths = _sum(np.square(work[k:, k:n]), axis=0)
        pivot = _pivot(lengths.tolist(), k, largest, rcond)
        if pivot is None:
            break
        j, length, largest = pivot
        if j != k:
            work[:, [k, j]] = work[:, [j, k]]
            order[k], order[j] = order[j], order[k]
        rank = k + 1
        x = work[k:, k]
        if m - k >= 8:  # else the sum of squares of x is the one of lengths to the bit: both sum one by one
            length = math.sqrt(_sum(np.square(x)))
        if length == 0.0:
            continue
        alpha = -length if x[0] >= 0.0 else length
        v = x.copy()
        v[0] -= alpha
        scale = 2.0 / float(_sum(np.square(v)))
        if _sums_down_in_order(m - k, n - k) and _sums_down_in_order(m - k, p):
            block = work[k:, k:]
            block -= np.multiply.outer(v, _sum(v[:, None] * block, axis=0) * scale)
        else:
            for block in (work[k:, k:n], work[k:, n:]):
                block -= np.multiply.outer(v, _sum(v[:, None] * block, axis=0) * scale)
    z = np.zeros((n, p))
    for k in range(rank - 1, -1, -1):
        tail = _sum(work[k, k + 1:rank, None] * z[k + 1:rank], axis=0) if k + 1 < rank else 0.0
        z[k] = (work[k, n:] - tail) / work[k, k]
    x = np.zeros_like(z)
    x[order] = z
    return x[:, 0] if vector else x


def inv_spd_batched(a) -> np.ndarray:
    """Inverses of a stack of small symmetric positive definite matrices (w x n x n), Gauss-Jordan without
    pivoting (stable for such matrices), every matrix in one pass."""
    work = np.array(a, dtype=float)
    w, n, _ = work.shape
    out = np.broadcast_to(np.eye(n), (w, n, n)).copy()
    for k in range(n):
        pivot = work[:, k, k].copy()
        work[:, k, :] /= pivot[:, None]
        out[:, k, :] /= pivot[:, None]
        for i in range(n):
            if i != k:
                factor = work[:, i, k].copy()
                work[:, i, :] -= factor[:, None] * work[:, k, :]
                out[:, i, :] -= factor[:, None] * out[:, k, :]
    return out


def generalized_inverse(a) -> np.ndarray:
    """A generalised inverse G of a square matrix (a G a = a), from :func:`lstsq` against the identity: for a
    singular ``a`` it inverts a maximal independent set of columns, which serves wherever any generalised inverse
    gives the same answer (a projection onto constraints, some of which repeat others)."""
    a = _f64(a)
    return lstsq(a, np.eye(a.shape[0]))


def psd_factor(a, rcond: float = 1e-12) -> np.ndarray:
    """F (n x r) with F F^T = a for a symmetric positive semi-definite ``a`` of rank r: Cholesky with diagonal
    pivoting, stopped where the largest remaining pivot falls below ``rcond`` times the largest diagonal entry."""
    work = np.array(a, dtype=float)
    n = work.shape[0]
    factor = np.zeros((n, n))
    remaining = np.diagonal(work).copy()
    scale = float(np.max(remaining)) if n else 0.0
    used = np.zeros(n, dtype=bool)
    rank = 0
    for k in range(n):
        candidates = np.where(used, -np.inf, remaining)
        p = int(np.argmax(candidates))
        if not candidates[p] > rcond * scale:
            break
        used[p] = True
        column = (work[:, p] - np.sum(factor[:, :k] * factor[p, :k], axis=1)) / np.sqrt(candidates[p])
        column[used & (np.arange(n) != p)] = 0.0
        column[p] = np.sqrt(candidates[p])
        factor[:, k] = column
        remaining = remaining - column * column
        rank = k + 1
    return factor[:, :rank]


def symmetric_eigen(a, max_sweeps: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (descending) and orthonormal eigenvectors (columns) of a symmetric matrix: cyclic Jacobi
    rotations, pairs (p, q) in row order, until the off-diagonal part is below 1e-30 of the whole in squares (or
    `max_sweeps` sweeps; a sweep at least squares the off-diagonal part once it is small)."""
    work = np.array(a, dtype=float)
    work = (work + work.T) / 2.0
    n = work.shape[0]
    vectors = np.eye(n)
    whole = float(np.sum(np.square(work)))
    for _ in range(max_sweeps):
        off = float(np.sum(np.square(work - np.diag(np.diagonal(work)))))
        if not off > 1e-30 * whole:
            break
        for p in range(n - 1):
            for q in range(p + 1, n):
                if work[p, q] == 0.0:
                    continue
                theta = (work[q, q] - work[p, p]) / (2.0 * work[p, q])
                t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
                t = -t if theta < 0.0 else t
                c = 1.0 / np.sqrt(t * t + 1.0)
                s = t * c
                for m in (work, vectors):
                    mp, mq = m[:, p].copy(), m[:, q].copy()
                    m[:, p], m[:, q] = c * mp - s * mq, s * mp + c * mq
                rp, rq = work[p, :].copy(), work[q, :].copy()
                work[p, :], work[q, :] = c * rp - s * rq, s * rp + c * rq
                work[p, q] = work[q, p] = 0.0
    values = np.diagonal(work).copy()
    order = np.argsort(-values, kind="stable")
    return values[order], vectors[:, order]


def solve_tridiagonal(lower, diagonal, upper, rhs) -> np.ndarray:
    """x with A x = rhs for tridiagonal A (``lower[i]`` = A[i+1, i], ``upper[i]`` = A[i, i+1]): Gaussian
    elimination with partial pivoting, as LAPACK's dgtsv (a row swap makes a second superdiagonal)."""
    d = np.array(diagonal, dtype=float).tolist()
    dl = np.array(lower, dtype=float).tolist()
    du = np.array(upper, dtype=float).tolist() + [0.0]
    b = np.array(rhs, dtype=float).tolist()
    n = len(d)
    du2 = [0.0] * n
    for i in range(n - 1):
        if abs(d[i]) >= abs(dl[i]):
            if d[i] == 0.0:
                raise LinAlgError("Singular matrix")
            f = dl[i] / d[i]
            d[i + 1] = d[i + 1] - f * du[i]
            b[i + 1] = b[i + 1] - f * b[i]
        else:
            f = d[i] / dl[i]
            d[i], dl[i] = dl[i], d[i]
            temp = d[i + 1]
            d[i + 1] = du[i] - f * temp
            du2[i] = du[i + 1]
            du[i + 1] = -f * du[i + 1]
            du[i] = temp
            b[i], b[i + 1] = b[i + 1], b[i] - f * b[i + 1]
    if d[n - 1] == 0.0:
        raise LinAlgError("Singular matrix")
    x = [0.0] * n
    x[n - 1] = b[n - 1] / d[n - 1]
    if n > 1:
        x[n - 2] = (b[n - 2] - du[n - 2] * x[n - 1]) / d[n - 2]
    for i in range(n - 3, -1, -1):
        x[i] = (b[i] - du[i] * x[i + 1] - du2[i] * x[i + 2]) / d[i]
    return np.array(x)


def qr(a) -> tuple[np.ndarray, np.ndarray]:
    """Reduced QR of an m x n matrix (m >= n) by Householder reflections: Q (m x n), R (n x n)."""
    r = np.array(a, dtype=float)
    m, n = r.shape
    reflectors = [_householder(r, k, None) for k in range(min(m, n))]
    q = np.eye(m, n)
    for k in range(min(m, n) - 1, -1, -1):
        v = reflectors[k]
        if v is not None:
            q[k:] -= np.multiply.outer(v, _sum(v[:, None] * q[k:], axis=0) * (2.0 / float(_sum(np.square(v)))))
    return q, np.triu(r[:n])
