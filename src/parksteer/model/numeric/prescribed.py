"""The prescribed-rack solve: the model driven by a given rack motion, the handwheel torque solved for.

With the rack's position (m), speed and acceleration given at every instant (any :class:`RackMotion`: a measured
rack smoothed by :func:`parksteer.measure.smoothing.smooth_rack`, or a spline through samples), the other
coordinates are integrated while each step solves the Kane equations ``M a = F + b T`` for their accelerations and
the column torque T (N m) together. The column twist follows from T for the outputs, under the linear column law or
a column deflection law (:class:`ColumnLaw`, ``ModelSpace.set_column_deflection``), integrated exactly for a torque
linear between samples at most ``TWIST_SAMPLE_S`` apart. The whole solve is one call of the compiled model's stiff
integrator (``ps_integrate_prescribed``) with an analytic reduced Jacobian; no step calls back into Python. The
reduction and its Jacobian: docs/model.md, "The prescribed-rack solve".
"""

from __future__ import annotations

import warnings

from bisect import bisect_right
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ...errors import UsageError
from ...geometry import column_twist
from .statics import static_state
from .tolerances import (PRESCRIBED_ATOL_FACTOR, PRESCRIBED_RTOL, absolute_tolerances, integrator_failure,
                         max_steps)

# The column twist is integrated exactly for a torque linear between samples this far apart at most (s).
# Against the column's time constant c / k (0.2 s) the twist filters the torque; at 5 ms the handwheel angle
# of a prescribed free-simulation rack is within 1e-5 rad of the free simulation's, reversals included.
TWIST_SAMPLE_S = 0.005
# The twist through a column deflection law (ColumnLaw.twist) is integrated to these tolerances: a dead band's
# smoothed corners are 1e-3 rad wide (rack_lash.smoothing_width at the handwheel), the twist is wanted well inside.
TWIST_RTOL = 1e-8
TWIST_ATOL_RAD = 1e-10
# Spacing of the table of a deflection law (ColumnLaw.table), rad: 1/90 of a dead band's smoothed corner.
TWIST_TABLE_RAD = 2e-5
# A break of the rack's pieces where its position, speed or acceleration jumps by more than this fraction of the
# largest value of each over the pieces is a corner of the input: the integrator stops and restarts there.
CORNER_TOLERANCE = 1e-9

class RackMotion(Protocol):
    """A rack motion as a piecewise polynomial in time: position (m) on each piece between ``breaks`` (s,
    increasing), ``coefficients`` highest power first, one column per piece (as :class:`scipy.interpolate.PPoly`);
    held at its end values outside the breaks. Its speed and acceleration are the polynomial's derivatives."""

    @property
    def breaks(self) -> np.ndarray: ...

    @property
    def coefficients(self) -> np.ndarray: ...

    @property
    def start_s(self) -> float: ...

    @property
    def end_s(self) -> float: ...


def rack_table(rack: RackMotion) -> np.ndarray:
    """`rack` as the compiled model's rack table: pieces, order, breaks, then the coefficients row by row."""
    breaks = np.asarray(rack.breaks, dtype=float)
    coefficients = np.asarray(rack.coefficients, dtype=float)
    if breaks.ndim != 1 or coefficients.shape[1:] != (len(breaks) - 1,) or len(breaks) < 2:
        raise ValueError("rack motion: needs breaks (m + 1) and coefficients (order x m)")
    return np.concatenate([[len(breaks) - 1, len(coefficients)], breaks, coefficients.ravel()])


def rack_corners(rack: RackMotion, t_start: float, t_end: float) -> np.ndarray:
    """The corners of `rack` strictly between `t_start` and `t_end` (s): its start and end, where it is held, and
    every break where its position, speed or acceleration jumps (by more than ``CORNER_TOLERANCE`` of the largest
    value of each over the pieces; a cubic spline's pieces join with none)."""
    breaks = np.asarray(rack.breaks, dtype=float)
    c = np.asarray(rack.coefficients, dtype=float)
    order = len(c)
    h = np.diff(breaks)
    jumps = np.zeros(len(breaks) - 2, dtype=bool)
    for derivative in range(min(3, order)):
        # the derivative's polynomial on each piece, highest power first: its value at the piece's start (the
        # constant term) and at its end
        d = c[: order - derivative] * np.array([np.prod(np.arange(k - derivative + 1, k + 1))
                                                for k in range(order - 1, derivative - 1, -1)])[:, None]
        at_start = d[-1]
        at_end = np.zeros(len(h))
        for row in d:
            at_end = at_end * h + row
        scale = max(float(np.max(np.abs(at_start))), float(np.max(np.abs(at_end))), np.finfo(float).tiny)
        jumps |= np.abs(at_start[1:] - at_end[:-1]) > CORNER_TOLERANCE * scale
    corners = np.concatenate([[rack.start_s, rack.end_s], breaks[1:-1][jumps]])
    return np.unique(corners[(corners > t_start) & (corners < t_end)])


