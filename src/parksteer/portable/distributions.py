"""Student's t quantile and the chi-square survival for whole degrees of freedom, with every bit fixed
(:mod:`parksteer.portable` says why), and without scipy.special, whose import pulls in numpy.f2py and the array-API
layer (half a second a process).

With whole degrees of freedom both have closed forms in elementary functions (Abramowitz and Stegun 26.7.3-4 and
26.4.4-5), evaluated here in IEEE arithmetic, ``math.sqrt`` and the portable :func:`~.elementary.atan` and
:func:`~.elementary.exp` and :func:`~.elementary.log`:

- :func:`student_t_quantile`: t with ``P(T <= t) = p``, found by Newton's method on ``A(t) = P(|T| < t)``
  (A&S 26.7.3-4: with ``theta = atan(t / sqrt(dof))``, a finite series in ``cos^2 theta``), first in theta (where A
  is concave and bounded, so that the iteration from 0 rises to the root whatever the tail), then in t on the
  upper tail ``P(T > t) = I_x(dof/2, 1/2) / 2`` (A&S 26.7.1, 26.5.8: the incomplete beta function's continued
  fraction, which keeps the tail's relative accuracy where ``1 - A`` would lose it);
- :func:`chi2_survival`: ``P(X > x)`` for X chi-square with `dof` degrees of freedom (A&S 26.4.4-5: ``exp(-x/2)``
  times a finite sum for even `dof`; ``erfc(sqrt(x/2))`` plus one for odd, erfc from its power series or, beyond
  ``x/2 = 1.5``, Legendre's continued fraction).

Their agreement with scipy.special's ``stdtrit`` and ``chdtrc`` and with the true values is measured in
``tests/test_portable_distributions.py``.
"""

from __future__ import annotations

import math
from functools import lru_cache

from .elementary import atan, cos, exp, log, sin

_TWO_OVER_PI = 0.63661977236758134308
_SQRT_PI = 1.77245385090551602730
_PI = 3.14159265358979323846
_MAX_ITERATIONS = 200


def _whole(dof) -> int:
    if isinstance(dof, bool) or not float(dof).is_integer() or dof < 1:
        raise ValueError(f"degrees of freedom must be a whole number >= 1, not {dof!r}")
    return int(dof)


def _integer_power(x: float, n: int) -> float:
    """x**n for a whole n >= 0 by squaring (``float ** int`` calls the C library's pow)."""
    out = 1.0
    while n:
        if n & 1:
            out *= x
        x *= x
        n >>= 1
    return out


