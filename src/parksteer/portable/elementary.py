"""Elementary functions with every bit fixed: fdlibm's algorithms, mirroring operation for operation the C in
``model/codegen/portable_math.c`` that the compiled model uses (:mod:`parksteer.portable` says why)."""

from __future__ import annotations

import numpy as np

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