def jacobian_parameters(run, p: np.ndarray) -> np.ndarray:
    """The parameter vector ``ps_prescribed_jac`` takes with `p`: the Jacobian is the full model's at a constant
    handwheel input that gives the prescribed-rack torque through a unit column spring without damping (see the
    module docstring), so a unit stiffness, no damping and one input piece (count, then start time, angle, rate,
    acceleration), whose angle each call sets."""
    n_par = len(run.model.info["parameters"])
    p_jac = np.array(p, dtype=float)
    p_jac[run.parameter_index("steering.column_torsional_stiffness")] = 1.0
    p_jac[run.parameter_index("steering.column_torsional_damping")] = 0.0
    p_jac[n_par:] = 0.0
    p_jac[n_par] = 1.0
    p_jac[n_par + 1] = -1.0e9
    return p_jac


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


@dataclass
class PrescribedStart:
    """What a prescribed-rack integration starts from (:func:`prescribed_start`): the checked output times and
    parameter vector, the rack's table, the Jacobian's parameter vector, the reduced state's absolute tolerances,
    the coordinates other than the rack, the static equilibrium and the reduced state there."""

    t_out: np.ndarray
    p: np.ndarray
    table: np.ndarray
    p_jac: np.ndarray
    atol: np.ndarray
    others: np.ndarray
    y_static: np.ndarray
    z0: np.ndarray


def prescribed_start(run, p: np.ndarray, rack: RackMotion, t_out, atol_factor: float) -> PrescribedStart:
    """The start of :func:`solve` and of the solve with sensitivities
    (:func:`parksteer.model.numeric.sensitivities.solve_sensitivities`): the same start, so the same steps."""
    model = run.model
    i_rack = model.index("rack")
    others = np.array([i for i in range(model.n_q) if i != i_rack], dtype=int)
    t_out = np.ascontiguousarray(t_out, dtype=float)  # read by the compiled model: a strided view would not do
    if t_out.ndim != 1 or len(t_out) < 2 or np.any(np.diff(t_out) <= 0):
        raise ValueError("output times must be at least two, strictly increasing")
    p = np.ascontiguousarray(p, dtype=float)
    table = rack_table(rack)
    p_jac = jacobian_parameters(run, p)
    units = model.info["coordinate_units"]
    atol = np.ascontiguousarray(absolute_tolerances([units[i] for i in others], atol_factor))
    rack_start = np.zeros(3)
    model.lib.ps_rack(float(t_out[0]), table.ctypes.data, rack_start.ctypes.data)
    y_static = static_state(run, fixed={"rack": rack_start[0]}, p=p)
    z0 = np.ascontiguousarray(np.concatenate([y_static[others], np.zeros(len(others))]))
    return PrescribedStart(t_out, p, table, p_jac, atol, others, y_static, z0)


