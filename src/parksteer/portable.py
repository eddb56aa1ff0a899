"""Arithmetic whose every bit is fixed by this code, not by the machine it runs on.

numpy hands matrix products, ``dot``, ``norm`` and everything in ``numpy.linalg`` to the BLAS and LAPACK it was
built with (OpenBLAS), which picks a kernel for the CPU at load time: a Haswell kernel sums in another order, and
fuses multiply-adds, where a SkylakeX or Sandybridge kernel does not, and the thread count splits sums differently
again. Its transcendental functions (``np.sin``, ``np.exp``, ``np.tanh``, ...) dispatch on the SIMD level (AVX-512
and AVX2 have their own implementations). Each gives the last bit to the machine; an adaptive integrator or an
iterative fit then turns that bit into a visible difference in a figure.

What is here uses only what IEEE 754 fixes exactly: elementwise +, -, *, /, sqrt, floor, frexp and ldexp, and
``np.sum``, whose pairwise order depends on the array's shape alone. So the same inputs give the same bits on any
machine, with any BLAS kernel, SIMD level or thread count.

- Linear algebra for the small systems of the model and the diagnosis (up to a few hundred unknowns):
  :func:`dot`, :func:`matmul`, :func:`norm`, :func:`solve`, :func:`inv`, :func:`cholesky`, :func:`lstsq`,
  :func:`qr`. Sums run in a fixed order; solves are Gaussian elimination with partial pivoting and Householder
  QR with column pivoting, the algorithms LAPACK uses, written out.
- Elementary functions :func:`sin`, :func:`cos`, :func:`tan`, :func:`atan`, :func:`atan2`, :func:`exp`,
  :func:`expm1`, :func:`tanh`, :func:`log`, :func:`power`, :func:`hypot`: fdlibm's algorithms, mirroring operation
  for operation the C in ``model/codegen/portable_math.c`` that the compiled model uses, so the model's C and its
  Python side agree to the bit (``tests/test_portable.py``). Each is within about one ulp of the true value.
- The few filters the loggers and the import use, designed in closed form: :func:`butterworth_lowpass_sos`,
  :func:`sos_steady_state`, :func:`hamming_lowpass_fir` (scipy designs them through numpy's polynomial and
  linear-algebra routines, which call the BLAS).

Scalars in give Python floats out; arrays give arrays.
"""

from __future__ import annotations

import numpy as np

LinAlgError = np.linalg.LinAlgError

# --- linear algebra ---------------------------------------------------------------------------------------------

_CHUNK_ELEMENTS = 1 << 21  # temporaries of matmul stay under 16 MB


def _f64(a) -> np.ndarray:
    return np.asarray(a, dtype=float)


def dot(a, b) -> float:
    """sum(a * b) of two vectors, pairwise in a fixed order."""
    return float(np.sum(np.multiply(_f64(a), _f64(b))))


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
        out[start:start + rows] = np.sum(block[:, None, :] * bt[None, :, :], axis=-1)
    if a.ndim == 1:
        out = out[0]
    if b.ndim == 1:
        out = out[..., 0]
    return out


def norm(a, axis: int | None = None):
    """Euclidean norm of a vector (or of a matrix's columns with ``axis=0``, rows with ``axis=1``)."""
    a = _f64(a)
    if axis is None:
        return float(np.sqrt(np.sum(np.square(a.ravel()))))
    lines = np.ascontiguousarray(np.moveaxis(a, axis, -1))
    return np.sqrt(np.sum(np.square(lines), axis=-1))


