"""Static equilibrium of the compiled model: the state both drives start from."""

from __future__ import annotations

import numpy as np

from ... import portable as pm


def static_state(run, fixed: dict[str, float] | None = None, t_s: float = 0.0, p: np.ndarray | None = None
                 ) -> np.ndarray:
    """The static equilibrium (u = 0) at the handwheel input of time `t_s`, with `fixed` coordinates held.

    `run` is a :class:`parksteer.model.numeric.simulate.PreparedRun`; `p` a parameter vector of its
    model (default: the run's own). Newton's method on f(q) = 0 with the generated df/dq.
    """
    model = run.model
    p = run.p if p is None else p
    n = model.n_q
    fixed = fixed or {}
    free = np.array([i for i, name in enumerate(model.coordinates) if name not in fixed], dtype=int)
    free_block = np.ix_(free, free)
    y = np.zeros(2 * n)
    for name, value in fixed.items():
        y[model.index(name)] = value
    for _ in range(50):
        residual = model.forcing(t_s, y, p)[free]
        jac = model.forcing_dq(t_s, y, p)[free_block]
        # least squares: a coordinate with neither stiffness nor load (an effect at strength 0) stays put
        step = pm.lstsq(jac, -residual)
        y[free] += step
        if np.abs(step).max() < 1e-14:
            break
    return y