def solve(run, p: np.ndarray, rack: RackMotion, t_out, rtol: float = PRESCRIBED_RTOL,
          atol_factor: float = PRESCRIBED_ATOL_FACTOR, outputs: bool = False,
          assist_off: bool = False, handwheel: bool = True) -> PrescribedSolution:
    """Solve the model of `run` (a PreparedRun) with parameter vector `p`, the rack following `rack`.

    The run starts from static equilibrium with the rack at its position at ``t_out[0]``;
    `t_out` (s, strictly increasing) are the output times. Tolerances: relative `rtol`, absolute
    `atol_factor` times the model's own (:mod:`parksteer.model.numeric.tolerances`). `assist_off`: the caller has
    switched an assist's boost off in `p` (its gain 0), so that no force depends on the column torque and the
    drive, written at zero handwheel input, is exact (:mod:`.assisted` solves an assisted car so). With `outputs`
    and not `handwheel`, the named outputs are the linkage's alone, taken at zero handwheel twist: the column's
    twist, an integration of its own through a deflection law, is not made (a caller that needs only the
    kinematics, such as the column angle per rack, pays for none of it).
    """
    model = run.model
    if not model.info.get("rack_drive", True) and not assist_off:
        raise UsageError(f"a prescribed rack cannot drive the effects {', '.join(model.effects)}: an assist feeds the "
                         "torsion-bar torque back into the load, so drive it by the handwheel angle")
    lib = model.lib
    n = model.n_q
    i_rack = model.index("rack")
    start = prescribed_start(run, p, rack, t_out, atol_factor)
    t_out, p, table, p_jac, atol, others = start.t_out, start.p, start.table, start.p_jac, start.atol, start.others
    n_o, z0 = len(others), start.z0
    p_ptr, table_ptr = p.ctypes.data, table.ctypes.data
    # The integrator interpolates at the output times without stepping to them, so the refined grid of the
    # twist changes no step.
    grid, at_out = _refined(t_out, TWIST_SAMPLE_S) if outputs and handwheel else (t_out, np.arange(len(t_out)))
    corners = np.ascontiguousarray(rack_corners(rack, grid[0], grid[-1]))
    states = np.empty((len(grid), 2 * n_o))
    stats = np.zeros(4)
    code = lib.ps_integrate_prescribed(p_ptr, p_jac.ctypes.data, table_ptr, z0.ctypes.data, len(grid),
                                       grid.ctypes.data, len(corners), corners.ctypes.data, float(rtol),
                                       atol.ctypes.data, max_steps(grid), states.ctypes.data, stats.ctypes.data)
    if code != 0:
        raise integrator_failure("prescribed-rack integration", code, float(stats[3]))

    # The states, accelerations and torque at every sample, solved together (the same equations as the rhs).
    m = len(grid)
    full, accs, torque = np.empty((m, 2 * n)), np.empty((m, n)), np.empty(m)
    if lib.ps_prescribed_samples(m, grid.ctypes.data, states.ctypes.data, p_ptr, table_ptr, full.ctypes.data,
                                 accs.ctypes.data, torque.ctypes.data):
        raise FloatingPointError("prescribed rack: the equations for the accelerations and torque are singular")
    if not outputs:
        return PrescribedSolution(t_out, torque)
    if not handwheel:
        full, accs, torque = (a[at_out] for a in (full, accs, torque))
        named = model.evaluate_outputs(t_out, full, p, accs, np.zeros((len(t_out), 2)))
        return PrescribedSolution(t_out, torque, full, accs, None, named)

    i_k = run.parameter_index("steering.column_torsional_stiffness")
    i_c = run.parameter_index("steering.column_torsional_damping")
    twist, twist_rate = column_twist(grid, torque, p[i_k], p[i_c])
    torque_grid = torque
    full, accs, torque, twist, twist_rate = (a[at_out] for a in (full, accs, torque, twist, twist_rate))
    column = model.evaluate_outputs(t_out, full, p, accs, np.zeros((len(t_out), 2)))
    column_rate = column["column_angle_per_rack_rad_per_m"] * full[:, n + i_rack]
    if any(e.replaces == "column_deflection" for e in run.effects):
        # The spring and damper act on the deflection g(twist): what column_twist gave is the deflection that
        # passes the torque; the twist is the one whose deflection that is (a dead band widens it by +-band).
        law = ColumnLaw(model, p, i_k, i_c, t_out[0], full[0], accs[0], column["column_angle_rad"][0], column_rate[0])
        twist, twist_rate = (a[at_out] for a in law.twist(grid, torque_grid, p[i_k], p[i_c]))
    handwheel = np.column_stack([column["column_angle_rad"] + twist, column_rate + twist_rate])
    named = model.evaluate_outputs(t_out, full, p, accs, handwheel)
    # The solved torque: rebuilt from the handwheel through the linear column law, it would be wrong under a
    # column deflection (ModelSpace.set_column_deflection, e.g. lash).
    named["column_torque_Nm"] = torque
    return PrescribedSolution(t_out, torque, full, accs, handwheel, named)


