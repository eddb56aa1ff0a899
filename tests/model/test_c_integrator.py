"""The C stiff integrator (src/parksteer/model/codegen/integrator.c) on test problems with known answers.

Each test compiles integrator.c after portable_math.c and a small C preamble that defines NY, NQ, ps_rhs and
ps_jac (as the generated model code does; the prescribed-rack functions as stubs), with the system cc, and calls
ps_integrate through ctypes. The prescribed-rack path (ps_integrate_prescribed) is checked on the model itself, in
tests/model/test_rack_drive.py.
"""

from __future__ import annotations

import ctypes
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

import parksteer

INTEGRATOR_C = Path(parksteer.__file__).resolve().parent / "model" / "codegen" / "integrator.c"
PORTABLE_MATH_C = INTEGRATOR_C.with_name("portable_math.c")  # ps_pow of the step control, as in a generated model

pytestmark = pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler (cc)")

OK, BUDGET_EXCEEDED, STEP_TOO_SMALL, EVALUATION_FAILED = 0, 1, 2, 3


class Problem:
    """ps_integrate of one compiled test problem."""

    def __init__(self, lib: ctypes.CDLL, n_y: int):
        self.lib, self.n_y = lib, n_y
        vp = ctypes.c_void_p
        lib.ps_integrate.restype = ctypes.c_int
        lib.ps_integrate.argtypes = [vp, vp, ctypes.c_int, vp, ctypes.c_int, vp, ctypes.c_double, vp, ctypes.c_long,
                                     vp, vp]

    def integrate(self, y0, t_out, rtol, atol, t_crit=(), max_steps=100_000, p=(0.0,)):
        y0 = np.ascontiguousarray(y0, dtype=float)
        t_out = np.ascontiguousarray(t_out, dtype=float)
        t_crit = np.ascontiguousarray(t_crit, dtype=float)
        atol = np.ascontiguousarray(np.broadcast_to(atol, (self.n_y,)), dtype=float)
        p = np.ascontiguousarray(p, dtype=float)
        y_out = np.full((len(t_out), self.n_y), np.nan)
        stats = np.zeros(4)
        code = self.lib.ps_integrate(p.ctypes.data, y0.ctypes.data, len(t_out), t_out.ctypes.data, len(t_crit),
                                     t_crit.ctypes.data if len(t_crit) else None, rtol, atol.ctypes.data, max_steps,
                                     y_out.ctypes.data, stats.ctypes.data)
        return code, y_out, stats

    def function(self, name: str, restype=ctypes.c_int):
        function = getattr(self.lib, name)
        function.restype, function.argtypes = restype, []
        return function


# The test problems are handwheel-driven systems; the prescribed-rack entry points the integrator also dispatches to
# (ps_integrate_prescribed, and its sensitivities' tangent) are stubs that fail, except in SENSITIVITY_PROBLEM.
PRESCRIBED_STUBS = """
#define NO (NQ - 1)
#define INPUT_OFFSET 2
#define PS_SENSITIVITIES 0
int ps_prescribed_rhs(double t, const double *z, const double *p, const double *rack, double *zdot) { return -1; }
int ps_prescribed_jac(double t, const double *z, const double *p, double *p_jac, const double *rack, double *J)
{ return -1; }
static int prescribed_tangent(double t, const double *z, const double *p, const double *rack, int m,
                              const double *dz, const double *const *dps, double *dzdot, double *dtorque,
                              double *dy, double *dG, double *dH)
{ return -1; }
"""


@pytest.fixture(scope="module")
def compile_problem(tmp_path_factory):
    """compile_problem(name, n_y, body[, prescribed]) -> Problem: integrator.c compiled after a preamble defining the
    problem (and the prescribed-rack system: stubs by default)."""
    directory = tmp_path_factory.mktemp("c_integrator")

    def build(name: str, n_y: int, body: str, prescribed: str = PRESCRIBED_STUBS) -> Problem:
        preamble = (f"#include <math.h>\n#include <string.h>\n{PORTABLE_MATH_C.read_text(encoding='utf-8')}\n"
                    f"#define NY {n_y}\n#define NQ (NY / 2)\n#define PS_HOT\n{body}\n" + prescribed)
        source = directory / f"{name}.c"
        source.write_text(preamble + INTEGRATOR_C.read_text(encoding="utf-8"), encoding="utf-8")
        library = directory / f"{name}.so"
        subprocess.run(["cc", "-O2", "-std=c99", "-shared", "-fPIC",
                        "-o", str(library), str(source), "-lm"], check=True, capture_output=True)
        return Problem(ctypes.CDLL(str(library)), n_y)

    return build


