"""Replay a measured rack motion through the model: smoothing the rack, then a fast rack-driven solve.

Why smooth: the rack of an 8-bit logger moves in steps of 2 full_scale / 255 (0.8 mm for a
+-0.1 m range). Replayed as it stands, every step is a jump in position, so the rack's
speed and acceleration (which the prescribed-rack model differentiates) are spikes, and
the rack friction's tanh flips at every step: the replayed torque is then wrong by several
N m. The rack is therefore replaced by a least-squares cubic spline (:func:`smooth_rack`)
with evenly spaced knots and one knot at each reversal. The spacing is the largest that
still fits the rack to within its own noise (estimated, as for the torque, from second
differences; the discrepancy principle), inside a range the cycle sets: closer knots follow
the noise, and the spline's speed then crosses zero where the rack never reverses, which
flips the rack friction; wider ones cannot follow the hand through a reversal. Each end of
the record is held at rest unless the data contradict it, so that a record starting from
rest gets no spurious starting speed.

What smoothing cannot fix: near a reversal the rack speed passes through zero, and the rack
friction force, F tanh(beta v), turns over within about 1 mm/s of it (a few hundredths of a
second). The rack data fix the turning time only to a few hundredths of a second, so the
replay is least certain there. :meth:`SmoothedRack.relogged` and :meth:`SmoothedRack.perturbed`
give other racks the data allow as well; :mod:`parksteer.diagnose.problem` replays them to
measure that uncertainty at every sample.

The solve (:class:`Replay`): with the rack prescribed, the other coordinates are
integrated while the column torque is found at each instant from the Kane equations,
``M a = F + b T`` with the rack's acceleration given (the same equations as
:func:`parksteer.model.numeric.simulate.simulate` with ``rack_drive``). This module adds speed,
not physics: the spline is evaluated from its coefficients, the column twist (which does
not feed back on the torque) is left out, and the integrator (LSODA via odeint) gets an
analytic Jacobian of the reduced system from the compiled model's full one. With ``h =
M^-1 b``, the reduced accelerations of the other coordinates are ``a_o + h_o dT``, with
``dT`` fixed by the rack's acceleration; differentiating gives ``d a_o/dy = J_o - (h_o /
h_rack) J_rack``, where J is the full model's Jacobian evaluated with a handwheel input
that makes its column torque equal the prescribed-rack torque (the column stiffness's own
dependence on the state cancels between the two terms; with a column dead band, as the
rack lash candidate makes, the Jacobian is only approximate, which slows the integrator's
Newton iterations but does not change the result). An 18 s replay takes a few hundredths
of a second instead of several seconds.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import odeint
from scipy.interpolate import BSpline, PPoly

from ..errors import UsageError
from ..measure.metrics import estimate_noise_rms
from ..model.symbolic.components import Effect
from ..model.numeric.simulate import ATOL_Q, ATOL_U, PreparedRun, prepare, static_state
from ..parameters import Parameters
from . import settings



# ------------------------------------------------------------------------------------ smoothing
@dataclass(frozen=True, eq=False)
class SmoothedRack:
    """A rack motion as a cubic spline: position, speed and acceleration at any time within the record.

    ``knots`` and ``bspline`` are the least-squares B-spline; ``coefficient_covariance`` is the
    covariance of its coefficients for white rack noise of RMS ``noise_rms_m`` (for
    :meth:`perturbed`).
    """

    knots: np.ndarray
    bspline: np.ndarray
    coefficient_covariance: np.ndarray
    knot_spacing_s: float
    fit_rms_m: float
    noise_rms_m: float
    held_at_rest: tuple[bool, bool] = (False, False)  # (start, end) of the record
    turning_times_s: tuple[float, ...] = ()  # where the rack reverses (each has a knot)

    def __post_init__(self):
        pp = PPoly.from_spline(BSpline(self.knots, self.bspline, 3, extrapolate=False))
        keep = np.diff(pp.x) > 0.0  # from_spline repeats the end knots as empty pieces
        object.__setattr__(self, "_breaks", np.concatenate([pp.x[:-1][keep], [pp.x[-1]]]))
        object.__setattr__(self, "_coefficients", pp.c[:, keep])

    @property
    def start_s(self) -> float:
        return float(self._breaks[0])

    @property
    def end_s(self) -> float:
        return float(self._breaks[-1])

    def evaluate(self, t_s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position (m), speed (m/s) and acceleration (m/s^2) at `t_s` (held at the ends outside the record)."""
        t = np.clip(np.asarray(t_s, dtype=float), self.start_s, self.end_s)
        x = self._breaks
        k = np.clip(np.searchsorted(x, t, side="right") - 1, 0, len(x) - 2)
        h = t - x[k]
        a, b, c, d = (row[k] for row in self._coefficients)
        return ((a * h + b) * h + c) * h + d, (3 * a * h + 2 * b) * h + c, 6 * a * h + 2 * b

    def scalar(self):
        """A fast scalar evaluator t -> (position, speed, acceleration) for the integrator's right-hand side."""
        x = [float(v) for v in self._breaks]
        rows = [[float(v) for v in row] for row in self._coefficients]
        last, t0, t1 = len(x) - 2, x[0], x[-1]

        def at(t: float) -> tuple[float, float, float]:
            t = t0 if t < t0 else (t1 if t > t1 else t)
            k = min(bisect.bisect_right(x, t) - 1, last)
            h = t - x[k]
            a, b, c, d = rows[0][k], rows[1][k], rows[2][k], rows[3][k]
            return ((a * h + b) * h + c) * h + d, (3.0 * a * h + 2.0 * b) * h + c, 6.0 * a * h + 2.0 * b

        return at

    def perturbed(self, rng: np.random.Generator) -> SmoothedRack:
        """A rack the data allow as well: coefficients drawn from their least-squares distribution."""
        draw = rng.multivariate_normal(self.bspline, self.coefficient_covariance, method="eigh")
        return SmoothedRack(self.knots, draw, self.coefficient_covariance, self.knot_spacing_s, self.fit_rms_m,
                            self.noise_rms_m, self.held_at_rest, self.turning_times_s)

    def relogged(self, time_s: np.ndarray, full_scale: float, bits: int, analog_rms: float,
                 rng: np.random.Generator) -> SmoothedRack:
        """A rack the logger could equally have recorded: this spline, logged again and smoothed again.

        The spline at `time_s` gets analog noise of `analog_rms` and is rounded to the logger's
        levels, then smoothed with the same knot spacing (and the same tests for rest at the
        ends). Unlike :meth:`perturbed`, this keeps what makes an 8-bit rack hard near a
        turning point: there the rack stays within one converter step for a tenth of a second
        or more, its rounding errors are the same from sample to sample rather than
        independent, and the turning time the data fix is correspondingly less certain.
        """
        from ..synthetic.logger import add_noise, quantise

        logged = quantise(add_noise(self.evaluate(time_s)[0], analog_rms, rng), full_scale, bits)
        return smooth_rack(time_s, logged, self.knot_spacing_s)

    def summary(self) -> dict:
        """The smoothing's settings and fit (for JSON)."""
        return {
            "knot_spacing_s": self.knot_spacing_s,
            "fit_rms_m": self.fit_rms_m,
            "rack_noise_rms_m": self.noise_rms_m,
            "held_at_rest_at_start": bool(self.held_at_rest[0]),
            "held_at_rest_at_end": bool(self.held_at_rest[1]),
            "turning_times_s": list(self.turning_times_s),
        }