class ColumnLaw:
    """A column's deflection law g(twist), read from the compiled model's column torque.

    The column torque is ``(k g + c g' dtwist/dt) g'`` (``ModelSpace.set_column_deflection``; ``g(x) = x`` for the
    paper's linear column). With k = 1 and c = 0 the model's torque output is ``g g'``; with k = 0, c = 1 and a
    unit twist rate it is ``g'^2``: so g and g' follow at any twist, whatever the law, without its formula. The
    slot's law is a function of the twist alone (``(model, twist) -> g``), so one state of the run serves.
    """

    def __init__(self, model, p, i_stiffness, i_damping, t, state, acceleration, column_angle, column_rate):
        self.model, self.t, self.state, self.acceleration = model, float(t), state, acceleration
        self.column_angle, self.column_rate = float(column_angle), float(column_rate)
        self.p_spring, self.p_damper = p.copy(), p.copy()
        self.p_spring[i_stiffness], self.p_spring[i_damping] = 1.0, 0.0
        self.p_damper[i_stiffness], self.p_damper[i_damping] = 0.0, 1.0
        self.calls = 0

    def _torque(self, p, twist: np.ndarray, rate: float) -> np.ndarray:
        m = len(twist)
        handwheel = np.column_stack([self.column_angle + twist, np.full(m, self.column_rate + rate)])
        self.calls += 1
        return self.model.evaluate_outputs(np.full(m, self.t), np.broadcast_to(self.state, (m, len(self.state))), p,
                                           np.broadcast_to(self.acceleration, (m, len(self.acceleration))),
                                           handwheel)["column_torque_Nm"]

    def deflection(self, twist) -> tuple[np.ndarray, np.ndarray]:
        """(g, g') at `twist` (an array)."""
        twist = np.atleast_1d(np.asarray(twist, dtype=float))
        slope = np.sqrt(np.maximum(self._torque(self.p_damper, twist, 1.0), 1e-300))
        return self._torque(self.p_spring, twist, 0.0) / slope, slope

    def inverse(self, deflection, tolerance: float = 1e-13, max_iterations: int = 200) -> np.ndarray:
        """The twist whose deflection is `deflection` (g is increasing).

        Newton's method kept inside a bracket (bisection where a step would leave it): in a dead band g' is
        nearly zero and a plain Newton step overshoots.
        """
        d = np.atleast_1d(np.asarray(deflection, dtype=float))
        width = np.full(d.shape, 1e-3)
        low, high = d - width, d + width
        for _ in range(60):  # widen the brackets until they hold the root
            out_low, out_high = self.deflection(low)[0] > d, self.deflection(high)[0] < d
            if not (out_low.any() or out_high.any()):
                break
            width *= 2.0
            low = np.where(out_low, low - width, low)
            high = np.where(out_high, high + width, high)
        else:
            raise FloatingPointError("column deflection law: no twist gives the deflection")
        x = np.clip(d, low, high)
        for _ in range(max_iterations):
            g, slope = self.deflection(x)
            error = g - d
            low, high = np.where(error < 0, x, low), np.where(error > 0, x, high)
            if np.all(np.abs(error) <= tolerance) or np.all(high - low <= tolerance):
                break
            newton = x - error / slope
            x = np.where((newton > low) & (newton < high), newton, 0.5 * (low + high))
        return x

    def table(self, low: float, high: float) -> Callable[[float], tuple[float, float]]:
        """x -> (g, g') on [low, high] by cubic Hermite interpolation of g and g' tabulated every TWIST_TABLE_RAD
        (exact at the nodes; between them within 1e-12 rad for corners 1e-3 rad wide), evaluated directly outside."""
        m = int(np.ceil((high - low) / TWIST_TABLE_RAD)) + 1
        nodes = low + TWIST_TABLE_RAD * np.arange(m)
        g_nodes, slope_nodes = (a.tolist() for a in self.deflection(nodes))
        h, last = TWIST_TABLE_RAD, m - 2

        def law(x: float) -> tuple[float, float]:
            u = (x - low) / h
            k = int(u)
            if u < 0.0 or k > last:
                g, slope = self.deflection(x)
                return float(g[0]), float(slope[0])
            s = u - k
            g0, g1, d0, d1 = g_nodes[k], g_nodes[k + 1], slope_nodes[k] * h, slope_nodes[k + 1] * h
            s2, s3 = s * s, s * s * s
            g = (2 * s3 - 3 * s2 + 1) * g0 + (s3 - 2 * s2 + s) * d0 + (-2 * s3 + 3 * s2) * g1 + (s3 - s2) * d1
            slope = ((6 * s2 - 6 * s) * g0 + (3 * s2 - 4 * s + 1) * d0 + (-6 * s2 + 6 * s) * g1 + (3 * s2 - 2 * s) * d1) / h
            return g, slope

        return law

    def twist(self, t: np.ndarray, torque: np.ndarray, stiffness: float, damping: float
              ) -> tuple[np.ndarray, np.ndarray]:
        """Twist (rad) and twist rate (rad/s) passing `torque` (linear between the samples `t`), from rest.

        ``(k g + c g' dx/dt) g' = T``, i.e. ``dx/dt = (T - k g g') / (c g'^2)``: in a dead band g' is nearly zero,
        the twist crosses the band as fast as the torque lets it, and the equation is stiff there (LSODA, which
        switches to a stiff method). It starts from the twist whose deflection passes T(t[0]) statically.
        Without damping the twist is the one whose deflection is T / k (g' = 1 outside a band's corners).
        """
        if damping <= 0.0:
            x = self.inverse(torque / stiffness)
            return x, np.gradient(x, t)
        ends = self.inverse(np.array([torque.min(), torque.max(), torque[0]]) / stiffness)
        margin = 0.5 * (ends[1] - ends[0]) + 0.01
        law = self.table(ends[0] - margin, ends[1] + margin)
        torque_list, time_list = torque.tolist(), t.tolist()
        slope_T = (np.diff(torque) / np.diff(t)).tolist()
        last = len(t) - 2

        def rate(x, time):
            k = min(max(bisect_right(time_list, time) - 1, 0), last)
            g, slope = law(float(x[0]))
            return (torque_list[k] + slope_T[k] * (time - time_list[k]) - stiffness * g * slope) / (damping * slope * slope)

        from scipy.integrate import ODEintWarning, odeint  # only a column deflection law's twist needs it

        from .tolerances import solver_failure

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ODEintWarning)
            x, info = odeint(rate, ends[2:], t, rtol=TWIST_RTOL, atol=TWIST_ATOL_RAD, mxstep=200000, full_output=True)
        if info["message"] != "Integration successful.":
            raise solver_failure("column twist through its deflection law", info, t)
        x = x[:, 0]
        g, slope = self.deflection(x)
        return x, (torque - stiffness * g * slope) / (damping * slope * slope)