# y' = A y in the model's layout, positions then velocities (NQ = 2): q'' + (K + I) q' + K q = 0 with K symmetric,
# eigenvalues 10 and 1e4, so each mode k of K gives the eigenvalues -1 and -k of A: -1 (twice), -10, -1e4.
# Once c = h / alpha exceeds 1e-4, the LU of (I - c A) needs row exchanges in more than one column.
STIFF_RATE = 1e4
ROTATION = 0.3
STIFFNESS = (np.array([[np.cos(ROTATION), -np.sin(ROTATION)], [np.sin(ROTATION), np.cos(ROTATION)]])
             @ np.diag([10.0, STIFF_RATE])
             @ np.array([[np.cos(ROTATION), np.sin(ROTATION)], [-np.sin(ROTATION), np.cos(ROTATION)]]))
LINEAR_A = np.block([[np.zeros((2, 2)), np.eye(2)], [-STIFFNESS, -(STIFFNESS + np.eye(2))]])
LINEAR = ("static const double A[16] = {" + ", ".join(repr(float(a)) for a in LINEAR_A.ravel()) + "};\n" + """
int ps_rhs(double t, const double *y, const double *p, double *ydot)
{
    for (int i = 0; i < 4; i++) ydot[i] = A[4 * i] * y[0] + A[4 * i + 1] * y[1] + A[4 * i + 2] * y[2] + A[4 * i + 3] * y[3];
    return 0;
}
int ps_jac(double t, const double *y, const double *p, double *J)
{
    memcpy(J, A, sizeof A);
    return 0;
}
""")


def linear_exact(t, y0):
    """y(t) = exp(A t) y0."""
    return np.array([expm(LINEAR_A * tk) @ y0 for tk in t])


LINEAR_Y0 = np.array([1.0, -0.5, 0.0, 0.0])
# outputs through the fast transient (time constant 1e-4) and the slow decay
LINEAR_T = np.concatenate([np.linspace(0.0, 5e-4, 11), np.linspace(1e-3, 10.0, 200)])


@pytest.fixture(scope="module")
def linear(compile_problem):
    return compile_problem("linear", 4, LINEAR)


def test_linear_stiff_system_within_tolerance(linear):
    """y' = A y with eigenvalues -1, -10 and -1e4 (stiffness ratio 1e4): at every output, through the fast transient
    and the slow decay, the error against the closed form is within a small multiple of the error weight
    rtol |y| + atol, and the stiff mode does not force explicit-sized steps (far fewer than 10 s / 1e-4 s)."""
    rtol, atol = 1e-6, 1e-9
    code, y, stats = linear.integrate(LINEAR_Y0, LINEAR_T, rtol, atol)
    assert code == OK
    exact = linear_exact(LINEAR_T, LINEAR_Y0)
    weighted = np.abs(y - exact) / (rtol * np.abs(exact) + atol)
    assert weighted.max() < 20.0  # a multistep method's global error: about 9 here
    assert stats[0] < 2000


def test_error_falls_with_rtol(linear):
    """Convergence: on the linear stiff system, tightening rtol (atol in proportion) from 1e-4 to 1e-8 makes the
    largest error at the outputs at least 100 times smaller, and each tighter tolerance gives a smaller error."""
    errors = []
    for rtol in (1e-4, 1e-6, 1e-8):
        code, y, _ = linear.integrate(LINEAR_Y0, LINEAR_T, rtol, 1e-3 * rtol)
        assert code == OK
        errors.append(np.max(np.abs(y - linear_exact(LINEAR_T, LINEAR_Y0))))
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < errors[0] / 100.0


ROBERTSON = """
int ps_rhs(double t, const double *y, const double *p, double *ydot)
{
    ydot[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
    ydot[1] = 0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] * y[1];
    ydot[2] = 3e7 * y[1] * y[1];
    return 0;
}
int ps_jac(double t, const double *y, const double *p, double *J)
{
    J[0] = -0.04;  J[1] = 1e4 * y[2];                 J[2] = 1e4 * y[1];
    J[3] = 0.04;   J[4] = -1e4 * y[2] - 6e7 * y[1];   J[5] = -1e4 * y[1];
    J[6] = 0.0;    J[7] = 6e7 * y[1];                 J[8] = 0.0;
    return 0;
}
"""