def solve(a, b) -> np.ndarray:
    """x with a x = b (a square); Gaussian elimination with partial pivoting. Raises LinAlgError if singular."""
    lu = np.array(a, dtype=float)
    x = np.array(b, dtype=float)
    n = lu.shape[0]
    if lu.shape != (n, n) or x.shape[0] != n:
        raise ValueError(f"solve: shapes {lu.shape} and {x.shape} do not align")
    vector = x.ndim == 1
    if vector:
        x = x[:, None]
    for k in range(n):
        p = k + int(np.argmax(np.abs(lu[k:, k])))
        if lu[p, k] == 0.0:
            raise LinAlgError("Singular matrix")
        if p != k:
            lu[[k, p]] = lu[[p, k]]
            x[[k, p]] = x[[p, k]]
        if k + 1 < n:
            factor = lu[k + 1:, k] / lu[k, k]
            lu[k + 1:, k:] -= np.multiply.outer(factor, lu[k, k:])
            x[k + 1:] -= np.multiply.outer(factor, x[k])
    for k in range(n - 1, -1, -1):
        tail = np.sum(lu[k, k + 1:, None] * x[k + 1:], axis=0) if k + 1 < n else 0.0
        x[k] = (x[k] - tail) / lu[k, k]
    return x[:, 0] if vector else x


def inv(a) -> np.ndarray:
    """The inverse of a square matrix (:func:`solve` against the identity)."""
    a = _f64(a)
    return solve(a, np.eye(a.shape[0]))


def cholesky(a) -> np.ndarray:
    """Lower-triangular L with L L^T = a; raises LinAlgError unless a is positive definite."""
    a = _f64(a)
    n = a.shape[0]
    low = np.zeros((n, n))
    for j in range(n):
        d = a[j, j] - float(np.sum(np.square(low[j, :j])))
        if not d > 0.0:
            raise LinAlgError("Matrix is not positive definite")
        low[j, j] = np.sqrt(d)
        if j + 1 < n:
            low[j + 1:, j] = (a[j + 1:, j] - np.sum(low[j + 1:, :j] * low[j, :j], axis=1)) / low[j, j]
    return low


def _householder(r: np.ndarray, k: int, b: np.ndarray | None) -> np.ndarray | None:
    """Zero r[k+1:, k] by a reflection applied to r[k:, k:] (and b[k:]); returns the reflector's vector."""
    x = r[k:, k]
    length = norm(x)
    if length == 0.0:
        return None
    alpha = -length if x[0] >= 0.0 else length
    v = x.copy()
    v[0] -= alpha
    scale = 2.0 / float(np.sum(np.square(v)))
    r[k:, k:] -= np.multiply.outer(v, np.sum(v[:, None] * r[k:, k:], axis=0) * scale)
    if b is not None:
        b[k:] -= np.multiply.outer(v, np.sum(v[:, None] * b[k:], axis=0) * scale)
    return v


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
    order = np.arange(n)
    rank = 0
    largest = 0.0
    for k in range(min(m, n)):
        lengths = np.sum(np.square(r[k:, k:]), axis=0)
        j = k + int(np.argmax(lengths))
        if k == 0:
            largest = float(np.sqrt(lengths[j - k]))
        if not np.sqrt(lengths[j - k]) > rcond * largest:
            break
        if j != k:
            r[:, [k, j]] = r[:, [j, k]]
            order[[k, j]] = order[[j, k]]
        _householder(r, k, rhs)
        rank = k + 1
    z = np.zeros((n, rhs.shape[1]))
    for k in range(rank - 1, -1, -1):
        tail = np.sum(r[k, k + 1:rank, None] * z[k + 1:rank], axis=0) if k + 1 < rank else 0.0
        z[k] = (rhs[k] - tail) / r[k, k]
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
            q[k:] -= np.multiply.outer(v, np.sum(v[:, None] * q[k:], axis=0) * (2.0 / float(np.sum(np.square(v)))))
    return q, np.triu(r[:n])


# --- elementary functions (mirror of model/codegen/portable_math.c) ----------------------------------------------

_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
_INVPIO2 = 6.36619772367581382433e-01
_REDUCE_LIMIT = 823549.6645826427  # 2^19 pi/2
_ATANHI = np.array([4.63647609000806093515e-01, 7.85398163397448278999e-01,
                    9.82793723247329054082e-01, 1.57079632679489655800e+00])
_ATANLO = np.array([2.26987774529616870924e-17, 3.06161699786838301793e-17,
                    1.39033110312309984516e-17, 6.12323399573676603587e-17])
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_INVLN2 = 1.44269504088896338700e+00
_EXP_OVER = 7.09782712893383973096e+02
_EXP_UNDER = -7.45133219101941108420e+02


