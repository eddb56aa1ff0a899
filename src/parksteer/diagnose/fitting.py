"""A fitted model and the weighted nonlinear least squares that makes one (:func:`least_squares`, :func:`polish`).

Levenberg-Marquardt on the weighted residuals r_i = (measured - model) / sigma_i (:mod:`parksteer.diagnose.problem`)
of the parameters :mod:`parksteer.diagnose.calibrate` chooses (:class:`FitParameter`): positive physical parameters
are fitted as the logarithm of their ratio to the default, a strength as it stands within its bounds; the Jacobian
starts from finite differences and is updated by Broyden's rank-one formula, and taken afresh at the end if the
parameters moved far (with ``DiagnosisSettings.exact_jacobian``, each Jacobian taken afresh is exact, from the
replays' forward sensitivities, instead of by finite differences). :func:`polish` then takes Gauss-Newton steps on a fresh Jacobian until the step is a tenth of
every standard error, so that a candidate's refit gains in the BIC only what it brings. Intervals are 95 %:
``cov = s^2 (J^T J)^-1`` inflated by (1 + rho) / (1 - rho) for the residuals' lag-1 autocorrelation rho, or, where
larger, a block sandwich over segments of the cycle (:meth:`Fit.intervals`). Why: docs/diagnosis.md, "How sure the
report says it is".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import portable as pm
from ..model.symbolic.components import Effect
from .settings import DEFAULT_SETTINGS, DiagnosisSettings
from .engine import ReplayEngine
from .problem import Problem
from .statistics import block_sandwich, lag1_autocorrelation, replay_covariance

Z95 = 1.959964  # two-sided 95 % quantile of the standard normal


@dataclass(frozen=True)
class FitParameter:
    """One fitted parameter: key ("effect.param"), transform ("log" of value / reference; "linear", a strength
    fitted as it stands from its lower bound; "offset", fitted as it stands from the model's value)."""

    key: str
    transform: str
    reference: float  # log: the value at theta = 0; offset: the model's value; linear: unused
    lower: float  # bounds on the value
    upper: float
    step: float  # finite-difference step in theta

    def value(self, theta: float) -> float:
        raw = self.reference * pm.exp(theta) if self.transform == "log" else theta
        return min(max(raw, self.lower), self.upper)

    def theta(self, value: float) -> float:
        return pm.log(value / self.reference) if self.transform == "log" else value

    def theta_bounds(self) -> tuple[float, float]:
        if self.transform == "log":
            return pm.log(self.lower / self.reference), pm.log(self.upper / self.reference)
        return self.lower, self.upper


@dataclass(frozen=True)
class Fit:
    """A fitted model: values, predictions, weighted residuals, Jacobian and the fit's statistics."""

    effects: list[Effect]
    parameters: list[FitParameter]
    theta: np.ndarray
    fixed: dict[str, float]
    predictions: list[np.ndarray]
    weighted: np.ndarray
    jacobian: np.ndarray  # d(model / sigma) / d(theta), one row per sample
    iterations: int
    evaluations: int
    history: list[float] = field(default_factory=list)  # weighted RSS after each accepted step

    @property
    def rss(self) -> float:
        return float(np.sum(self.weighted**2))

    @property
    def values(self) -> dict[str, float]:
        return {p.key: p.value(t) for p, t in zip(self.parameters, self.theta)}

    @property
    def overrides(self) -> dict[str, float]:
        return {**self.fixed, **self.values}

    def rho(self, problem: Problem) -> float:
        return lag1_autocorrelation(problem, self.weighted)

    def intervals(self, problem: Problem, block_s: float = DEFAULT_SETTINGS.interval_block_s) -> dict[str, dict]:
        """Value, standard error and 95 % interval of each parameter (in its own unit).

        The standard error is the larger of two: the model-based one (module docstring) and a
        block sandwich over `block_s` segments of each file, ``B/(B-k) (J^T J)^-1 (sum_b g_b g_b^T)
        (J^T J)^-1`` with ``g_b = J_b^T r_b`` the block's score (:func:`parksteer.diagnose.statistics.block_sandwich`). The
        model-based one is right only if the model is exact and the residual is noise; the
        sandwich takes the residual as it is, a structured misfit included, so its
        intervals widen when the model class is not exact. Neither sees an error of the replayed
        rack itself, which is one error for the whole record and so shifts the fit rather than
        the residual: its share (:func:`parksteer.diagnose.statistics.replay_covariance`, the spread of the fitted values the
        replay ensemble's racks would give) is added in quadrature. With the sandwich the 95 % point is
        Student's t with B - k degrees of freedom (B blocks), since the meat is estimated from B blocks.
        """
        if not self.parameters:
            return {}
        n, k = self.weighted.size, len(self.parameters)
        rho = min(max(self.rho(problem), 0.0), 0.95)
        variance = self.rss / max(n - k, 1) * (1.0 + rho) / (1.0 - rho)
        covariance, sandwich, blocks = np.full((k, k), np.inf), np.full((k, k), np.inf), 0
        replay = np.zeros((k, k))
        # A parameter the data do not see at all (a tyre's on air bearings) has a zero column and makes J^T J
        # singular: its interval is infinite, and the others' come from the columns that are left.
        norms = pm.norm(self.jacobian, axis=0)
        for seen in (np.ones(k, dtype=bool), norms > 1e-9 * max(float(norms.max(initial=0.0)), 1e-300)):
            if not seen.any():
                break
            jacobian = self.jacobian[:, seen]
            try:
                sub = np.ix_(seen, seen)
                covariance[sub] = variance * pm.inv(pm.matmul(jacobian.T, jacobian))
                sandwich[sub], blocks = block_sandwich(jacobian, self.weighted, problem, block_s)
                replay[sub] = replay_covariance(jacobian, problem)
                break
            except pm.LinAlgError:
                covariance, sandwich, blocks = np.full((k, k), np.inf), np.full((k, k), np.inf), 0
                replay = np.zeros((k, k))
        quantile = pm.student_t_quantile(0.975, blocks - k) if blocks > k else math.inf
        out = {}
        for i, (p, t) in enumerate(zip(self.parameters, self.theta)):
            model_se = math.sqrt(max(covariance[i, i], 0.0))
            sandwich_se = math.sqrt(max(sandwich[i, i], 0.0))
            # the replay's own error is common to every block (one rack for the whole record): added apart
            half = pm.hypot(max(Z95 * model_se, quantile * sandwich_se), Z95 * math.sqrt(max(replay[i, i], 0.0)))
            se = half / Z95
            low, high = p.value(t - half), p.value(t + half)
            if p.transform != "log":
                low, high = t - half, t + half  # the interval itself may cross a bound
            out[p.key] = {"value": p.value(t), "ci95": [low, high],
                          "standard_error": (p.value(t) * se if p.transform == "log" else se)}
        return out


def _predict(engine: ReplayEngine, problem: Problem, effects: list[Effect], parameters: list[FitParameter],
             theta: np.ndarray, fixed: dict[str, float]) -> tuple[list[np.ndarray], np.ndarray]:
    overrides = {**fixed, **{p.key: p.value(t) for p, t in zip(parameters, theta)}}
    predictions = engine.predict(problem, effects, overrides)
    return predictions, problem.weighted(predictions)


def finite_difference_jacobian(engine: ReplayEngine, problem: Problem, effects: list[Effect],
                               parameters: list[FitParameter], theta: np.ndarray, fixed: dict[str, float],
                               predictions: list[np.ndarray]) -> np.ndarray:
    """d(model / sigma)/d(theta) by forward differences (a backward step at an upper bound)."""
    base = problem.scale(predictions)
    columns = []
    for i, p in enumerate(parameters):
        step = p.step
        if theta[i] + step > p.theta_bounds()[1]:
            step = -step
        shifted = theta.copy()
        shifted[i] += step
        moved, _ = _predict(engine, problem, effects, parameters, shifted, fixed)
        columns.append((problem.scale(moved) - base) / step)
    return np.column_stack(columns) if columns else np.zeros((base.size, 0))


def exact_jacobian(engine: ReplayEngine, problem: Problem, effects: list[Effect], parameters: list[FitParameter],
                   theta: np.ndarray, fixed: dict[str, float]) -> np.ndarray | None:
    """d(model / sigma)/d(theta) from each file's replay with forward sensitivities (one integration a file, counted
    as one solve), or None where they do not apply: a file fitted on its angle or motor channel, an assisted car.

    A parameter the compiled model reads directly has its unit direction in the parameter vector; one that the run's
    preparation turns into other entries (a tyre's friction coefficient into the surface grip), the central
    difference of the prepared vectors at 1e-6 of its value (no replay: the preparation's own arithmetic)."""
    from ..model.numeric.sensitivities import solve_sensitivities

    if any(f.uses_angle or f.uses_motor for f in problem.files):
        return None
    values = [p.value(t) for p, t in zip(parameters, theta)]
    overrides = {**fixed, **{p.key: v for p, v in zip(parameters, values)}}
    per_theta = np.array([v if p.transform == "log" else 1.0 for p, v in zip(parameters, values)])
    blocks = []
    for index, f in enumerate(problem.files):
        replay = engine.replay(problem, effects, index)
        if replay.assisted:
            return None
        run, p_vector = replay.parameter_vector(overrides)
        directions = np.zeros((len(parameters), len(run.model.info["parameters"])))
        for k, (parameter, value) in enumerate(zip(parameters, values)):
            key = parameter.key
            if key in run.model.parameter_positions and not key.startswith("derived."):
                directions[k, run.parameter_index(key)] = 1.0
                continue
            h = 1e-6 * max(abs(value), 1e-12)
            up = replay.parameter_vector({**overrides, key: value + h})[1]
            down = replay.parameter_vector({**overrides, key: value - h})[1]
            directions[k] = (up - down)[: directions.shape[1]] / (2.0 * h)
        replay.count_solve()
        solution = solve_sensitivities(run, p_vector, replay.rack, replay.time_s, directions)
        blocks.append(solution.torque_sensitivities * per_theta / np.asarray(f.sigma, dtype=float).reshape(-1, 1))
    return np.vstack(blocks)


def fresh_jacobian(engine: ReplayEngine, problem: Problem, effects: list[Effect], parameters: list[FitParameter],
                   theta: np.ndarray, fixed: dict[str, float], predictions: list[np.ndarray],
                   settings: DiagnosisSettings) -> np.ndarray:
    """A Jacobian taken afresh at `theta`: exact where the settings ask and the replays allow (:func:`exact_jacobian`),
    else by finite differences."""
    exact = exact_jacobian(engine, problem, effects, parameters, theta, fixed) if settings.exact_jacobian else None
    return exact if exact is not None else finite_difference_jacobian(engine, problem, effects, parameters, theta,
                                                                       fixed, predictions)


def least_squares(engine: ReplayEngine, problem: Problem, effects: list[Effect], parameters: list[FitParameter],
                  theta0: np.ndarray, fixed: dict[str, float] | None = None, jacobian: np.ndarray | None = None,
                  max_iterations: int | None = None, tolerance: float | None = None,
                  settings: DiagnosisSettings = DEFAULT_SETTINGS, refresh_at_end: bool = True) -> Fit:
    """Levenberg-Marquardt with Broyden updates (see the module docstring); `jacobian` may seed it.

    `max_iterations` and `tolerance` default to the calibration's (`settings`). Without `refresh_at_end` the
    Jacobian returned is the last one the iterations used (:func:`polish` takes a fresh one anyway).
    """
    max_iterations = settings.calibration_max_iterations if max_iterations is None else max_iterations
    tolerance = settings.calibration_tolerance if tolerance is None else tolerance
    fixed = dict(fixed or {})
    start_evaluations = engine.evaluations
    lower = np.array([p.theta_bounds()[0] for p in parameters])
    upper = np.array([p.theta_bounds()[1] for p in parameters])
    theta = np.clip(np.asarray(theta0, dtype=float), lower, upper)
    predictions, r = _predict(engine, problem, effects, parameters, theta, fixed)
    rss = pm.dot(r, r)
    history = [rss]
    if not parameters:
        return Fit(effects, parameters, theta, fixed, predictions, r, np.zeros((r.size, 0)), 0, 0, history)
    J = jacobian.copy() if jacobian is not None and not settings.exact_jacobian else fresh_jacobian(
        engine, problem, effects, parameters, theta, fixed, predictions, settings)
    theta_at_jacobian = theta.copy()
    damping = 1e-3
    iterations = 0
    failures = 0
    while iterations < max_iterations:
        JTJ = pm.matmul(J.T, J)
        scale = np.diag(JTJ).copy()
        scale[scale <= 0] = 1.0
        # Converged when the full Gauss-Newton step (kept within the bounds) is a small fraction of every
        # parameter's standard error: a further step could not change the answer within its own uncertainty.
        # (A test on the change of the sum of squares stops too early in a long, narrow valley, where two
        # parameters trade against each other, e.g. a rack damping against the rack friction.)
        se = np.full(len(theta), np.inf)
        try:
            newton = np.clip(theta + pm.solve(JTJ, pm.matmul(J.T, r)), lower, upper) - theta
            se = np.sqrt(np.maximum(np.diag(pm.inv(JTJ)), 0.0) * rss / max(r.size - len(theta), 1))
            if np.all(np.abs(newton) <= tolerance * se):
                break
        except pm.LinAlgError:
            pass
        iterations += 1
        step = pm.solve(JTJ + damping * np.diag(scale), pm.matmul(J.T, r))
        trial = np.clip(theta + step, lower, upper)
        step = trial - theta
        if not np.any(step):
            break
        trial_predictions, trial_r = _predict(engine, problem, effects, parameters, trial, fixed)
        trial_rss = pm.dot(trial_r, trial_r)
        predicted = rss - float(np.sum((r - pm.matmul(J, step)) ** 2))
        # Broyden: the actual change of model / sigma is r - trial_r. A step much smaller than the standard
        # errors moves the model by little more than the integrator's own noise: it would corrupt J.
        if np.any(np.abs(step) > se):
            J += np.outer((r - trial_r) - pm.matmul(J, step), step) / pm.dot(step, step)
        if trial_rss < rss:
            poor = predicted > 0 and (rss - trial_rss) < 0.25 * predicted
            theta, predictions, r, rss = trial, trial_predictions, trial_r, trial_rss
            history.append(rss)
            damping = max(damping / 3.0, 1e-7)
            failures = 0
            if poor:  # the linear model promised much more than the step gave: renew it
                J = fresh_jacobian(engine, problem, effects, parameters, theta, fixed, predictions, settings)
                theta_at_jacobian = theta.copy()
        else:
            damping *= 4.0
            failures += 1
            if failures == 2:  # the updated Jacobian misleads: start again from finite differences
                J = fresh_jacobian(engine, problem, effects, parameters, theta, fixed, predictions, settings)
                theta_at_jacobian = theta.copy()
            elif failures > 3:
                break
    if refresh_at_end and np.max(np.abs(theta - theta_at_jacobian)) > settings.jacobian_refresh_theta:
        J = fresh_jacobian(engine, problem, effects, parameters, theta, fixed, predictions, settings)
    return Fit(effects, parameters, theta, fixed, predictions, r, J, iterations,
               engine.evaluations - start_evaluations, history)


def gauss_newton_step(jacobian: np.ndarray, weighted: np.ndarray, theta: np.ndarray, lower: np.ndarray,
                      upper: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(The full Gauss-Newton step kept within the bounds, each parameter's model-based standard error
    ``sqrt(diag((J^T J)^-1) RSS / (n - k))``); a singular J^T J gives infinite standard errors and no step."""
    k = len(theta)
    JTJ = pm.matmul(jacobian.T, jacobian)
    try:
        newton = np.clip(theta + pm.solve(JTJ, pm.matmul(jacobian.T, weighted)), lower, upper) - theta
        variance = pm.dot(weighted, weighted) / max(weighted.size - k, 1)
        return newton, np.sqrt(np.maximum(np.diag(pm.inv(JTJ)), 0.0) * variance)
    except pm.LinAlgError:
        return np.zeros(k), np.full(k, np.inf)


def polish(engine: ReplayEngine, problem: Problem, fit: Fit, settings: DiagnosisSettings = DEFAULT_SETTINGS) -> Fit:
    """`fit` taken on to the optimum of its own sum of squares: Gauss-Newton on a fresh finite-difference Jacobian.

    :func:`least_squares` judges convergence on a Jacobian updated by Broyden's formula, which after a few steps
    along a narrow valley (the tyre's friction against the rack's) points the wrong way, and it stops after
    ``calibration_max_iterations``; so it can stop several standard errors short of the optimum. A candidate's
    refit starts there and walks on, and the base parameters' further fall of the sum of squares is then counted
    as the candidate's BIC gain. The criterion here, on a Jacobian taken afresh at the point itself: the full
    Gauss-Newton step is within ``calibration_polish_tolerance`` of every parameter's model-based standard error.
    A step of delta standard errors lowers the weighted sum of squares by at most about delta^2 RSS / (n - k) per
    parameter, so what is left to gain is under k delta^2 n_eff / (n - k) in the BIC (0.03 for three parameters
    at a tenth of a standard error), far below the ``bic_missing_threshold``. A step that does not lower the sum
    of squares is halved up to ``calibration_polish_halvings`` times; if none does, the point is the optimum to
    within the replay's own numerical noise and is kept. At most ``calibration_polish_rounds`` fresh Jacobians
    (each one replay a parameter, and one a step). The fit returned carries the last fresh Jacobian, taken at its
    point when it has converged."""
    parameters, effects, fixed = fit.parameters, fit.effects, fit.fixed
    if not parameters:
        return fit
    start_evaluations = engine.evaluations
    lower = np.array([p.theta_bounds()[0] for p in parameters])
    upper = np.array([p.theta_bounds()[1] for p in parameters])
    theta, predictions, r = fit.theta.copy(), fit.predictions, fit.weighted
    rss, history, J, rounds = pm.dot(r, r), list(fit.history), fit.jacobian, 0
    while rounds < settings.calibration_polish_rounds:
        rounds += 1
        J = fresh_jacobian(engine, problem, effects, parameters, theta, fixed, predictions, settings)
        newton, se = gauss_newton_step(J, r, theta, lower, upper)
        if np.all(np.abs(newton) <= settings.calibration_polish_tolerance * se):
            break
        for _ in range(settings.calibration_polish_halvings + 1):
            trial_predictions, trial_r = _predict(engine, problem, effects, parameters, theta + newton, fixed)
            trial_rss = pm.dot(trial_r, trial_r)
            if trial_rss < rss:
                theta, predictions, r, rss = theta + newton, trial_predictions, trial_r, trial_rss
                history.append(rss)
                break
            newton = newton / 2.0
        else:
            break  # no step along Gauss-Newton's direction lowers the sum of squares: the optimum, to the noise
    return Fit(effects, parameters, theta, fixed, predictions, r, J, fit.iterations + rounds,
               fit.evaluations + engine.evaluations - start_evaluations, history)