def test_robertson_matches_radau_reference(compile_problem):
    """Robertson's chemical kinetics (rate constants 0.04, 1e4, 3e7; eigenvalues down to about -1e4, an
    intermediate y2 of order 1e-5): against scipy's Radau at rtol 1e-10, every output over 0..1e3 s
    (log-spaced) is within a small multiple of the error weight, and the three concentrations still sum to 1
    (the scheme conserves linear invariants)."""
    robertson = compile_problem("robertson", 3, ROBERTSON)
    y0 = np.array([1.0, 0.0, 0.0])
    t = np.concatenate([[0.0], np.logspace(-5, 3, 41)])
    rtol, atol = 1e-6, np.array([1e-10, 1e-14, 1e-10])

    def rhs(_, y):
        return [-0.04 * y[0] + 1e4 * y[1] * y[2], 0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] ** 2,
                3e7 * y[1] ** 2]

    def jac(_, y):
        return [[-0.04, 1e4 * y[2], 1e4 * y[1]], [0.04, -1e4 * y[2] - 6e7 * y[1], -1e4 * y[1]],
                [0.0, 6e7 * y[1], 0.0]]

    reference = solve_ivp(rhs, (t[0], t[-1]), y0, method="Radau", t_eval=t, rtol=1e-10, atol=atol * 1e-4,
                          jac=jac).y.T
    code, y, stats = robertson.integrate(y0, t, rtol, atol)
    assert code == OK
    weighted = np.abs(y - reference) / (rtol * np.abs(reference) + atol)
    assert weighted.max() < 20.0
    assert np.max(np.abs(y.sum(axis=1) - 1.0)) < 1e-12
    assert stats[0] < 1000


# Scalar problems in one library, chosen by p[0]:
#   KINK: y' = max(0, t - 1) written piecewise, with a spy (was ps_rhs called beyond t = 1 before at 1?);
#   FAILS_AFTER_START / NAN_AFTER_START: y' = -y, but ps_rhs fails or returns NaN anywhere but at t = 0;
#   JACOBIAN_FAILS: y' = -y with a ps_jac that always fails; BLOW_UP: y' = y^2 (y = 1 / (1 - t) from y(0) = 1).
KINK, FAILS_AFTER_START, NAN_AFTER_START, JACOBIAN_FAILS, BLOW_UP = range(5)
SCALAR = """
enum { KINK, FAILS_AFTER_START, NAN_AFTER_START, JACOBIAN_FAILS, BLOW_UP };
static int reached_one, evaluated_beyond_one_first;
void reset_spy(void) { reached_one = 0; evaluated_beyond_one_first = 0; }
int spy_reached_one(void) { return reached_one; }
int spy_crossed_one(void) { return evaluated_beyond_one_first; }
int ps_rhs(double t, const double *y, const double *p, double *ydot)
{
    switch ((int)p[0]) {
    case KINK:
        if (t == 1.0) reached_one = 1;
        if (t > 1.0 && !reached_one) evaluated_beyond_one_first = 1;
        ydot[0] = t <= 1.0 ? 0.0 : t - 1.0;
        return 0;
    case FAILS_AFTER_START: ydot[0] = -y[0]; return t > 0.0;  /* "mass matrix not positive definite" */
    case NAN_AFTER_START: ydot[0] = t > 0.0 ? NAN : -y[0]; return 0;
    case BLOW_UP: ydot[0] = y[0] * y[0]; return 0;
    default: ydot[0] = -y[0]; return 0;
    }
}
int ps_jac(double t, const double *y, const double *p, double *J)
{
    switch ((int)p[0]) {
    case KINK: J[0] = 0.0; return 0;
    case JACOBIAN_FAILS: J[0] = -1.0; return 1;
    case BLOW_UP: J[0] = 2.0 * y[0]; return 0;
    default: J[0] = -1.0; return 0;
    }
}
"""


@pytest.fixture(scope="module")
def scalar(compile_problem):
    return compile_problem("scalar", 1, SCALAR)


def test_step_stops_at_t_crit(scalar):
    """A right-hand side whose time derivative jumps at t = 1 (y' = max(0, t - 1), so y = (t - 1)^2 / 2 after
    1): with t_crit = [1] the integration arrives at exactly t = 1 before evaluating anything beyond it and
    matches the closed form to within the tolerance; without t_crit it does evaluate beyond 1 first (so the
    spy is able to see a crossing)."""
    reset, reached, crossed = scalar.function("reset_spy", None), scalar.function("spy_reached_one"), \
        scalar.function("spy_crossed_one")
    t = np.linspace(0.0, 3.0, 31)
    exact = 0.5 * np.maximum(0.0, t - 1.0) ** 2
    rtol, atol = 1e-8, 1e-10

    reset()
    code, y, _ = scalar.integrate([0.0], t, rtol, atol, t_crit=[1.0], p=[KINK])
    assert code == OK
    assert reached() == 1 and crossed() == 0
    assert np.max(np.abs(y[:, 0] - exact) / (rtol * exact + atol)) < 10.0

    reset()
    code, _, _ = scalar.integrate([0.0], t, rtol, atol, p=[KINK])
    assert code == OK
    assert crossed() == 1