def _elementwise(func):
    """Run `func` on float64 arrays with floating-point warnings off; a scalar in gives a float out."""
    def wrapper(*args):
        arrays = [np.asarray(a, dtype=float) for a in args]
        with np.errstate(all="ignore"):
            out = func(*arrays)
        if all(np.ndim(a) == 0 for a in args):
            return float(out)
        return out
    wrapper.__name__ = func.__name__
    wrapper.__doc__ = func.__doc__
    return wrapper


def _reduce(x):
    fn = np.floor(x * _INVPIO2 + 0.5)
    t = x - fn * _PIO2_1
    w = fn * _PIO2_2
    r = t - w
    w = fn * _PIO2_2T - ((t - r) - w)
    y0 = r - w
    y1 = (r - y0) - w
    quadrant = fn - 4.0 * np.floor(fn * 0.25)
    return y0, y1, quadrant


def _kernel_sin(x, y):
    z = x * x
    v = z * x
    r = 8.33333333332248946124e-03 + z * (-1.98412698298579493134e-04 + z * (
        2.75573137070700676789e-06 + z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))
    return x - ((z * (0.5 * y - v * r) - y) - v * -1.66666666666666324348e-01)


def _kernel_cos(x, y):
    z = x * x
    w = z * z
    r = z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03 + z * 2.48015872894767294178e-05)) + (
        w * w * (-2.75573143513906633035e-07 + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))
    hz = 0.5 * z
    w = 1.0 - hz
    return w + (((1.0 - w) - hz) + (z * r - x * y))


def _sin_cos(x, shift: int):
    y0, y1, quadrant = _reduce(x)
    s, c = _kernel_sin(y0, y1), _kernel_cos(y0, y1)
    q = (quadrant + shift) % 4  # cos x = sin(x + pi/2): one quadrant on
    out = np.select([q == 0, q == 1, q == 2], [s, c, -s], -c)
    return np.where(np.abs(x) < _REDUCE_LIMIT, out, np.nan)


@_elementwise
def sin(x):
    """sin x (fdlibm; |x| < 2^19 pi/2, NaN beyond)."""
    return _sin_cos(x, 0)


@_elementwise
def cos(x):
    """cos x (fdlibm; |x| < 2^19 pi/2, NaN beyond)."""
    return _sin_cos(x, 1)


@_elementwise
def tan(x):
    """tan x as sin x / cos x (within 2 ulp)."""
    return _sin_cos(x, 0) / _sin_cos(x, 1)


def _atan(x):
    a = np.abs(x)
    ids = np.select([a < 0.4375, a < 0.6875, a < 1.1875, a < 2.4375], [-1, 0, 1, 2], 3)
    t = np.select([ids == -1, ids == 0, ids == 1, ids == 2],
                  [x, (2.0 * a - 1.0) / (2.0 + a), (a - 1.0) / (a + 1.0), (a - 1.5) / (1.0 + 1.5 * a)], -1.0 / a)
    z = t * t
    w = z * z
    s1 = z * (3.33333333333329318027e-01 + w * (1.42857142725034663711e-01 + w * (9.09088713343650656196e-02 + w * (
        6.66107313738753120669e-02 + w * (4.97687799461593236017e-02 + w * 1.62858201153657823623e-02)))))
    s2 = w * (-1.99999999998764832476e-01 + w * (-1.11111104054623557880e-01 + w * (-7.69187620504482999495e-02 + w * (
        -5.83357013379057348645e-02 + w * -3.65315727442169155270e-02))))
    small = t - t * (s1 + s2)
    k = np.maximum(ids, 0)
    r = _ATANHI[k] - ((t * (s1 + s2) - _ATANLO[k]) - t)
    r = np.where(x < 0, -r, r)
    big = _ATANHI[3] + _ATANLO[3]
    out = np.where(ids < 0, small, r)
    out = np.where(a >= 7.378697629483821e19, np.where(x > 0, big, -big), out)
    return np.where(np.isnan(x), x, out)


@_elementwise
def atan(x):
    """arctan x (fdlibm)."""
    return _atan(x)


