"""parksteer.portable.distributions: Student's t quantile and the chi-square survival for whole degrees of freedom.

Checked here:
- the closed forms: t with 1 degree of freedom is Cauchy, t = tan(pi (p - 1/2)); with 2, t = (2p - 1) / sqrt(2 p
  (1 - p)); chi-square with 2 is exp(-x/2), with 1 erfc(sqrt(x/2)); each evaluated in 50 digits by mpmath;
- the true values (mpmath's regularized incomplete beta and gamma functions, 50 digits) at the probabilities the
  diagnosis asks for and beyond;
- agreement with scipy.special's ``stdtrit`` and ``chdtrc``, which the diagnosis used before, over the degrees of
  freedom it calls them with (measured: t within 3.7e-15 relative, 20 ulps, for 1 to 100 degrees of freedom at
  0.95 and 0.975; the chi-square survival within 7e-14 relative for 1 to 60 degrees of freedom, x from 1e-6 to
  1000, where scipy is itself the farther from the true value: up to 355 ulps against this module's 17);
- that a wrong degree of freedom or probability is refused.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from parksteer import portable as pm

mpmath.mp.dps = 50


def _ulps(value: float, truth) -> float:
    """|value - truth| in units of the last place of the true value."""
    return float(abs(mpmath.mpf(value) - truth) / mpmath.mpf(np.spacing(abs(float(truth)))))


def _true_t(p: float, dof: int):
    """The p quantile of t(dof) in 50 digits: the root of P(T > t) = 1 - p, P(T > t) = I_x(dof/2, 1/2) / 2."""
    nu, tail = mpmath.mpf(dof), 1 - mpmath.mpf(p)
    sign = 1 if tail < 0.5 else -1
    tail = min(tail, 1 - tail)

    def upper(t):
        return mpmath.betainc(nu / 2, mpmath.mpf(1) / 2, 0, nu / (nu + t * t), regularized=True) / 2 - tail

    start = mpmath.mpf(abs(pm.student_t_quantile(p, dof)))
    return sign * mpmath.findroot(upper, start)


def _true_chi2(x: float, dof: int):
    return mpmath.gammainc(mpmath.mpf(dof) / 2, mpmath.mpf(x) / 2, mpmath.inf, regularized=True)


PROBABILITIES = (0.95, 0.975, 0.6, 0.99, 0.999, 0.3, 0.05)


@pytest.mark.parametrize("p", [*PROBABILITIES, 0.5 + 2.0 ** -20, 0.9999])
def test_t_with_one_and_two_degrees_of_freedom_is_its_closed_form(p):
    """t(1) is the Cauchy distribution, its quantile tan(pi (p - 1/2)); t(2)'s is (2p - 1) / sqrt(2 p (1 - p))
    (both exact in 50 digits): within 4 ulps (the Cauchy's tail beyond 0.999 magnifies the rounding of p itself, so
    it is held to 1e-14 relative there)."""
    mp = mpmath.mpf(p)
    cauchy = mpmath.tan(mpmath.pi * (mp - mpmath.mpf(1) / 2))
    two = (2 * mp - 1) / mpmath.sqrt(2 * mp * (1 - mp))
    assert _ulps(pm.student_t_quantile(p, 2), two) <= 4
    if p < 0.999:
        assert _ulps(pm.student_t_quantile(p, 1), cauchy) <= 8
    assert pm.student_t_quantile(p, 1) == pytest.approx(float(cauchy), rel=1e-14)


@pytest.mark.parametrize("x", [1e-6, 0.01, 0.5, 1.0, 2.9, 3.1, 10.0, 100.0, 700.0])
def test_chi2_with_one_and_two_degrees_of_freedom_is_its_closed_form(x):
    """chi-square(2) survives with exp(-x/2) and chi-square(1) with erfc(sqrt(x/2)) (50 digits): within 2 ulps
    and 20 ulps (erfc from 1 - erf below x = 3, where erf is up to 0.92 of it)."""
    assert _ulps(pm.chi2_survival(x, 2), mpmath.exp(-mpmath.mpf(x) / 2)) <= 2
    assert _ulps(pm.chi2_survival(x, 1), mpmath.erfc(mpmath.sqrt(mpmath.mpf(x) / 2))) <= 20


@pytest.mark.parametrize("dof", [1, 2, 3, 4, 5, 7, 10, 13, 20, 31, 47, 60, 100])
def test_t_quantile_is_the_true_quantile(dof):
    """Against the root of the incomplete beta function in 50 digits: within 12 ulps up to 100 degrees of freedom
    (the continued fraction of the tail loses a few bits as dof / (dof + t^2) nears 1), and symmetric: the p and
    1 - p quantiles are each other's negatives."""
    for p in PROBABILITIES:
        assert _ulps(pm.student_t_quantile(p, dof), _true_t(p, dof)) <= 12, p
    assert pm.student_t_quantile(0.25, dof) == -pm.student_t_quantile(0.75, dof)  # 1 - 0.75 is 0.25 exactly
    assert pm.student_t_quantile(0.5, dof) == 0.0


