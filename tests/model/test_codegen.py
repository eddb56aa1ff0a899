"""The generated C against sympy and against finite differences."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from parksteer.model.symbolic.components import resolve_effects
from parksteer.model.symbolic.derive import derive
from parksteer.model.numeric.simulate import prepare


def _random_states(model, rng, count):
    scale_q = {"rack": 0.06, "bounce": 2e-3, "roll": 2e-3, "twist_left": 0.2, "twist_right": 0.2}
    scale_u = {"rack": 0.03, "bounce": 0.01, "roll": 0.02, "twist_left": 0.05, "twist_right": 0.05}
    for _ in range(count):
        q = [scale_q.get(c, 1e-3) * rng.uniform(-1, 1) for c in model.coordinates]
        u = [scale_u.get(c, 1e-2) * rng.uniform(-1, 1) for c in model.coordinates]
        yield rng.uniform(0, 18), np.array(q + u)


def test_compiled_right_hand_side_equals_sympy_equations(params):
    """The C right-hand side (after cse and printing) equals M^-1 f evaluated directly from the sympy mass matrix
    and forcing of the derivation (lambdified), at random states."""
    effects = resolve_effects(None)
    run = prepare("unladen", effects=effects, params=params)
    derivation = derive(effects)
    space = derivation.space
    plain = derivation.plain_symbols()
    q_syms = [plain[q] for q in space.q]
    u_syms = [plain[u] for u in space.u]
    p_syms = [space.parameter_symbols[k] for k in run.model.info["parameters"]]
    args = [q_syms, u_syms, p_syms, space.handwheel_angle, space.handwheel_rate]
    mass = sp.lambdify(args, derivation.mass_matrix.xreplace(plain), "numpy")
    forcing = sp.lambdify(args, derivation.forcing.xreplace(plain), "numpy")
    n = run.model.n_q
    p_model = run.p[: len(p_syms)]
    for t, y in _random_states(run.model, np.random.default_rng(3), 5):
        hw = run.model.handwheel(t, run.p)
        a = np.linalg.solve(mass(y[:n], y[n:], p_model, *hw), np.ravel(forcing(y[:n], y[n:], p_model, *hw)))
        np.testing.assert_allclose(run.model.rhs(t, y, run.p)[n:], a, rtol=1e-9, atol=1e-9 * np.max(np.abs(a)))


# The default model, and effects whose laws bring conditions (braked wheels), an extra state (pre-sliding
# friction) or a second linkage geometry (Ackermann) into the chain rule through the common subexpressions.
@pytest.mark.parametrize("effects", [None, "+braked_wheels", "+rack_presliding", "+ackermann"])
def test_analytic_jacobian_equals_finite_differences(params, effects):
    """The generated Jacobian d(u, M^-1 f)/d(q, u) matches central differences of the compiled right-hand side."""
    run = prepare("unladen", effects=effects, params=params)
    model, p = run.model, run.p
    for t, y in _random_states(model, np.random.default_rng(5), 4):
        jac = model.jacobian(t, y, p)
        numeric = np.empty_like(jac)
        for j in range(len(y)):
            h = 1e-6 * max(abs(y[j]), 1e-3)
            up, down = y.copy(), y.copy()
            up[j] += h
            down[j] -= h
            numeric[:, j] = (model.rhs(t, up, p) - model.rhs(t, down, p)) / (2 * h)
        scale = np.max(np.abs(numeric), axis=1, keepdims=True) + 1e-12
        assert np.max(np.abs(jac - numeric) / scale) < 1e-5


def test_the_short_derivative_route_gives_sympys_derivative_exactly():
    """The chain-rule Jacobian differentiates through a memoised short route to Expr.diff (the generated C, and so
    every model figure's last bits, must not change): for the functions the models use (products, powers, square
    roots, |x| and its sign, atan2, tanh, a piecewise law), in either form sympy calls it (`x`, `(x, 1)`,
    `(x, 0)`), it returns the very expression sympy's Derivative does, and sympy's own route is back afterwards
    (after the outermost of nested uses)."""
    from sympy.core.expr import Expr

    from parksteer.model.symbolic.derive import memoised_diff

    x, y = sp.symbols("x y", real=True)
    exprs = [x * y ** 2 * sp.sin(x), sp.sqrt(x ** 2 + y ** 2), sp.Abs(x) * sp.tanh(3 * x / y), sp.atan2(y, x),
             sp.Piecewise((x ** 2, x > y), (sp.exp(-x), True)), 1 / (x * sp.cos(y) + 2), sp.Integer(3) * y]
    expected = [[e.diff(s) for s in (x, y)] + [e.diff((x, 1)), e.diff((y, 0))] for e in exprs]
    original = Expr.diff
    with memoised_diff():
        assert Expr.diff is not original
        found = [[e.diff(s) for s in (x, y)] + [e.diff((x, 1)), e.diff((y, 0))] for e in exprs]
        again = [sp.diff(e, x) for e in exprs]  # a second time: from the memo
        with memoised_diff():  # nested: the outer one's route stays until the outer one ends
            patched = Expr.diff
        assert Expr.diff is patched is not original
    assert Expr.diff is original
    for want, got in zip(expected, found):
        assert [sp.srepr(w) for w in want] == [sp.srepr(g) for g in got]
    assert [sp.srepr(g[0]) for g in found] == [sp.srepr(a) for a in again]


def test_partial_velocities_are_sympys():
    """A generalized force takes each load point's partial velocity with respect to every speed; the short route
    (no direction cosine matrix differentiated when it holds no speed: an orientation depends on the
    coordinates only) gives Vector.diff's very vector for every load of the default model."""
    from parksteer.model.symbolic.derive import build_space, partial_velocity
    import sympy.physics.mechanics as me

    space = build_space(resolve_effects(None))
    loads = space.core_loads() + space.column_loads()
    assert loads
    for where, _ in loads:
        velocity = where.ang_vel_in(space.N) if isinstance(where, me.ReferenceFrame) else where.vel(space.N)
        for speed in space.u:
            short, full = partial_velocity(velocity, speed, space.N), velocity.diff(speed, space.N)
            assert [(sp.srepr(m), f) for m, f in short.args] == [(sp.srepr(m), f) for m, f in full.args]