@_elementwise
def atan2(y, x):
    """The angle of (x, y), in (-pi, pi] (fdlibm's reduction to atan |y/x|)."""
    pi, pi_lo = 3.1415926535897931160e+00, 1.2246467991473531772e-16
    y, x = np.broadcast_arrays(y, x)
    z = _atan(np.abs(y / x))
    quadrant = np.where(x > 0.0, np.where(y > 0.0, z, -z), np.where(y > 0.0, pi - (z - pi_lo), (z - pi_lo) - pi))
    half = _ATANHI[3] + _ATANLO[3]
    out = np.where(x == 0.0, np.where(y > 0.0, half, -half), quadrant)
    on_axis = np.where((x < 0.0) | ((x == 0.0) & np.signbit(x)), np.where(np.signbit(y), -pi, pi), y)
    out = np.where(y == 0.0, on_axis, out)
    return np.where(np.isnan(x) | np.isnan(y), x + y, out)


def _split_ln2(x):
    k = np.trunc(_INVLN2 * x + np.where(x < 0.0, -0.5, 0.5))
    hi = x - k * _LN2_HI
    lo = k * _LN2_LO
    return k, hi, lo, hi - lo


@_elementwise
def exp(x):
    """e^x (fdlibm)."""
    k, hi, lo, r = _split_ln2(x)
    t = r * r
    c = r - t * (1.66666666666666019037e-01 + t * (-2.77777777770155933842e-03 + t * (
        6.61375632143793436117e-05 + t * (-1.65339022054652515390e-06 + t * 4.13813679705723846039e-08))))
    y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi)
    out = np.ldexp(y, np.clip(np.nan_to_num(k), -2000, 2000).astype(np.int64))
    out = np.where(x > _EXP_OVER, np.inf, np.where(x < _EXP_UNDER, 0.0, out))
    return np.where(np.isnan(x), x, out)


def _expm1(x):
    k, hi, lo, r = _split_ln2(x)
    c = (hi - r) - lo
    hfx = 0.5 * r
    hxs = r * hfx
    r1 = 1.0 + hxs * (-3.33333333333331316428e-02 + hxs * (1.58730158725481460165e-03 + hxs * (
        -7.93650757867487942473e-05 + hxs * (4.00821782732936239552e-06 + hxs * -2.01099218183624371326e-07))))
    t = 3.0 - r1 * hfx
    e0 = hxs * ((r1 - t) / (6.0 - r * t))
    e = (r * (e0 - c) - c)
    e = e - hxs
    ki = np.clip(np.nan_to_num(k), -2000, 2000).astype(np.int64)
    out = np.select(
        [k == 0.0, k == -1.0, k == 1.0, (k <= -2.0) | (k > 56.0), k < 20.0],
        [r - (r * e0 - hxs),
         0.5 * (r - e) - 0.5,
         np.where(r < -0.25, -2.0 * (e - (r + 0.5)), 1.0 + 2.0 * (r - e)),
         np.ldexp(1.0 - (e - r), ki) - 1.0,
         np.ldexp((1.0 - np.ldexp(1.0, -ki)) - (e - r), ki)],
        np.ldexp((r - (e + np.ldexp(1.0, -ki))) + 1.0, ki))
    out = np.where(x > _EXP_OVER, np.inf, np.where(x < -38.0, -1.0, out))
    return np.where(np.isnan(x), x, out)


@_elementwise
def expm1(x):
    """e^x - 1, accurate near 0 (fdlibm)."""
    return _expm1(x)


@_elementwise
def tanh(x):
    """tanh x (fdlibm, through expm1)."""
    a = np.abs(x)
    t = _expm1(-2.0 * a)
    z = np.where(a >= 22.0, 1.0, np.where(a >= 1.0, 1.0 - 2.0 / (_expm1(2.0 * a) + 2.0), -t / (t + 2.0)))
    return np.where(np.isnan(x), x, np.where(x < 0.0, -z, z))