def _central(t: float, dof: int) -> float:
    """P(|T| < t) for t >= 0 (A&S 26.7.3 for odd `dof`, 26.7.4 for even)."""
    denominator = dof + t * t
    c = dof / denominator  # cos^2 theta
    term, total = 1.0, 1.0
    if dof % 2 == 0:
        for j in range(1, dof // 2):
            term *= c * ((2 * j - 1) / (2 * j))
            total += term
        return t / math.sqrt(denominator) * total
    theta = atan(t / math.sqrt(dof))
    if dof == 1:
        return _TWO_OVER_PI * theta
    for j in range(1, (dof - 1) // 2):
        term *= c * ((2 * j) / (2 * j + 1))
        total += term
    return _TWO_OVER_PI * (theta + t * math.sqrt(dof) / denominator * total)


def _beta_reciprocal(dof: int) -> float:
    """1 / B(dof/2, 1/2) = Gamma((dof+1)/2) / (Gamma(dof/2) sqrt(pi)): a ratio of whole numbers, over pi for odd
    `dof`, formed exactly in Python's integers and rounded once (then once more by pi)."""
    if dof % 2 == 0:  # n = dof/2: (2n-1)!! / (2^n (n-1)!)
        n = dof // 2
        numerator, denominator = 1, 2 ** n
        for j in range(1, n):
            numerator *= 2 * j + 1
            denominator *= j
        return numerator / denominator
    m = (dof + 1) // 2  # (m-1)! 2^(m-1) / ((2m-3)!! pi)
    numerator, denominator = 2 ** (m - 1), 1
    for j in range(1, m):
        numerator *= j
        denominator *= 2 * j - 1
    return numerator / denominator / _PI


def _log1p(u: float) -> float:
    """log(1 + u) for u >= 0 to a few ulps, from the portable log (Goldberg's correction for the rounding of 1 + u)."""
    w = 1.0 + u
    return u if w == 1.0 else log(w) * (u / (w - 1.0))


def _beta_fraction(a: float, b: float, x: float) -> float:
    """The continued fraction 1 / (1 + d1 / (1 + d2 / ...)) of the incomplete beta function, I_x(a, b) = x^a (1-x)^b
    / (a B(a, b)) times it (A&S 26.5.8): its depth found by Lentz's method, then evaluated from the bottom up,
    which rounds less (a few ulps where Lentz's product of factors drifts by tens)."""
    tiny = 1e-300
    numerators: list[float] = []
    c, d = 1.0, 0.0  # Lentz's start for 1 + d1 / (1 + d2 / ...)
    for m in range(_MAX_ITERATIONS):
        for numerator in (-(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1.0)),
                          (m + 1) * (b - m - 1) * x / ((a + 2 * m + 1.0) * (a + 2 * m + 2.0))):
            numerators.append(numerator)
            d = 1.0 + numerator * d
            d = 1.0 / (d if abs(d) > tiny else tiny)
            c = 1.0 + numerator / c
            c = c if abs(c) > tiny else tiny
            change = c * d
        if abs(change - 1.0) < 1e-16:
            break
    denominator = 1.0
    for numerator in reversed(numerators):
        denominator = 1.0 + numerator / denominator
    return 1.0 / denominator


def _upper_tail(t: float, dof: int) -> float:
    """P(T > t) for t >= 0, to a few ulps relative however small: I_x(dof/2, 1/2) / 2 with x = dof / (dof + t^2)
    (A&S 26.7.1), by the continued fraction, its factor x^(dof/2) as exp(-dof/2 log1p(t^2/dof)); near t = 0 as
    1/2 - I_(1-x)(1/2, dof/2) / 2, which is no smaller than a quarter there."""
    a = 0.5 * dof
    squared = t * t
    root = math.sqrt(dof + squared)
    x_to_a = exp(-a * _log1p(squared / dof))
    y_to_half = t / root  # sqrt(1 - x)
    front = x_to_a * y_to_half * _beta_reciprocal(dof)
    x = dof / (dof + squared)
    if x < (a + 1.0) / (a + 2.5):
        return 0.5 * front * _beta_fraction(a, 0.5, x) / a
    return 0.5 - front * _beta_fraction(0.5, a, squared / (dof + squared))


def _cos_power(c: float, power_of_cos: int) -> float:
    """cos^m theta from c = cos^2 theta."""
    half = _integer_power(c, power_of_cos // 2)
    return half * math.sqrt(c) if power_of_cos % 2 else half


def student_t_quantile(p: float, dof: int) -> float:
    """The p quantile of Student's t with `dof` (a whole number) degrees of freedom, ``scipy.special.stdtrit(dof,
    p)`` (module docstring)."""
    dof = _whole(dof)
    p = float(p)
    if not 0.0 < p < 1.0:
        raise ValueError(f"probability must be in (0, 1), not {p!r}")
    return _t_quantile(p, dof)


@lru_cache(maxsize=256)
def _t_quantile(p: float, dof: int) -> float:
    """:func:`student_t_quantile` of checked arguments, kept: a diagnosis asks for the same few (a few ms each)."""
    if p == 0.5:
        return 0.0
    tail = min(p, 1.0 - p)  # exact: 1 - p for p >= 1/2 is (Sterbenz)
    density_at_0 = _beta_reciprocal(dof) / math.sqrt(dof)
    root_dof = math.sqrt(dof)
    # In theta = atan(t / sqrt(dof)), A = P(|T| < t) has the falling slope 2 f(0) sqrt(dof) cos^(dof-1) theta: A is
    # concave, and Newton's steps from 0 rise monotonically to the root.
    target, theta = 1.0 - 2.0 * tail, 0.0
    for _ in range(_MAX_ITERATIONS):
        cos_theta = cos(theta)
        step = ((target - _central(root_dof * sin(theta) / cos_theta, dof))
                / (2.0 * density_at_0 * root_dof * _cos_power(cos_theta * cos_theta, dof - 1)))
        if not step > 1e-9 * max(theta, 1e-300):
            break
        theta += step
    # then in t, to the last bits: on the upper tail where it is below a quarter (A's rounding would cost them
    # there), else on A, whose target 1 - 2 tail is then exact and which keeps its relative accuracy near t = 0
    t = root_dof * sin(theta) / cos(theta)
    for _ in range(8):
        density = density_at_0 * _cos_power(dof / (dof + t * t), dof + 1)
        if tail < 0.25:
            step = (_upper_tail(t, dof) - tail) / density
        else:
            step = (target - _central(t, dof)) / (2.0 * density)
        if t + step == t:
            break
        t += step
    return t if p > 0.5 else -t


def _erfc(z: float) -> float:
    """erfc(sqrt(z)) for z >= 0: 1 - erf from erf's power series (A&S 7.1.6) up to z = 1.5, where erfc is above
    0.08; beyond, Legendre's continued fraction for the upper incomplete Gamma(1/2, z), evaluated by Lentz's
    method."""
    y = math.sqrt(z)
    if z < 1.5:
        term, total = 1.0, 1.0
        for n in range(1, _MAX_ITERATIONS):
            term *= 2.0 * z / (2 * n + 1)
            total += term
            if term < 1e-17 * total:
                break
        return 1.0 - 2.0 / _SQRT_PI * exp(-z) * y * total
    tiny = 1e-300
    b = z + 0.5
    c, d = 1.0 / tiny, 1.0 / b
    fraction = d
    for i in range(1, _MAX_ITERATIONS):
        a = -i * (i - 0.5)
        b += 2.0
        d = a * d + b
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = b + a / c
        c = c if abs(c) > tiny else tiny
        change = c * d
        fraction *= change
        if abs(change - 1.0) < 1e-16:
            break
    return exp(-z) * y / _SQRT_PI * fraction


def chi2_survival(x: float, dof: int) -> float:
    """P(X > x) for X chi-square with `dof` (a whole number) degrees of freedom, ``scipy.special.chdtrc(dof, x)``
    (module docstring); relative accuracy holds while ``exp(-x/2)`` is a normal number (x below about 1400)."""
    dof = _whole(dof)
    x = float(x)
    if math.isnan(x):
        return math.nan
    if x <= 0.0:
        return 1.0
    z = 0.5 * x
    if dof % 2 == 0:  # exp(-z) sum_{j < dof/2} z^j / j!
        term = exp(-z)
        total = term
        for j in range(1, dof // 2):
            term *= z / j
            total += term
        return total
    # erfc(sqrt z) + exp(-z) sum_{j=1}^{(dof-1)/2} z^(j-1/2) / Gamma(j+1/2)
    total = 0.0
    if dof > 1:
        term = 2.0 * exp(-z) * math.sqrt(z) / _SQRT_PI
        total = term
        for j in range(1, (dof - 1) // 2):
            term *= z / (j + 0.5)
            total += term
    return _erfc(z) + total
