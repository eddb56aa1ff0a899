"""The prescribed-rack solve: the model driven by a given rack motion, the handwheel torque solved for.

With the rack's position, speed and acceleration given at every instant (any :class:`RackMotion`: a
measured rack smoothed by :func:`parksteer.measure.smoothing.smooth_rack`, or a spline through
samples), the rack is not a state. The other coordinates are integrated while each step solves the
Kane equations ``M a = F + b T`` for their accelerations and the column torque T together, with the
rack's acceleration given. The column twist (handwheel minus column angle) does not feed back on T;
when outputs are asked for it follows from ``c dtwist/dt + k twist = T``, integrated exactly for a
torque linear between samples at most ``TWIST_SAMPLE_S`` apart, from the static twist at the start.

Speed: the integrator (LSODA via odeint, which loops in Fortran) gets an analytic Jacobian of the
reduced system from the compiled model's full one. With ``h = M^-1 b``, the reduced accelerations of
the other coordinates are ``a_o + h_o dT``, with ``dT`` fixed by the rack's acceleration;
differentiating gives ``d a_o/dy = J_o - (h_o / h_rack) J_rack``, where J is the full model's
Jacobian evaluated with a handwheel input that makes its column torque equal the prescribed-rack
torque (the column law's own dependence on the state cancels between the two terms, whatever the
law: a linear spring, or the dead band of the rack lash candidate, whose twist is widened by the
torque it would not pass). An 18 s replay takes a few hundredths of a second.
"""

from __future__ import annotations

import warnings

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.integrate import ODEintWarning, odeint

from .statics import static_state
from .tolerances import PRESCRIBED_ATOL_FACTOR, PRESCRIBED_RTOL, absolute_tolerances, max_steps, solver_failure

# The column twist is integrated exactly for a torque linear between samples this far apart at most (s).
# Against the column's time constant c / k (0.2 s) the twist filters the torque; at 5 ms the handwheel angle
# of a prescribed free-simulation rack is within 1e-5 rad of the free simulation's, reversals included.
TWIST_SAMPLE_S = 0.005
# The integrator's first step, s: from rest, well inside the first output interval of any record.
FIRST_STEP_S = 1e-4

try:  # the kernel of np.linalg.solve for one right-hand side, without its checks (a third of each step's cost)
    from numpy.linalg._umath_linalg import solve1 as _kernel

    def _solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """np.linalg.solve(a, b) for a square float matrix and a vector: the same LAPACK call, the same numbers."""
        return _kernel(a, b, signature="dd->d")
except ImportError:  # a numpy that keeps it elsewhere
    _solve = np.linalg.solve


class RackMotion(Protocol):
    """A rack motion: ``scalar()`` gives t (s) -> (position m, speed m/s, acceleration m/s^2)."""

    @property
    def start_s(self) -> float: ...

    @property
    def end_s(self) -> float: ...

    def scalar(self) -> Callable[[float], tuple[float, float, float]]: ...


@dataclass
class PrescribedSolution:
    """The solve at the output times: the handwheel torque, and with outputs also the states and the model's outputs.

    ``outputs`` holds the compiled model's named outputs (``column_torque_Nm`` is the solved
    torque); ``handwheel`` the handwheel angle (rad) and rate (rad/s), column angle plus twist.
    """

    time_s: np.ndarray
    torque_Nm: np.ndarray
    states: np.ndarray | None = None
    accelerations: np.ndarray | None = None
    handwheel: np.ndarray | None = None
    outputs: dict[str, np.ndarray] | None = None