def _log(x):
    m, e = np.frexp(x)
    low = m < 0.70710678118654752440
    m = np.where(low, m * 2.0, m)
    dk = np.where(low, e - 1, e).astype(float)
    f = m - 1.0
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    t1 = w * (3.999999999940941908e-01 + w * (2.222219843214978396e-01 + w * 1.531383769920937332e-01))
    t2 = z * (6.666666666666735130e-01 + w * (2.857142874366239149e-01 + w * (
        1.818357216161805012e-01 + w * 1.479819860511658591e-01)))
    big_r = t2 + t1
    hfsq = 0.5 * f * f
    out = dk * _LN2_HI - ((hfsq - (s * (hfsq + big_r) + dk * _LN2_LO)) - f)
    out = np.where(x == 0.0, -np.inf, np.where(x < 0.0, np.nan, out))
    return np.where(np.isnan(x) | (x == np.inf), x, out)


@_elementwise
def log(x):
    """Natural logarithm (fdlibm's polynomial, one formula for every binade)."""
    return _log(x)


@_elementwise
def power(x, y):
    """x^y: integer y (|y| <= 64) by repeated squaring, any sign of x; otherwise exp(y log x) for x > 0."""
    x, y = np.broadcast_arrays(x, y)
    general = np.where(x == 0.0, np.where(y > 0.0, 0.0, np.inf), exp(y * _log(x)))
    integral = (y == np.floor(y)) & (np.abs(y) <= 64.0)
    if not np.any(integral):
        return general
    n = np.where(integral, np.abs(y), 0.0).astype(np.int64)
    base, result = x.copy(), np.ones_like(x)
    while np.any(n):
        odd = (n & 1) == 1
        result = np.where(odd, result * base, result)
        n = n >> 1
        base = np.where(n > 0, base * base, base)
    result = np.where(y < 0.0, 1.0 / result, result)
    return np.where(integral, result, general)


@_elementwise
def hypot(x, y):
    """sqrt(x^2 + y^2) (no guard against overflow: the arguments here are lengths and forces)."""
    return np.sqrt(x * x + y * y)


# --- filter design (the few filters the loggers and the import use, in closed form) -----------------------------