def test_t_crit_outside_the_run_and_at_its_ends_is_harmless(linear):
    """Corners before the start, at the start, at the end or after it change nothing: the run ends at the last
    output with the same accuracy (no zero-length steps or restarts that fail)."""
    rtol, atol = 1e-6, 1e-9
    code, y, stats = linear.integrate(LINEAR_Y0, LINEAR_T, rtol, atol,
                                      t_crit=[-1.0, 0.0, 10.0 - 1e-15, 10.0, 11.0])
    assert code == OK and stats[3] == LINEAR_T[-1]
    exact = linear_exact(LINEAR_T, LINEAR_Y0)
    assert np.max(np.abs(y - exact) / (rtol * np.abs(exact) + atol)) < 20.0


@pytest.mark.parametrize("mode", [FAILS_AFTER_START, NAN_AFTER_START, JACOBIAN_FAILS])
def test_failed_evaluations_return_3(scalar, mode):
    """A right-hand side that reports failure (nonzero) or returns NaN beyond the start, or a Jacobian that
    always fails, ends the run with code 3 at the start time (no step can succeed, halving does not help)
    after a bounded number of calls, with the first output row set to y0."""
    code, y, stats = scalar.integrate([1.0], [0.0, 1.0], 1e-6, 1e-9, p=[mode])
    assert code == EVALUATION_FAILED
    assert stats[3] == 0.0 and stats[0] == 0
    assert stats[1] < 50
    assert y[0, 0] == 1.0


def test_step_budget_returns_1(linear):
    """max_steps bounds the attempts between two outputs: with 3 allowed, the run stops with code 1 before the
    first output after the start, having taken at most 3 steps."""
    code, _, stats = linear.integrate(LINEAR_Y0, [0.0, 10.0], 1e-6, 1e-9, max_steps=3)
    assert code == BUDGET_EXCEEDED
    assert 0 < stats[3] < 10.0
    assert stats[0] <= 3


def test_blow_up_returns_2(scalar):
    """y' = y^2, y(0) = 1 (y = 1 / (1 - t)) has no solution past t = 1: asked for t = 2, the step size collapses
    and the run stops with code 2 just short of t = 1, where y is huge."""
    code, _, stats = scalar.integrate([1.0], [0.0, 2.0], 1e-6, 1e-9, max_steps=1_000_000, p=[BLOW_UP])
    assert code == STEP_TOO_SMALL
    assert 0.999 < stats[3] < 1.0


def test_stats_are_plausible(linear):
    """stats = steps, rhs calls, Jacobian calls, last time: a successful run ends at the last output, and the
    output rows are filled, the first one with y0 unchanged. The problem is linear, so with its (constant)
    Jacobian each Newton iteration is exact: a step costs two right-hand sides (the correction and the check
    that it converged) and the one Jacobian of the start is never re-evaluated. Both fail if the LU solve with
    row exchanges (needed here) is wrong."""
    code, y, stats = linear.integrate(LINEAR_Y0, LINEAR_T, 1e-6, 1e-9)
    steps, rhs_calls, jac_calls, t_last = stats
    assert code == OK
    assert t_last == LINEAR_T[-1]
    assert 10 < steps < rhs_calls <= 2.2 * steps
    assert jac_calls == 1
    assert np.all(np.isfinite(y)) and np.array_equal(y[0], LINEAR_Y0)


def test_the_nominal_cycle_matches_an_independent_converged_integration(params):
    """On the model itself: the nominal 18 s cycle integrated by ps_integrate at the project's tolerances
    (simulate.integrate) gives the handwheel torque of scipy's LSODA (odeint, an independent stiff integrator)
    run to convergence (rtol 1e-11, a ten-thousandth of the absolute tolerances) within 0.002 N m, the band the
    project's tolerances promise (tolerances.RTOL; measured 0.0004 N m)."""
    from scipy.integrate import odeint

    from parksteer.model.numeric.simulate import _atol, integrate, prepare, static_state

    run = prepare("unladen", params=params)
    model, p = run.model, run.p
    t = np.round(np.arange(0.0, run.profile.end_time_s + 0.005, 0.01), 12)
    states = integrate(run, t)
    corners = np.array([piece[0] for piece in run.profile.pieces])
    reference = odeint(lambda y, s: model.rhs(s, y, p), static_state(run), t,
                       Dfun=lambda y, s: model.jacobian(s, y, p), rtol=1e-11, atol=_atol(model) * 1e-4,
                       mxstep=200_000, tcrit=corners)
    torque = model.evaluate_outputs(t, states, p)["column_torque_Nm"]
    reference_torque = model.evaluate_outputs(t, reference, p)["column_torque_Nm"]
    assert np.max(np.abs(torque - reference_torque)) < 0.002