def solve(run, p: np.ndarray, rack: RackMotion, t_out, rtol: float = PRESCRIBED_RTOL,
          atol_factor: float = PRESCRIBED_ATOL_FACTOR, outputs: bool = False) -> PrescribedSolution:
    """Solve the model of `run` (a PreparedRun) with parameter vector `p`, the rack following `rack`.

    The run starts from static equilibrium with the rack at its position at ``t_out[0]``;
    `t_out` (s, strictly increasing) are the output times. Tolerances: relative `rtol`, absolute
    `atol_factor` times the model's own (:mod:`parksteer.model.numeric.tolerances`).
    """
    model = run.model
    lib = model.lib
    n = model.n_q
    i_rack = model.index("rack")
    others = np.array([i for i in range(n) if i != i_rack], dtype=int)
    speeds = others + n
    n_o = len(others)
    drive = rack.scalar()
    t_out = np.asarray(t_out, dtype=float)
    if t_out.ndim != 1 or len(t_out) < 2 or np.any(np.diff(t_out) <= 0):
        raise ValueError("output times must be at least two, strictly increasing")
    p = np.ascontiguousarray(p, dtype=float)

    y = np.zeros(2 * n)
    M, F, b = np.zeros((n, n)), np.zeros(n), np.zeros(n)
    A = np.zeros((n, n))
    zdot = np.zeros(2 * n_o)
    y_ptr, p_ptr, M_ptr, F_ptr, b_ptr = (a.ctypes.data for a in (y, p, M, F, b))

    def accelerations(t: float, z: np.ndarray) -> tuple[np.ndarray, float]:
        """(accelerations of the other coordinates then the column torque, rack acceleration)."""
        r, rd, rdd = drive(t)
        y[others] = z[:n_o]
        y[speeds] = z[n_o:]
        y[i_rack] = r
        y[n + i_rack] = rd
        lib.ps_drive(y_ptr, p_ptr, M_ptr, F_ptr, b_ptr)
        A[:, :n_o] = M[:, others]
        A[:, n_o] = -b
        return _solve(A, F - M[:, i_rack] * rdd), rdd

    def rhs(z, t):
        x, _ = accelerations(t, z)
        zdot[:n_o] = z[n_o:]
        zdot[n_o:] = x[:n_o]
        return zdot

    # Jacobian: the full model's, at a constant handwheel input that gives the prescribed-rack torque
    # through a unit column spring without damping (see the module docstring).
    n_par = len(model.info["parameters"])
    p_jac = p.copy()
    p_jac[run.parameter_index("steering.column_torsional_stiffness")] = 1.0
    p_jac[run.parameter_index("steering.column_torsional_damping")] = 0.0
    p_jac[n_par:] = 0.0
    p_jac[n_par] = 1.0  # one piece: (start time, angle, rate, acceleration)
    p_jac[n_par + 1] = -1.0e9
    p_jac_ptr = p_jac.ctypes.data
    J_full = np.zeros((2 * n, 2 * n))
    J = np.zeros((2 * n_o, 2 * n_o))
    J[np.arange(n_o), n_o + np.arange(n_o)] = 1.0
    reduced = np.concatenate([others, speeds])
    acc = np.zeros(n)
    hw = np.zeros(2)
    t_one = np.zeros(1)
    out_one = np.zeros(len(model.outputs))
    i_column = model.outputs.index("column_angle_rad")
    i_torque = model.outputs.index("column_torque_Nm")

    def jacobian(z, t):
        x, rdd = accelerations(t, z)
        acc[others] = x[:n_o]
        acc[i_rack] = rdd
        t_one[0] = t
        hw[0] = 0.0
        lib.ps_outputs(1, t_one.ctypes.data, y_ptr, acc.ctypes.data, hw.ctypes.data, p_jac_ptr, out_one.ctypes.data)
        hw[0] = out_one[i_column] + x[n_o]  # angle = column angle + torque / (unit stiffness)
        # A column law with a dead band (rack lash) passes less torque for that twist: widen it by the shortfall,
        # so that the Jacobian is the exact one whatever the column law.
        lib.ps_outputs(1, t_one.ctypes.data, y_ptr, acc.ctypes.data, hw.ctypes.data, p_jac_ptr, out_one.ctypes.data)
        p_jac[n_par + 2] = hw[0] + x[n_o] - out_one[i_torque]
        if lib.ps_jac(float(t), y_ptr, p_jac_ptr, J_full.ctypes.data):
            raise FloatingPointError("mass matrix not positive definite")
        h = _solve(M, b)
        J[n_o:] = J_full[n + others][:, reduced] - np.outer(h[others] / h[i_rack], J_full[n + i_rack][reduced])
        return J

    units = model.info["coordinate_units"]
    atol = absolute_tolerances([units[i] for i in others], atol_factor)
    y_static = static_state(run, fixed={"rack": drive(float(t_out[0]))[0]}, p=p)
    z0 = np.concatenate([y_static[others], np.zeros(n_o)])
    # LSODA interpolates at the output times without stepping to them; with its first step fixed (it would
    # otherwise choose it from the first output interval) the refined grid of the twist changes no step.
    grid, at_out = _refined(t_out, TWIST_SAMPLE_S) if outputs else (t_out, np.arange(len(t_out)))
    with warnings.catch_warnings():  # a failure is reported below as one line, not as a warning too
        warnings.simplefilter("ignore", ODEintWarning)
        states, info = odeint(rhs, z0, grid, Dfun=jacobian, rtol=rtol, atol=atol, mxstep=max_steps(grid), full_output=True,
                              h0=FIRST_STEP_S)
    if info["message"] != "Integration successful.":
        raise solver_failure("prescribed-rack integration", info, grid)

    # The accelerations and the torque at every sample, solved together (the same equations as `accelerations`).
    m = len(grid)
    full = np.zeros((m, 2 * n))
    full[:, others], full[:, speeds] = states[:, :n_o], states[:, n_o:]
    rack_states = np.array([drive(float(t)) for t in grid])
    full[:, i_rack], full[:, n + i_rack] = rack_states[:, 0], rack_states[:, 1]
    Ms, Fs, bs = np.empty((m, n, n)), np.empty((m, n)), np.empty((m, n))
    for k in range(m):
        lib.ps_drive(full[k].ctypes.data, p_ptr, Ms[k].ctypes.data, Fs[k].ctypes.data, bs[k].ctypes.data)
    system = np.concatenate([Ms[:, :, others], -bs[:, :, None]], axis=2)
    x = np.linalg.solve(system, (Fs - Ms[:, :, i_rack] * rack_states[:, 2:3])[:, :, None])[:, :, 0]
    torque = x[:, n_o]
    accs = np.zeros((m, n))
    accs[:, others], accs[:, i_rack] = x[:, :n_o], rack_states[:, 2]
    if not outputs:
        return PrescribedSolution(t_out, torque)

    k_col = p[run.parameter_index("steering.column_torsional_stiffness")]
    c_col = p[run.parameter_index("steering.column_torsional_damping")]
    twist, twist_rate = column_twist(grid, torque, k_col, c_col)
    full, accs, torque, twist, twist_rate = (a[at_out] for a in (full, accs, torque, twist, twist_rate))
    column = model.evaluate_outputs(t_out, full, p, accs, np.zeros((len(t_out), 2)))
    handwheel = np.column_stack([column["column_angle_rad"] + twist,
                                 column["column_angle_per_rack_rad_per_m"] * full[:, n + i_rack] + twist_rate])
    named = model.evaluate_outputs(t_out, full, p, accs, handwheel)
    # The solved torque: rebuilt from the handwheel through the linear column law, it would be wrong under a
    # column deflection (ModelSpace.set_column_deflection, e.g. lash).
    named["column_torque_Nm"] = torque
    return PrescribedSolution(t_out, torque, full, accs, handwheel, named)


