"""Forward sensitivities of the prescribed-rack solve: the handwheel torque and its derivatives with respect to
chosen parameters, from one integration.

Beside the reduced state z (the coordinates other than the rack, and their speeds), the compiled integrator carries
S = dz/dp . v for each parameter direction v (``ps_integrate_prescribed_sens``: the staggered direct method on the
same steps, the sensitivity equations S' = J S + f_p v derived by sympy from the same expressions as the model,
``eval_tangent``, which the model's second library holds: :attr:`.compiled.CompiledModel.with_tangent`); the
torque's derivative is h_z S + h_p v at each output (``ps_prescribed_torque_sens``). The state starts from the
static equilibrium with the rack held, so S starts from that equilibrium's derivative, dq_o/dp = -(df/dq_o)^-1 df/dp
(the implicit function theorem on the statics' equations). The steps, and so every
byte of the torque, are those of :func:`parksteer.model.numeric.prescribed.solve`. The method: docs/model.md,
"Forward sensitivities".

Scope: the manual car's torque (no handwheel twist, no named outputs); an assisted model, whose drive depends on
the torsion bar's torque, is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ... import portable as pm
from ...errors import UsageError
from .prescribed import PRESCRIBED_ATOL_FACTOR, PRESCRIBED_RTOL, RackMotion, prescribed_start, rack_corners
from .tolerances import integrator_failure, max_steps

# The directions one integration carries (the compiled integrator's BDF_MAX_SENS); more are integrated in batches.
MAX_DIRECTIONS = 16


@dataclass
class SensitivitySolution:
    """The handwheel torque (N m) at the output times and its derivative along each parameter direction:
    ``torque_sensitivities[i, k]`` is d torque(t_i) / dp . v_k (N m per unit of the direction)."""

    time_s: np.ndarray
    torque_Nm: np.ndarray
    torque_sensitivities: np.ndarray


def parameter_directions(run, keys: list[str]) -> np.ndarray:
    """Unit directions of the parameters `keys` in the parameter vector of `run` (a PreparedRun): one row each,
    so that the sensitivities are the partial derivatives by each key's value."""
    directions = np.zeros((len(keys), len(run.model.info["parameters"])))
    for k, key in enumerate(keys):
        directions[k, run.parameter_index(key)] = 1.0
    return directions


def initial_sensitivities(run, p: np.ndarray, y_static: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """dz0/dp . v for each direction (rows: the reduced state, other coordinates then their zero speeds): the
    derivative of the static equilibrium with the rack held, whose free rows f(q) = 0 the statics solve by least
    squares (:func:`parksteer.model.numeric.statics.static_state`, at the handwheel input of time 0)."""
    model = run.model
    n = model.n_q
    others = [i for i in range(n) if i != model.index("rack")]
    m = len(directions)
    dF = np.empty((m, n))
    if model.with_tangent.lib.ps_forcing_tangent(0.0, y_static.ctypes.data, p.ctypes.data, m,
                                                 directions.ctypes.data, dF.ctypes.data):
        raise UsageError(f"the model of {', '.join(model.effects)} has no sensitivities")
    dFdq = model.forcing_dq(0.0, y_static, p)[np.ix_(others, others)]
    dq = pm.lstsq(dFdq, -dF[:, others].T)  # (others x m)
    return np.ascontiguousarray(np.concatenate([dq.T, np.zeros((m, len(others)))], axis=1))


def solve_sensitivities(run, p: np.ndarray, rack: RackMotion, t_out, directions: np.ndarray,
                        rtol: float = PRESCRIBED_RTOL, atol_factor: float = PRESCRIBED_ATOL_FACTOR
                        ) -> SensitivitySolution:
    """The prescribed-rack solve of :func:`parksteer.model.numeric.prescribed.solve` (the same arguments; its
    torque to the byte) with the torque's derivatives along `directions` (rows of the parameter vector's length,
    e.g. :func:`parameter_directions`)."""
    model = run.model
    if not model.info.get("rack_drive", True):  # the generated C has sensitivities exactly where the rack drives
        raise UsageError(f"no sensitivities of the effects {', '.join(model.effects)}: an assist feeds the "
                         "torsion-bar torque back into the load, and its replay is not the prescribed-rack solve")
    n_par = len(model.info["parameters"])
    directions = np.ascontiguousarray(np.atleast_2d(np.asarray(directions, dtype=float)))
    if directions.shape[1] != n_par or len(directions) == 0:
        raise ValueError(f"sensitivity directions: need rows of {n_par} parameters")
    begin = prescribed_start(run, p, rack, t_out, atol_factor)  # solve's start, so solve's steps
    t_out, p, table, p_jac, atol = begin.t_out, begin.p, begin.table, begin.p_jac, begin.atol
    lib, n_z, z0, y_static = model.with_tangent.lib, 2 * len(begin.others), begin.z0, begin.y_static
    corners = np.ascontiguousarray(rack_corners(rack, t_out[0], t_out[-1]))
    m = len(t_out)
    torque = np.empty(m)
    sensitivities = np.empty((m, len(directions)))
    for start in range(0, len(directions), MAX_DIRECTIONS):
        batch = np.ascontiguousarray(directions[start:start + MAX_DIRECTIONS])
        k = len(batch)
        s0 = initial_sensitivities(run, p, y_static, batch)
        states, s_out, stats = np.empty((m, n_z)), np.empty((m, k, n_z)), np.zeros(4)
        code = lib.ps_integrate_prescribed_sens(
            p.ctypes.data, p_jac.ctypes.data, table.ctypes.data, z0.ctypes.data, m, t_out.ctypes.data, len(corners),
            corners.ctypes.data, float(rtol), atol.ctypes.data, max_steps(t_out), states.ctypes.data,
            stats.ctypes.data, k, batch.ctypes.data, s0.ctypes.data, s_out.ctypes.data)
        if code != 0:
            raise integrator_failure("prescribed-rack integration with sensitivities", code, float(stats[3]))
        full, accs = np.empty((m, 2 * model.n_q)), np.empty((m, model.n_q))
        if start == 0 and lib.ps_prescribed_samples(m, t_out.ctypes.data, states.ctypes.data, p.ctypes.data, table.ctypes.data,
                                     full.ctypes.data, accs.ctypes.data, torque.ctypes.data):
            raise FloatingPointError("prescribed rack: the equations for the accelerations and torque are singular")
        out = np.empty((m, k))  # every batch takes the same steps: the torque is the first batch's
        if lib.ps_prescribed_torque_sens(m, t_out.ctypes.data, states.ctypes.data, s_out.ctypes.data,
                                         p.ctypes.data, table.ctypes.data, k, batch.ctypes.data, out.ctypes.data):
            raise FloatingPointError("prescribed rack: the torque's sensitivities are singular")
        sensitivities[:, start:start + k] = out
    return SensitivitySolution(t_out, torque, sensitivities)