def twist_spread(run, p: np.ndarray, solution: PrescribedSolution, torque_error: np.ndarray) -> np.ndarray:
    """How far the twist that passes the solved torque moves if that torque is off by `torque_error` (N m, per
    sample): half the distance between the static twists passing T - error and T + error.

    For the paper's linear column that is error / k. Under a deflection law it is (g^-1((T + e) / k) -
    g^-1((T - e) / k)) / 2: on an engaged flank the same, and where |T| is within the error of zero, a dead band's
    whole width, since a torque that small does not say which flank the hand holds (`solution` with outputs)."""
    i_k = run.parameter_index("steering.column_torsional_stiffness")
    stiffness = p[i_k]
    torque_error = np.asarray(torque_error, dtype=float)
    if not any(e.replaces == "column_deflection" for e in run.effects):
        return torque_error / stiffness
    model = run.model
    i_rack = model.index("rack")
    column = solution.outputs["column_angle_rad"]
    rate = solution.outputs["column_angle_per_rack_rad_per_m"] * solution.states[:, model.n_q + i_rack]
    law = ColumnLaw(model, p, i_k, run.parameter_index("steering.column_torsional_damping"), solution.time_s[0],
                    solution.states[0], solution.accelerations[0], column[0], rate[0])
    torque = solution.torque_Nm
    return 0.5 * (law.inverse((torque + torque_error) / stiffness) - law.inverse((torque - torque_error) / stiffness))


def _refined(t_out: np.ndarray, max_step: float) -> tuple[np.ndarray, np.ndarray]:
    """`t_out` with each interval split into equal steps of at most `max_step`; and where `t_out` sits in it."""
    pieces = np.maximum(np.ceil(np.diff(t_out) / max_step - 1e-9).astype(int), 1)
    at_out = np.concatenate([[0], np.cumsum(pieces)])
    grid = np.empty(at_out[-1] + 1)
    for k, m in enumerate(pieces):
        grid[at_out[k] : at_out[k + 1]] = t_out[k] + (t_out[k + 1] - t_out[k]) * np.arange(m) / m
    grid[-1] = t_out[-1]
    return grid, at_out