@pytest.mark.parametrize("dof", [1, 2, 3, 4, 5, 6, 9, 12, 17, 24, 39, 60])
def test_chi2_survival_is_the_true_value(dof):
    """Against the regularized upper incomplete gamma function Q(dof/2, x/2) in 50 digits: within 20 ulps from
    x = 1e-6 to 1000 (values down to 1e-200); 1 at x = 0."""
    for x in (1e-6, 1e-3, 0.1, 0.5, 1.0, 2.9, 3.0, 3.1, 5.0, 10.0, 20.0, 50.0, 100.0, 300.0, 1000.0):
        assert _ulps(pm.chi2_survival(x, dof), _true_chi2(x, dof)) <= 20, x
    assert pm.chi2_survival(0.0, dof) == 1.0


def test_agrees_with_scipy_special_over_the_degrees_of_freedom_used():
    """The diagnosis asks for t at 0.975 (intervals: blocks less parameters) and 0.95 (a baseline's bounds: records
    less one), and for the chi-square survival of its axes' likelihood ratios: the values scipy.special gave, to
    4e-15 relative (t, 1 to 100 degrees of freedom) and 1e-13 (chi-square, 1 to 60, x from 1e-6 to 1000)."""
    special = pytest.importorskip("scipy.special")
    for dof in range(1, 101):
        for p in (0.95, 0.975):
            assert pm.student_t_quantile(p, dof) == pytest.approx(float(special.stdtrit(dof, p)), rel=4e-15, abs=0)
    for dof in range(1, 61):
        for x in np.geomspace(1e-6, 1e3, 60):
            expected = float(special.chdtrc(dof, x))
            assert pm.chi2_survival(float(x), dof) == pytest.approx(expected, rel=1e-13, abs=1e-300)


@pytest.mark.parametrize("dof", [0, -1, 2.5, True, float("nan")])
def test_degrees_of_freedom_not_a_whole_number_above_zero_are_refused(dof):
    """Only whole degrees of freedom have these closed forms: anything else is a ValueError naming it."""
    with pytest.raises(ValueError, match="degrees of freedom"):
        pm.student_t_quantile(0.975, dof)
    with pytest.raises(ValueError, match="degrees of freedom"):
        pm.chi2_survival(1.0, dof)


@pytest.mark.parametrize("p", [0.0, 1.0, -0.1, float("nan")])
def test_probability_outside_the_open_unit_interval_is_refused(p):
    """A quantile needs 0 < p < 1."""
    with pytest.raises(ValueError, match="probability"):
        pm.student_t_quantile(p, 5)


def test_results_are_python_floats_whatever_the_input_type():
    """numpy scalars and whole-valued floats are accepted; the answers are floats, as scipy's were cast to."""
    assert isinstance(pm.student_t_quantile(np.float64(0.975), np.int64(7)), float)
    assert isinstance(pm.chi2_survival(np.float64(3.0), 3.0), float)
    assert math.isnan(pm.chi2_survival(float("nan"), 3))