def column_twist(t: np.ndarray, torque: np.ndarray, stiffness: float, damping: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Twist (rad) and twist rate (rad/s) of the column from ``c dtwist/dt + k twist = T``, from rest at T(t[0]) / k.

    Exact for a torque linear between the samples `t`. Without damping the twist is T / k.
    """
    if damping <= 0.0:
        twist = torque / stiffness
        return twist, np.gradient(twist, t)
    tau = damping / stiffness
    h = np.diff(t)
    decay = np.exp(-h / tau)
    slope = np.diff(torque) / h
    # x(t0 + h) = T1/k - tau s/k + (x0 - T0/k + tau s/k) e^(-h/tau), s the torque's slope over the interval
    twist = np.empty(len(t))
    twist[0] = torque[0] / stiffness
    for k in range(len(h)):
        lag = tau * slope[k] / stiffness
        twist[k + 1] = torque[k + 1] / stiffness - lag + (twist[k] - torque[k] / stiffness + lag) * decay[k]
    return twist, (torque - stiffness * twist) / damping


def _refined(t_out: np.ndarray, max_step: float) -> tuple[np.ndarray, np.ndarray]:
    """`t_out` with each interval split into equal steps of at most `max_step`; and where `t_out` sits in it."""
    pieces = np.maximum(np.ceil(np.diff(t_out) / max_step - 1e-9).astype(int), 1)
    at_out = np.concatenate([[0], np.cumsum(pieces)])
    grid = np.empty(at_out[-1] + 1)
    for k, m in enumerate(pieces):
        grid[at_out[k] : at_out[k + 1]] = t_out[k] + (t_out[k + 1] - t_out[k]) * np.arange(m) / m
    grid[-1] = t_out[-1]
    return grid, at_out