def _knot_vector(t: np.ndarray, spacing_s: float, turns: tuple[float, ...] = ()) -> np.ndarray:
    """Clamped cubic knots: evenly spaced interior knots about `spacing_s` apart, and one at each turning time.

    A reversal is the one place where the rack's motion changes within a few tenths of a
    second; with a knot at the turning time the spline can decelerate into it and accelerate
    out of it on either side, whatever the reversal's phase against the even knots. Even knots
    closer than half a spacing to a turning time give way to it.
    """
    span = t[-1] - t[0]
    pieces = max(1, int(round(span / spacing_s)))
    interior = list(t[0] + span * np.arange(1, pieces) / pieces)
    closest = settings.RACK_MIN_SAMPLES_PER_KNOT * float(np.median(np.diff(t)))
    turns = [x for x in turns if t[0] + closest < x < t[-1] - closest]
    knots = sorted([k for k in interior if all(abs(k - x) >= 0.5 * spacing_s for x in turns)] + turns)
    return np.concatenate([[t[0]] * 4, knots, [t[-1]] * 4])


def turning_times(time_s: np.ndarray, rack_m: np.ndarray) -> tuple[float, ...]:
    """Times where the rack reverses: zero crossings of its speed between steady motions of opposite sign.

    The speed is a local straight-line fit over RACK_TURN_WINDOW_S (as parksteer.measure.phases
    finds strokes); steady motion is a speed beyond a fifth of the 90th percentile of |speed|.
    """
    from ..measure.phases import local_linear_fit

    _, speed = local_linear_fit(time_s, rack_m, settings.RACK_TURN_WINDOW_S)
    level = 0.2 * float(np.percentile(np.abs(speed), 90))
    moving = np.flatnonzero(np.abs(speed) > level)
    turns = []
    for a, b in zip(moving[:-1], moving[1:]):
        if level > 0 and np.sign(speed[a]) != np.sign(speed[b]):
            segment = speed[a : b + 1]
            k = a + int(np.flatnonzero(np.sign(segment[:-1]) != np.sign(segment[1:]))[0])
            v0, v1 = speed[k], speed[k + 1]
            turns.append(float(time_s[k] + (time_s[k + 1] - time_s[k]) * v0 / (v0 - v1)))
    return tuple(turns)


