"""Kane's equations (the generated C) against an independent Lagrange derivation."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

from parksteer.model.symbolic.components import resolve_effects
from parksteer.model.symbolic.derive import build_space
from parksteer.model.numeric.simulate import prepare


@pytest.mark.slow  # builds a model of its own: started early, so that the workers end together
def test_kane_agrees_with_lagrange_at_random_states(params):
    """The compiled Kane equations (mass matrix and accelerations) equal those of sympy's LagrangesMethod applied
    to the same bodies and loads (kinetic energy differentiated, generalized forces from partial velocities with
    respect to dq/dt) at random states across the operating range, with every effect on."""
    effects = resolve_effects(None)
    run = prepare("unladen", effects=effects, params=params)
    model, p = run.model, run.p
    space = build_space(effects, speeds_as_qdot=True)
    values = {space.parameter_symbols[k]: v for k, v in zip(model.info["parameters"], p)}
    th, thd = sp.symbols("th thd")
    values[space.handwheel_angle], values[space.handwheel_rate] = th, thd
    loads = space.core_loads() + space.column_loads()
    for effect in effects:
        loads += effect.loads(space)
    loads = [(where, vector.xreplace(values)) for where, vector in loads]
    lagrangian = space.kinetic_energy().xreplace(values)
    method = me.LagrangesMethod(lagrangian, space.q, forcelist=loads, frame=space.N)
    method.form_lagranges_equations()
    n = len(space.q)
    qs, qds = sp.symbols(f"q0:{n}"), sp.symbols(f"qd0:{n}")
    plain = {**dict(zip([q.diff(space.t) for q in space.q], qds)), **dict(zip(space.q, qs))}
    mass = sp.lambdify([qs, qds, th, thd], method.mass_matrix.xreplace(values).xreplace(plain), "numpy")
    forcing = sp.lambdify([qs, qds, th, thd], method.forcing.xreplace(values).xreplace(plain), "numpy")

    rng = np.random.default_rng(7)
    scale_q = {"rack": 0.06, "bounce": 2e-3, "roll": 2e-3, "twist_left": 0.2, "twist_right": 0.2}
    scale_u = {"rack": 0.03, "bounce": 0.01, "roll": 0.02, "twist_left": 0.5, "twist_right": 0.5}
    for _ in range(4):
        q = np.array([scale_q[c] * rng.uniform(-1, 1) for c in model.coordinates])
        u = np.array([scale_u[c] * rng.uniform(-1, 1) for c in model.coordinates])
        t = rng.uniform(0.0, 18.0)
        hw = model.handwheel(t, p)
        y = np.concatenate([q, u])
        M_kane, _, _ = model.drive_parts(y, p)
        M_lagrange = np.array(mass(q, u, *hw), dtype=float)
        np.testing.assert_allclose(M_kane, M_lagrange, rtol=1e-9, atol=1e-9 * np.max(np.abs(M_lagrange)))
        a_kane = model.rhs(t, y, p)[n:]
        a_lagrange = np.linalg.solve(M_lagrange, np.array(forcing(q, u, *hw), dtype=float).ravel())
        np.testing.assert_allclose(a_kane, a_lagrange, rtol=1e-7, atol=1e-9 * np.max(np.abs(a_lagrange)))