# A prescribed system with known sensitivities (NY = 4, so 2 NO = 2 reduced states): z_i' = -p_i z_i, whose
# derivative by p_j is dz_i/dp_j = -t z_i(0) exp(-p_i t) for i = j and 0 otherwise.
SENSITIVITY_PROBLEM = """
#define NO (NQ - 1)
#define INPUT_OFFSET 2
#define PS_SENSITIVITIES 1
int ps_prescribed_rhs(double t, const double *z, const double *p, const double *rack, double *zdot)
{ zdot[0] = -p[0] * z[0]; zdot[1] = -p[1] * z[1]; return 0; }
int ps_prescribed_jac(double t, const double *z, const double *p, double *p_jac, const double *rack, double *J)
{ J[0] = -p[0]; J[1] = 0.0; J[2] = 0.0; J[3] = -p[1]; return 0; }
static int prescribed_tangent(double t, const double *z, const double *p, const double *rack, int m,
                              const double *dz, const double *const *dps, double *dzdot, double *dtorque,
                              double *dy, double *dG, double *dH)
{
    for (int k = 0; k < m; k++)
        for (int i = 0; i < 2; i++) dzdot[2 * k + i] = -p[i] * dz[2 * k + i] - dps[k][i] * z[i];
    return 0;
}
"""


def test_sensitivities_of_exponential_decay_are_the_closed_form(compile_problem):
    """Closed form: for z_i' = -p_i z_i the staggered NDF sensitivities are dz_i/dp_i = -t z_i(0) exp(-p_i t) (and
    zero across), to the integrator's tolerance (rtol 1e-10: within 1e-7 of the largest value, for rates 2 and
    50 /s); the state with sensitivities is the state without, byte for byte."""
    problem = compile_problem("decay", 4, "int ps_rhs(double t, const double *y, const double *p, double *ydot) "
                              "{ return -1; }\nint ps_jac(double t, const double *y, const double *p, double *J) "
                              "{ return -1; }", SENSITIVITY_PROBLEM)
    lib = problem.lib
    vp, i32 = ctypes.c_void_p, ctypes.c_int
    lib.ps_integrate_prescribed_sens.restype = i32
    lib.ps_integrate_prescribed_sens.argtypes = [vp, vp, vp, vp, i32, vp, i32, vp, ctypes.c_double, vp,
                                                 ctypes.c_long, vp, vp, i32, vp, vp, vp]
    lib.ps_integrate_prescribed.restype = i32
    lib.ps_integrate_prescribed.argtypes = [vp, vp, vp, vp, i32, vp, i32, vp, ctypes.c_double, vp, ctypes.c_long,
                                            vp, vp]
    p = np.array([2.0, 50.0])
    z0, t = np.array([1.0, 0.5]), np.linspace(0.0, 2.0, 401)
    directions, s0 = np.eye(2), np.zeros((2, 2))
    atol = np.full(2, 1e-14)
    states, plain, sens, stats = np.empty((401, 2)), np.empty((401, 2)), np.empty((401, 2, 2)), np.zeros(4)
    none, rack = ctypes.c_void_p(), np.zeros(1)  # a rack table the system does not read: it selects the path
    assert lib.ps_integrate_prescribed_sens(p.ctypes.data, none, rack.ctypes.data, z0.ctypes.data, 401, t.ctypes.data, 0, none,
                                            1e-10, atol.ctypes.data, 100000, states.ctypes.data,
                                            stats.ctypes.data, 2, directions.ctypes.data, s0.ctypes.data,
                                            sens.ctypes.data) == 0
    assert lib.ps_integrate_prescribed(p.ctypes.data, none, rack.ctypes.data, z0.ctypes.data, 401, t.ctypes.data, 0, none,
                                       1e-10, atol.ctypes.data, 100000, plain.ctypes.data, stats.ctypes.data) == 0
    assert np.array_equal(states, plain)
    for j in range(2):
        expected = np.zeros((401, 2))
        expected[:, j] = -t * z0[j] * np.exp(-p[j] * t)
        error = np.max(np.abs(sens[:, j, :] - expected)) / np.max(np.abs(expected))
        assert error <= 1e-7, error