def _constrained_solve(gram: np.ndarray, rhs: np.ndarray, constraints: np.ndarray):
    """Least squares with linear equality constraints C c = 0: (coefficients, their covariance per unit variance)."""
    inverse = np.linalg.inv(gram)
    coefficients = inverse @ rhs
    covariance = inverse
    if len(constraints):
        gc = inverse @ constraints.T
        correction = gc @ np.linalg.inv(constraints @ gc)
        coefficients = coefficients - correction @ (constraints @ coefficients)
        covariance = inverse - correction @ gc.T
    return coefficients, 0.5 * (covariance + covariance.T)


def _lsq_fit(t: np.ndarray, x: np.ndarray, spacing_s: float, turns: tuple[float, ...] = ()):
    """(knots, coefficients, covariance per unit variance, fit RMS) of the least-squares cubic spline.

    At each end of the record the spline is held at rest (zero speed) unless the data
    contradict it: unless holding it raises the residual sum of squares by more than
    ``RACK_REST_TEST_CHI2`` times the noise variance (a likelihood-ratio test with one degree of
    freedom; the bar is set well above the usual 6.6 because a spline with knots a few tenths
    of a second apart cannot follow the hand's first 0.2 s exactly and so leans towards a
    start speed that is not there). A record that starts or ends at rest then gets no
    spurious end speed, which the rack friction would turn into a spurious torque and the
    tyre carcass would remember; one cut in the middle of a stroke (15 mm/s, some fifty
    standard errors from rest) keeps its speed. None if the spline is ill-posed.
    """
    knots = _knot_vector(t, spacing_s, turns)
    design = BSpline.design_matrix(t, knots, 3).toarray()
    gram = design.T @ design
    try:
        np.linalg.cholesky(gram)
    except np.linalg.LinAlgError:  # Schoenberg-Whitney fails: an interval without data
        return None
    rhs = design.T @ x
    free, _ = _constrained_solve(gram, rhs, np.zeros((0, len(rhs))))
    rss_free = float(np.sum((design @ free - x) ** 2))
    noise_var = max(rss_free / max(len(t) - len(rhs), 1), 1e-30)
    speed_rows = np.array([BSpline(knots, np.eye(len(rhs))[j], 3)(np.array([t[0], t[-1]]), 1)
                           for j in range(len(rhs))]).T
    held, at_rest = [], []
    for row in speed_rows:
        trial, _ = _constrained_solve(gram, rhs, np.array(held + [row]))
        rss = float(np.sum((design @ trial - x) ** 2))
        at_rest.append(rss - rss_free < settings.RACK_REST_TEST_CHI2 * noise_var)
        if at_rest[-1]:
            held.append(row)
    coefficients, covariance = _constrained_solve(gram, rhs, np.array(held).reshape(len(held), len(rhs)))
    rms = float(np.sqrt(np.mean((design @ coefficients - x) ** 2)))
    return knots, coefficients, covariance, rms, tuple(at_rest)


