"""The generated C against sympy and against finite differences."""

from __future__ import annotations

import contextlib

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

    import sympy.physics.mechanics as me

    x, y = sp.symbols("x y", real=True)
    q, u = me.dynamicsymbols("q u", real=True)
    g = sp.Function("g")
    exprs = [x * y ** 2 * sp.sin(x), sp.sqrt(x ** 2 + y ** 2), sp.Abs(x) * sp.tanh(3 * x / y), sp.atan2(y, x),
             sp.Piecewise((x ** 2, x > y), (sp.exp(-x), True)), 1 / (x * sp.cos(y) + 2), sp.Integer(3) * y,
             x * g(x, y) ** 2]  # the last one's derivative holds an unevaluated Derivative of g
    dynamic = [u * sp.cos(q) * x + q ** 2 * y, sp.sqrt(1 + u ** 2) * sp.sin(q), y]  # by a coordinate, a speed
    expected = [[e.diff(s) for s in (x, y)] + [e.diff((x, 1)), e.diff((y, 0))] for e in exprs]
    expected_dynamic = [[e.diff(s) for s in (q, u)] for e in dynamic]
    original = Expr.diff
    with memoised_diff():
        assert Expr.diff is not original
        found = [[e.diff(s) for s in (x, y)] + [e.diff((x, 1)), e.diff((y, 0))] for e in exprs]
        found_dynamic = [[e.diff(s) for s in (q, u)] for e in dynamic]
        again = [sp.diff(e, x) for e in exprs]  # a second time: from the memo
        assert [[sp.srepr(e.diff(s)) for s in (q, u)] for e in dynamic] == [[sp.srepr(d) for d in row]
                                                                            for row in found_dynamic]
        with memoised_diff():  # nested: the outer one's route stays until the outer one ends
            patched = Expr.diff
        assert Expr.diff is patched is not original
    assert Expr.diff is original
    for want, got in zip(expected + expected_dynamic, found + found_dynamic):
        assert [sp.srepr(w) for w in want] == [sp.srepr(g) for g in got]
    assert [sp.srepr(g[0]) for g in found] == [sp.srepr(a) for a in again]


def test_partial_velocities_and_their_dot_products_are_sympys():
    """A generalized force is the sum over loads of each load point's partial velocity with respect to a speed,
    dotted with the load; the short routes (no direction cosine matrix differentiated when it holds no speed: an
    orientation depends on the coordinates only; measure numbers differentiated entry by entry, memoised; the dot
    product without sympy's multiplications by zero) give Vector.diff's very vector and Vector.dot's very
    expression for every load of a model with friction, lash and braked wheels, within memoised_diff (as the
    derivation runs them) and outside it; a vector holding an infinity takes Vector.dot (0 * oo is nan)."""
    from parksteer.model.symbolic.derive import build_space, dot, memoised_diff, partial_velocity
    import sympy.physics.mechanics as me

    effects = resolve_effects("+braked_wheels,+kingpin_friction,+rack_lash")
    space = build_space(effects)
    loads = space.core_loads() + space.column_loads() + [load for e in effects for load in e.loads(space)]
    assert len(loads) > 10
    for memoised in (False, True):
        with memoised_diff() if memoised else contextlib.nullcontext():
            for where, load in loads:
                velocity = where.ang_vel_in(space.N) if isinstance(where, me.ReferenceFrame) else where.vel(space.N)
                for speed in space.u:
                    short, full = partial_velocity(velocity, speed, space.N), velocity.diff(speed, space.N)
                    assert [(sp.srepr(m), f) for m, f in short.args] == [(sp.srepr(m), f) for m, f in full.args]
                    assert sp.srepr(dot(short, load)) == sp.srepr(full.dot(load))
    x = sp.Symbol("x", real=True)
    A = space.N.orientnew("A", "Axis", (x, space.N.z))
    infinite, finite = sp.oo * space.N.x + x * space.N.y, x * A.y
    assert sp.srepr(dot(infinite, finite)) == sp.srepr(infinite.dot(finite))
    assert sp.srepr(dot(finite, x * A.x + space.N.z)) == sp.srepr(finite.dot(x * A.x + space.N.z))


def test_the_memoised_replacement_is_xreplaces():
    """Code generation writes every expression in C symbols through one memoised Replacer (the matrices and outputs
    share their kinematic terms): it gives xreplace's very expressions for the mass matrix, the forcing and the
    energies of the default model, and for a rule that sets symbols to 0 (the drive at zero handwheel input)."""
    from parksteer.model.symbolic.derive import Replacer

    derivation = derive(resolve_effects(None))
    plain = derivation.plain_symbols()
    for i, name in enumerate(derivation.parameter_names):
        plain[derivation.space.parameter_symbols[name]] = sp.Symbol(f"p[{i}]", real=True)
    replace = Replacer(plain)
    exprs = [derivation.mass_matrix, derivation.forcing, derivation.forcing_inertia, derivation.potential_energy,
             derivation.space.kinetic_energy()]
    for expr in exprs:
        assert sp.srepr(replace(expr)) == sp.srepr(expr.xreplace(plain))
    column = derivation.space.kinematics.column_torque
    zero_hand = {derivation.space.handwheel_angle: 0, derivation.space.handwheel_rate: 0}
    assert sp.srepr(Replacer(zero_hand)(column)) == sp.srepr(column.xreplace(zero_hand))
    assert Replacer(zero_hand)(column) != column