def butterworth_lowpass_sos(order: int, cutoff_hz: float, rate_hz: float) -> np.ndarray:
    """Second-order sections (rows b0 b1 b2 1 a1 a2) of a digital Butterworth low-pass, by the bilinear transform
    with the cutoff prewarped: the design of ``scipy.signal.butter(order, cutoff_hz, fs=rate_hz, output="sos")``
    written out, with c = tan(pi fc / fs) and each analogue pole pair's damping q = 2 sin((2k + 1) pi / 2n):
    H(z) = c^2 (1 + 1/z)^2 / ((1 + q c + c^2) + 2 (c^2 - 1) / z + (1 - q c + c^2) / z^2), and for an odd order a
    first-order section c (1 + 1/z) / ((1 + c) + (c - 1) / z)."""
    if order < 1 or not 0.0 < cutoff_hz < 0.5 * rate_hz:
        raise ValueError(f"Butterworth low-pass: order {order} and cutoff {cutoff_hz} Hz at {rate_hz} Hz")
    c = tan(np.pi * cutoff_hz / rate_hz)
    c2 = c * c
    sections = []
    for k in range(order // 2):
        q = 2.0 * sin((2 * k + 1) * np.pi / (2 * order))
        d = 1.0 + q * c + c2
        g = c2 / d
        sections.append([g, 2.0 * g, g, 1.0, 2.0 * (c2 - 1.0) / d, (1.0 - q * c + c2) / d])
    if order % 2:
        g = c / (1.0 + c)
        sections.append([g, g, 0.0, 1.0, (c - 1.0) / (1.0 + c), 0.0])
    return np.array(sections)


def sos_steady_state(sos: np.ndarray) -> np.ndarray:
    """Initial states (per section, direct form II transposed as scipy.signal.sosfilt) for a filter at rest under a
    unit input: each section's output is its DC gain G = sum(b) / sum(a), its states z2 = b2 - a2 G and
    z1 = b1 - a1 G + z2, scaled by the DC gain of the sections before it (scipy.signal.sosfilt_zi, in closed
    form)."""
    states = np.empty((len(sos), 2))
    scale = 1.0
    for i, (b0, b1, b2, a0, a1, a2) in enumerate(np.asarray(sos, dtype=float)):
        b0, b1, b2, a1, a2 = b0 / a0, b1 / a0, b2 / a0, a1 / a0, a2 / a0
        gain = ((b0 + b1) + b2) / ((1.0 + a1) + a2)
        z2 = b2 - a2 * gain
        states[i] = (scale * ((b1 - a1 * gain) + z2), scale * z2)
        scale = scale * gain
    return states


def hamming_lowpass_fir(taps: int, cutoff: float) -> np.ndarray:
    """Linear-phase FIR low-pass, windowed sinc with a Hamming window, unit gain at DC; `cutoff` relative to the
    Nyquist frequency: ``scipy.signal.firwin(taps, cutoff, window="hamming")`` written out."""
    m = np.arange(taps) - 0.5 * (taps - 1)
    x = np.pi * cutoff * m
    sinc = np.where(m == 0.0, 1.0, sin(np.where(m == 0.0, 1.0, x)) / np.where(m == 0.0, 1.0, x))
    window = 0.54 + 0.46 * cos(np.linspace(-np.pi, np.pi, taps))
    h = cutoff * sinc * window
    return h / float(np.sum(h))


def fir_decimate(values: np.ndarray, fir: np.ndarray, factor: int) -> np.ndarray:
    """``scipy.signal.resample_poly(values, 1, factor, window=fir)`` written out, with its zero-phase delay and its
    zero padding, summed in upfirdn's order (oldest sample first, one rounding per product and per sum), so that it
    gives the same bits without importing scipy.signal (more than a second per process)."""
    values = np.asarray(values, dtype=float)
    n_in = len(values)
    n_out = n_in // factor + bool(n_in % factor)
    half_len = (len(fir) - 1) // 2
    n_pre_pad = factor - half_len % factor
    n_pre_remove = (half_len + n_pre_pad) // factor
    h = np.concatenate([np.zeros(n_pre_pad), np.asarray(fir, dtype=float)])
    # output m of the full convolution taken every `factor` samples: sum over taps j of h[j] * values[m factor - j]
    outputs = np.arange(n_pre_remove, n_pre_remove + n_out) * factor
    out = np.zeros(n_out)
    for j in range(len(h) - 1, -1, -1):
        if h[j] == 0.0:
            continue
        index = outputs - j
        inside = (index >= 0) & (index < n_in)
        out[inside] = out[inside] + values[index[inside]] * h[j]
    return out


def running_median(values: np.ndarray, size: int) -> np.ndarray:
    """The median of `size` (odd) samples centred on each sample, the ends repeated:
    ``scipy.ndimage.median_filter(values, size, mode="nearest")`` (a selection: exact), without scipy.ndimage."""
    half = size // 2
    padded = np.concatenate([np.full(half, values[0]), values, np.full(half, values[-1])])
    windows = np.lib.stride_tricks.sliding_window_view(padded, size)
    out = np.empty(len(values))
    for start in range(0, len(values), 1 << 16):  # in blocks: a partitioned copy of every window at once is n * size
        out[start:start + (1 << 16)] = np.partition(windows[start:start + (1 << 16)], half, axis=1)[:, half]
    return out


def running_max3(values: np.ndarray) -> np.ndarray:
    """The largest of each sample and its two neighbours, the ends repeated:
    ``scipy.ndimage.maximum_filter1d(values, 3, mode="nearest")``, without scipy.ndimage."""
    padded = np.concatenate([values[:1], values, values[-1:]])
    return np.maximum(np.maximum(padded[:-2], padded[1:-1]), padded[2:])


__all__ = ["LinAlgError", "dot", "matmul", "norm", "solve", "inv", "cholesky", "lstsq", "qr", "inv_spd_batched",
           "generalized_inverse", "psd_factor", "solve_tridiagonal",
           "sin", "cos", "tan", "atan", "atan2", "exp", "expm1", "tanh", "log", "power", "hypot",
           "butterworth_lowpass_sos", "sos_steady_state", "hamming_lowpass_fir", "fir_decimate",
           "running_median", "running_max3"]