def knot_spacings(time_s: np.ndarray) -> list[float]:
    """The knot spacings tried, s: from the finer of the range's bottom and a few samples, up to its top."""
    dt = float(np.median(np.diff(time_s)))
    low, high = settings.RACK_KNOT_SPACING_RANGE_S
    low = max(low, settings.RACK_MIN_SAMPLES_PER_KNOT * dt)
    count = int(math.floor(math.log(high / low) / math.log(settings.RACK_KNOT_SPACING_STEP))) + 1
    return [low * settings.RACK_KNOT_SPACING_STEP**i for i in range(max(count, 1))]


def smooth_rack(time_s, rack_m, knot_spacing_s: float | None = None) -> SmoothedRack:
    """The measured rack as a least-squares cubic spline; the knot spacing from the data unless given.

    Chosen spacing: the largest tried (:func:`knot_spacings`) whose fit RMS per degree of
    freedom is within ``RACK_DISCREPANCY_FACTOR`` of the rack's noise RMS; if none is, the finest.
    """
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(rack_m, dtype=float)
    if t.ndim != 1 or len(t) != len(x) or len(t) < 8:
        raise UsageError("rack smoothing needs matching time and rack columns with at least 8 samples")
    if (np.diff(t) <= 0).any():
        raise UsageError("rack smoothing: time must be strictly increasing")
    noise = estimate_noise_rms(x)
    turns = turning_times(t, x)

    def build(fit, spacing):
        knots, coefficients, inverse, rms, at_rest = fit
        return SmoothedRack(knots, coefficients, noise**2 * inverse, float(spacing), rms, noise, at_rest, turns)

    if knot_spacing_s is not None:
        if not knot_spacing_s > 0:
            raise UsageError(f"knot spacing must be positive, got {knot_spacing_s:g} s")
        fit = _lsq_fit(t, x, knot_spacing_s, turns)
        if fit is None:
            raise UsageError(f"rack smoothing: knot spacing {knot_spacing_s:g} s leaves intervals without samples")
        return build(fit, knot_spacing_s)
    best = None
    for spacing in knot_spacings(t):
        fit = _lsq_fit(t, x, spacing, turns)
        if fit is None:
            continue
        # the residual of a least-squares fit with p coefficients has n - p degrees of freedom
        unbiased = fit[3] * math.sqrt(len(t) / max(len(t) - len(fit[1]), 1))
        if best is None or unbiased <= settings.RACK_DISCREPANCY_FACTOR * noise:
            best = (fit, spacing)
    if best is None:
        raise UsageError("rack smoothing: no knot spacing gives a well-posed spline (samples too uneven)")
    return build(*best)


# ------------------------------------------------------------------------------------------ solve
@dataclass
class Replay:
    """The model of one effect set, driven by one smoothed rack, for one case and surface.

    :meth:`torque` replays it with effect-parameter overrides ({"effect.param": value})
    and returns the handwheel torque at the requested times. A run is prepared once
    (compiled model, parameter vector, static balance); an override of an effect
    parameter only changes that entry of the vector. Any other override (a parameter-file
    section or a case value) prepares the run again.
    """

    effects: list[Effect]
    case: str
    surface: str
    params: Parameters
    rack: SmoothedRack
    time_s: np.ndarray
    base_overrides: dict[str, float] = field(default_factory=dict)
    evaluations: int = 0

    def __post_init__(self):
        self.time_s = np.asarray(self.time_s, dtype=float)
        self._runs: dict[tuple, PreparedRun] = {}
        self._effect_by_name = {e.name: e for e in self.effects}
        self._run = self._prepared(self.base_overrides)

    def _split(self, overrides: dict[str, float]) -> tuple[dict[str, float], dict[str, float]]:
        """(effect-parameter overrides, other overrides)."""
        direct, other = {}, {}
        for key, value in overrides.items():
            owner = key.partition(".")[0]
            (direct if owner in self._effect_by_name else other)[key] = value
        return direct, other

    def _prepared(self, overrides: dict[str, float]) -> PreparedRun:
        _, other = self._split(overrides)
        key = tuple(sorted(other.items()))
        if key not in self._runs:
            self._runs[key] = prepare(self.case, self.effects, other, self.surface, self.params)
        return self._runs[key]

    def parameter_vector(self, overrides: dict[str, float] | None = None) -> tuple[PreparedRun, np.ndarray]:
        merged = {**self.base_overrides, **(overrides or {})}
        run = self._prepared(merged)
        p = run.p.copy()
        direct, _ = self._split(merged)
        for key, value in direct.items():
            owner, _, name = key.partition(".")
            spec = self._effect_by_name[owner].parameter(name)
            p[run.parameter_index(key)] = spec.check(owner, value)
        return run, p

    def value(self, key: str) -> float:
        """The value of parameter `key` ("effect.param") in the base run."""
        run, p = self.parameter_vector()
        return float(p[run.parameter_index(key)])

    def torque(self, overrides: dict[str, float] | None = None, outputs: bool = False):
        """Handwheel torque (N m) at `time_s`; with `outputs`, also the model's named outputs there."""
        run, p = self.parameter_vector(overrides)
        self.evaluations += 1
        return _solve(run, p, self.rack, self.time_s, outputs)


def _solve(run: PreparedRun, p: np.ndarray, rack: SmoothedRack, t_out: np.ndarray, outputs: bool):
    model = run.model
    lib = model.lib
    n = model.n_q
    i_rack = model.index("rack")
    others = np.array([i for i in range(n) if i != i_rack], dtype=int)
    speeds = others + n
    n_o = len(others)
    drive = rack.scalar()

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
        return np.linalg.solve(A, F - M[:, i_rack] * rdd), rdd

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

    def jacobian(z, t):
        x, rdd = accelerations(t, z)
        acc[others] = x[:n_o]
        acc[i_rack] = rdd
        t_one[0] = t
        lib.ps_outputs(1, t_one.ctypes.data, y_ptr, acc.ctypes.data, hw.ctypes.data, p_jac_ptr, out_one.ctypes.data)
        p_jac[n_par + 2] = out_one[i_column] + x[n_o]  # angle = column angle + torque / (unit stiffness)
        if lib.ps_jac(float(t), y_ptr, p_jac_ptr, J_full.ctypes.data):
            raise FloatingPointError("mass matrix not positive definite")
        h = np.linalg.solve(M, b)
        J[n_o:] = J_full[n + others][:, reduced] - np.outer(h[others] / h[i_rack], J_full[n + i_rack][reduced])
        return J

    units = model.info["coordinate_units"]
    atol = settings.REPLAY_ATOL_FACTOR * np.array([ATOL_Q[units[i]] for i in others] + [ATOL_U[units[i]] for i in others])
    t0 = float(t_out[0])
    r0 = drive(t0)[0]
    y_static = static_state(run, fixed={"rack": r0})
    z0 = np.concatenate([y_static[others], np.zeros(n_o)])
    # The run starts from rest at the first sample: integrate from there (odeint needs t_out[0] = start).
    states, info = odeint(rhs, z0, t_out, Dfun=jacobian, rtol=settings.REPLAY_RTOL, atol=atol, mxstep=200000,
                          full_output=True)
    if info["message"] != "Integration successful.":
        raise RuntimeError(f"replay integration failed: {info['message']}")
    torque = np.empty(len(t_out))
    if not outputs:
        for k, t in enumerate(t_out):
            torque[k] = accelerations(float(t), states[k])[0][n_o]
        return torque
    full = np.zeros((len(t_out), 2 * n))
    accs = np.zeros((len(t_out), n))
    for k, t in enumerate(t_out):
        x, rdd = accelerations(float(t), states[k])
        torque[k] = x[n_o]
        full[k] = y
        accs[k, others] = x[:n_o]
        accs[k, i_rack] = rdd
    columns = model.evaluate_outputs(t_out, full, p, accs, np.zeros((len(t_out), 2)))
    # The column torque output needs the handwheel; the prescribed-rack torque is the solved one.
    columns = {k: v for k, v in columns.items() if k != "column_torque_Nm"}
    columns["handwheel_torque_Nm"] = torque
    columns["rack_m"] = full[:, i_rack]
    return torque, columns
