"""Diagnose: calibrate, rank the candidates, refit the best, choose, and say what would separate them.

The steps (:func:`diagnose`):

1. replay the files through the base model at its default parameters, and estimate each
   sample's replay uncertainty (:mod:`parksteer.diagnose.problem`);
2. calibrate the base model's uncertain parameters (:mod:`parksteer.diagnose.calibrate`);
3. for every candidate not in the model, its signature and score test at the calibrated model
   (:mod:`parksteer.diagnose.candidates`);
4. refit the best-scored few in the full nonlinear model (calibrated parameters and the
   candidate's strength together);
5. compare by an information criterion over the effective sample size:
   ``BIC = n_eff ln(RSS / n) + k ln(n_eff)``, with ``n_eff = n (1 - rho) / (1 + rho)`` and rho
   the lag-1 autocorrelation of the best model's weighted residuals (neighbouring samples of
   a smooth misfit are not independent evidence);
6. the verdict:

   - ``missing``: the best candidate lowers the BIC by more than ``bic_missing_threshold``
     and, with it, the error is at the floor (weighted RMS within ``adequate_rms_factor`` of
     the noise floor) or it removes at least ``explained_fraction_missing`` of the weighted
     sum of squares above the floor (a perfect model leaves a weighted sum of squares equal
     to the number of samples); either way the error with it must come within
     ``missing_rms_ceiling`` floors (without its largest ``missing_ceiling_trim`` of residuals),
     since a named effect that leaves the residual above what records with nothing hidden reach
     along the strokes is not the whole story. This is tested first: a small
     effect that the calibration has mostly absorbed can leave the error near the floor and
     still be strongly evidenced by its shape;
   - ``adequate``: otherwise, when no candidate is strongly evidenced and the calibrated base
     model's weighted error is at the floor;
   - ``unexplained``: the residual is structured (or a candidate is evidenced but leaves most
     of it), and no candidate removes most of it.

   When a candidate is strongly evidenced, the replay uncertainty is estimated again with its
   fitted model, each sample keeps the larger of the two, and the comparison is repeated with
   these weights: a candidate can sharpen the torque exactly where the rack data are least
   certain (a breakaway peak at a reversal), and a comparison weighted by the base model's
   uncertainty alone would count the replay's timing errors there against it.

7. candidates within ``BIC_INDISTINGUISHABLE`` of the best are ``indistinguishable`` by these
   data; for each, both fitted models are replayed (on the first file's rack) under every
   condition the data do not cover (the other load cases and spacers, on the ground and on
   air bearings), and the condition where they differ most, relative to the noise floor, is
   named as the measurement that would separate them;
8. a candidate ``confounded`` with the calibrated parameters (these data cannot tell it from a
   change of them) gets the same: the measurement where it would show although the calibrated
   parameters take it up here (:func:`confound_tests`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from .. import portable as pm
from ..model.symbolic.components import Effect, discover_effects, resolve_effects
from ..names import SURFACES
from ..errors import SolverError
from ..parameters import Parameters
from .settings import DEFAULT_SETTINGS, DiagnosisSettings
from .calibrate import Fit, FitParameter, calibrate, least_squares
from .candidates import Score, Signature, candidate_effects, probe_signature, score, strength_parameter
from .parallel import Progress, fork_map, forks
from .problem import FileData, Problem, effective_samples, fit_statistics, lag1_autocorrelation
from .replay import Replay

VERDICTS = ("missing", "adequate", "unexplained")


@dataclass
class Candidate:
    """One candidate's signature, score and (for the best few) refit."""

    signature: Signature
    score: Score
    refit: Fit | None = None
    delta_bic: float | None = None

    @property
    def name(self) -> str:
        return self.signature.effect.name

    def rss_after(self, base_rss: float) -> float:
        return self.refit.rss if self.refit is not None else base_rss - self.score.removed_rss


@dataclass
class Separation:
    """Where two fitted models differ most, among the conditions the data do not cover."""

    effect: str
    delta_bic: float
    case: str
    surface: str
    predicted_difference_rms_Nm: float
    over_noise_floor: float
    conditions: list[dict]


@dataclass
class Diagnosis:
    """Everything :func:`diagnose` found (turned into JSON by :mod:`parksteer.diagnose.report`)."""

    problem: Problem
    base_effects: list[Effect]
    nominal_predictions: list[np.ndarray]
    calibration: Fit
    candidates: list[Candidate]
    untestable: list[str]
    verdict: str
    best: Candidate | None
    indistinguishable: list[Separation]
    n_eff: float
    rho: float
    explained_fraction: float | None
    timings_s: dict[str, float] = field(default_factory=dict)
    settings: DiagnosisSettings = DEFAULT_SETTINGS
    identification: list[dict] = field(default_factory=list)  # what these data fix (:func:`identification`)
    # where each confounded candidate would show, by name (:func:`confound_tests`; empty where the settings say not)
    confound_tests: dict[str, dict | None] = field(default_factory=dict)

    @property
    def effect(self) -> str | None:
        return self.best.name if self.verdict == "missing" and self.best is not None else None

    @property
    def ranked(self) -> list[Candidate]:
        refitted = sorted((c for c in self.candidates if c.refit is not None), key=lambda c: -(c.delta_bic or 0.0))
        others = sorted((c for c in self.candidates if c.refit is None), key=lambda c: -c.score.statistic)
        return refitted + others

    @property
    def confounded(self) -> list[Candidate]:
        return confounded_candidates(self.candidates, self.settings)

    @property
    def unobservable(self) -> list[str]:
        return [c.name for c in self.candidates if not c.signature.observable]

    def statistics(self, predictions: list[np.ndarray]) -> dict:
        return fit_statistics(self.problem, predictions)


def confounded_candidates(candidates: list[Candidate], settings: DiagnosisSettings) -> list[Candidate]:
    """The observable candidates whose signature is mostly a calibrated parameter's (identifiable fraction below
    the settings' confounded_fraction): these data cannot tell them from a change of that parameter."""
    return [c for c in candidates
            if c.signature.observable and c.score.identifiable_fraction < settings.confounded_fraction]


def trimmed_rms(weighted: np.ndarray, trim: float) -> float:
    """RMS of the weighted residuals without the largest fraction `trim` of them (in noise floors)."""
    magnitudes = np.sort(np.abs(np.asarray(weighted, dtype=float)))
    kept = magnitudes[: max(int(math.ceil((1.0 - trim) * len(magnitudes))), 1)]
    return float(np.sqrt(np.mean(kept**2)))


def choose_verdict(base_ratio: float, best_delta_bic: float | None, after_ratio: float | None,
                   explained: float | None, settings: DiagnosisSettings = DEFAULT_SETTINGS,
                   spread_ratio: float | None = None) -> str:
    """The verdict from the calibrated base model's weighted RMS over the floor, the best refit's BIC gain, its
    weighted RMS over the floor and the fraction of the excess it removes (module docstring, step 6).

    `spread_ratio` is the best refit's weighted RMS without its largest ``missing_ceiling_trim`` of residuals (by
    default `after_ratio`): the ceiling is checked on it, so that a misfit confined to a few instants does not
    block a name while one spread along the strokes does."""
    evidenced = best_delta_bic is not None and best_delta_bic > settings.bic_missing_threshold
    spread_ratio = after_ratio if spread_ratio is None else spread_ratio
    if (evidenced and spread_ratio <= settings.missing_rms_ceiling
            and (after_ratio <= settings.adequate_rms_factor
                 or (explained is not None and explained >= settings.explained_fraction_missing))):
        return "missing"
    if base_ratio <= settings.adequate_rms_factor and not evidenced:
        return "adequate"
    return "unexplained"


def identification(problem: Problem, calibration: Fit, settings: DiagnosisSettings = DEFAULT_SETTINGS
                   ) -> list[dict]:
    """What these data fix: every parameter the method calibrates (with the angle, also what only the angle
    shows), each with a status and, where it is not fixed, the test that would fix it.

    ``fixed``: calibrated, its 95 % interval within ``identified_relative_halfwidth`` of its value either side
    (a phase-like parameter: ``identified_phase_halfwidth_rad``); ``not fixed``: calibrated with a wider
    interval, replayed at both ends of it on the first file's rack under each load case and surface the data do
    not cover, the condition where the torque moves most (RMS, in noise floors) named as the test that fixes
    it; ``not calibrated``: a parameter only the handwheel angle shows, in a diagnosis without it.
    """
    intervals = calibration.intervals(problem, settings.interval_block_s)
    offsets = {key for key, _, _ in settings.calibrated_with_angle_offsets}
    out = []
    for key in [*settings.calibrated_parameters, *settings.calibrated_with_angle, *sorted(offsets)]:
        if key not in intervals:
            if not problem.uses_angle and (key in settings.calibrated_with_angle or key in offsets):
                out.append({"parameter": key, "status": "not calibrated", "value": None, "ci95": None,
                            "fixed_by": "a handwheel angle channel, with the rack logged on 12 bits or finer "
                                        "(parksteer diagnose --angle)"})
            continue
        entry = intervals[key]
        value, ci = entry["value"], entry["ci95"]
        if ci is None or not all(math.isfinite(c) for c in ci):
            halfwidth = math.inf
        else:
            halfwidth = (ci[1] - ci[0]) / 2
        limit = settings.identified_phase_halfwidth_rad if key in offsets \
            else settings.identified_relative_halfwidth * abs(value)
        row = {"parameter": key, "status": "fixed" if halfwidth <= limit else "not fixed", "value": value,
               "ci95": ci, "fixed_by": None}
        if row["status"] == "not fixed" and math.isfinite(halfwidth):
            row["fixed_by"] = _fixing_test(problem, calibration, key, ci[0], ci[1])
        out.append(row)
    return out


def confound_tests(problem: Problem, calibration: Fit, candidates: list[Candidate]) -> dict[str, dict | None]:
    """Where each candidate that the calibrated parameters take up in these data would show, by name: None if
    the data cover every load case and surface.

    A candidate at its probe strength changes the replayed torque by a few noise floors; the calibrated
    parameters, moved by the least-squares change that best cancels that change here (to first order: the score
    test's projection, Score.calibrated_equivalent), take up all but the part the score test sees (its
    identifiable fraction). The
    compensated model and the calibrated base model, which the data cannot tell apart, are then replayed on the
    first file's rack under each condition the data do not cover (the base model once for all candidates), and
    the condition where they differ most (RMS, in noise floors) is the measurement that would tell the candidate
    from the parameter: a king-pin friction, whose moment grows with the wheel load, from a rack friction, which
    does not.
    """
    if not candidates or not conditions_not_covered(problem):
        return {c.name: None for c in candidates}
    runs, summaries = [(calibration.effects, calibration.overrides)], []
    for candidate in candidates:
        signature, score = candidate.signature, candidate.score
        theta = calibration.theta - signature.probe * score.calibrated_equivalent
        moved = {p.key: p.value(t) for p, t in zip(calibration.parameters, theta)}
        runs.append((signature.model, {**calibration.fixed, **moved, signature.key: signature.probe}))
        # what the moved parameters leave of the probe's plain RMS change here (in the weighted sense)
        left_Nm = signature.rms_change_Nm * score.identifiable_fraction
        summaries.append({"strength": signature.probe, "change_here_rms_Nm": signature.rms_change_Nm,
                          "left_here_rms_Nm": left_Nm,
                          "left_here_over_noise_floor": left_Nm / problem.files[0].noise.total_rms,
                          "compensated": moved})
    out = {}
    for candidate, rows, summary in zip(candidates, differences_by_condition(problem, runs), summaries):
        top = max(rows, key=lambda r: r["over_noise_floor"])
        out[candidate.name] = {"case": top["case"], "surface": top["surface"],
                               "predicted_difference_rms_Nm": top["predicted_difference_rms_Nm"],
                               "over_noise_floor": top["over_noise_floor"], **summary}
    return out


def _fixing_test(problem: Problem, calibration: Fit, key: str, low: float, high: float) -> dict | None:
    """The uncovered condition where the parameter's two interval ends move the replayed torque most."""
    base = calibration.overrides
    rows = differences_by_condition(problem, [(calibration.effects, {**base, key: v}) for v in (low, high)])[0]
    return max(rows, key=lambda r: r["over_noise_floor"]) if rows else None


def differences_by_condition(problem: Problem, runs: list[tuple[list[Effect], dict[str, float]]]
                             ) -> list[list[dict]]:
    """The first run and each other ((effects, overrides) each), replayed on the first file's rack under each
    load case and surface the data do not cover: for each other run, one row per condition with the RMS torque
    difference from the first there, in N m and in the file's noise floors. Runs of the same effect set share
    one prepared replay per condition."""
    f = problem.files[0]
    rows: list[list[dict]] = [[] for _ in runs[1:]]
    for case, surface in conditions_not_covered(problem):
        replays: dict[int, Replay] = {}
        predicted = []
        for effects, overrides in runs:
            if id(effects) not in replays:
                replays[id(effects)] = Replay(effects, case, surface, problem.params, f.rack, f.time_s)
            predicted.append(replays[id(effects)].torque(overrides))
        for out, other in zip(rows, predicted[1:]):
            difference = float(np.sqrt(np.mean((predicted[0] - other) ** 2)))
            out.append({"case": case, "surface": surface, "predicted_difference_rms_Nm": difference,
                        "over_noise_floor": difference / f.noise.total_rms})
    return rows


def refit(problem: Problem, calibration: Fit, signature: Signature, start_strength: float,
          settings: DiagnosisSettings = DEFAULT_SETTINGS) -> Fit:
    """The calibrated parameters and the candidate's strength fitted together in the full model."""
    spec = strength_parameter(signature.effect)
    strength = FitParameter(signature.key, "linear", 1.0, max(spec.lower, 0.0), spec.upper, signature.probe)
    parameters = [*calibration.parameters, strength]
    theta0 = np.concatenate([calibration.theta, [min(max(start_strength, strength.lower), strength.upper)]])
    seed = np.column_stack([calibration.jacobian, signature.weighted])
    fit = least_squares(problem, signature.model, parameters, theta0, calibration.fixed, jacobian=seed,
                        max_iterations=settings.refit_max_iterations, settings=settings)
    angle_keys = set(settings.calibrated_with_angle) | {key for key, _, _ in settings.calibrated_with_angle_offsets}
    reset = [i for i, p in enumerate(calibration.parameters) if p.key in angle_keys]
    if problem.uses_angle and reset:
        # The calibrated base model's column may have absorbed the candidate (a soft column passes for a lash):
        # refit also from the parameter file's values of what only the angle calibrates, and keep the better fit.
        theta1 = theta0.copy()
        for i in reset:
            theta1[i] = calibration.parameters[i].theta(calibration.parameters[i].reference) \
                if calibration.parameters[i].transform == "offset" else 0.0
        other = least_squares(problem, signature.model, parameters, theta1, calibration.fixed,
                              max_iterations=settings.refit_max_iterations, settings=settings)
        if other.rss < fit.rss:
            other.evaluations += fit.evaluations
            fit = other
    return fit


def _compare_refits(problem: Problem, calibration: Fit, refitted: list[Candidate]):
    """(best candidate, effective sample size, rho): each refit's BIC gain over the calibrated base model."""
    best_fit = min((c.refit for c in refitted), key=lambda f: f.rss, default=calibration)
    rho = lag1_autocorrelation(problem, best_fit.weighted)
    n_eff = effective_samples(problem.n, rho)
    for c in refitted:
        c.delta_bic = n_eff * pm.log(calibration.rss / c.refit.rss) - pm.log(n_eff)
    return max(refitted, key=lambda c: c.delta_bic, default=None), n_eff, rho


def reweigh(problem: Problem, fit: Fit, sigma_before: list[np.ndarray]) -> None:
    """Recompute a fit's weighted residuals and Jacobian after the files' attainable errors changed."""
    fit.weighted = problem.weighted(fit.predictions)
    ratio = np.concatenate([old / f.sigma for old, f in zip(sigma_before, problem.files)])
    fit.jacobian = fit.jacobian * ratio[:, None]


def conditions_not_covered(problem: Problem) -> list[tuple[str, str]]:
    covered = {(f.case, f.surface) for f in problem.files}
    return [(c, s) for c in problem.params.case_names for s in SURFACES if (c, s) not in covered]


def separation(problem: Problem, best: Candidate, other: Candidate) -> Separation:
    """Replay both fitted models on the first file's rack under each uncovered condition (module docstring)."""
    rows = differences_by_condition(problem, [(c.signature.model, c.refit.overrides) for c in (best, other)])[0]
    top = max(rows, key=lambda r: r["over_noise_floor"])
    return Separation(other.name, float(other.delta_bic), top["case"], top["surface"],
                      top["predicted_difference_rms_Nm"], top["over_noise_floor"], rows)


def _in_workers(problem: Problem, function, items: list, by_candidate: bool) -> list:
    """`function` over `items` (candidates), spread over the workers if `by_candidate` or the predictions do
    not spread the files; the replays the workers ran are counted."""
    if (problem.parallel_files and not by_candidate) or not forks(len(items), problem.workers):
        return [function(item) for item in items]

    def counted(item):
        before = problem.evaluations
        return function(item), problem.evaluations - before

    out = fork_map(counted, items, problem.workers)
    problem.extra_evaluations += sum(evaluations for _, evaluations in out)
    return [result for result, _ in out]


def estimate_torque_lags(problem: Problem, effects: list[Effect], overrides: dict[str, float],
                         settings: DiagnosisSettings = DEFAULT_SETTINGS) -> float:
    """Search each file's torque channel lag behind its rack channel on the model `effects` with `overrides`
    (with settings.torque_lag_fitted: a grid search around the file's present lag and a parabola through its best
    three) and move the file's lag there where that lowers its weighted residual sum of squares by more than
    log(samples); return the largest move (s). A file fitted on its angle keeps none."""
    if not settings.torque_lag_fitted or settings.torque_lag_max_s <= 0.0:
        return 0.0
    lags = np.arange(-settings.torque_lag_max_s, settings.torque_lag_max_s + 0.5 * settings.torque_lag_step_s,
                     settings.torque_lag_step_s)
    largest = 0.0
    for i, f in enumerate(problem.files):
        if f.uses_angle:
            continue
        replay = problem.replay(effects, i)  # at the file's present replay instants
        sigma = f.sigma_Nm

        def rss(lag: float) -> float:
            try:
                torque = replay.at_times(replay.time_s - lag).torque(overrides)
            except SolverError:  # the solver gave up at these instants: not a lag to keep
                return math.inf
            return float(np.sum(((f.torque_Nm - torque) / sigma) ** 2))

        values = np.array([rss(lag) for lag in lags])
        k = int(np.argmin(values))
        best, best_rss = float(lags[k]), float(values[k])
        if 0 < k < len(lags) - 1 and np.all(np.isfinite(values[k - 1 : k + 2])):
            left, centre, right = values[k - 1 : k + 2]
            curvature = left - 2.0 * centre + right
            if curvature > 0.0:
                vertex = best + 0.5 * settings.torque_lag_step_s * (left - right) / curvature
                at_vertex = rss(vertex)
                if at_vertex < best_rss:
                    best, best_rss = vertex, at_vertex
        at_zero = values[int(np.argmin(np.abs(lags)))]
        if at_zero - best_rss > pm.log(f.n):
            f.torque_lag_s = float(f.torque_lag_s + best)
            largest = max(largest, abs(best))
    return largest


def _lags_moved(problem: Problem, effects: list[Effect], overrides: dict[str, float], settings: DiagnosisSettings,
                progress: Progress, why: str) -> bool:
    """Search the lags again on `effects` with `overrides`; if one moved by a search step or more, say so and drop
    the replays made at the old instants (Problem.forget_replays)."""
    if estimate_torque_lags(problem, effects, overrides, settings) < settings.torque_lag_step_s:
        return False
    progress(f"torque channel behind the rack's{why}: " + ", ".join(
        f"{f.label} {1000.0 * f.torque_lag_s:.1f} ms" for f in problem.files if f.torque_lag_s))
    problem.forget_replays()
    return True


def diagnose(files: list[FileData], params: Parameters, effects=None, registry: dict[str, Effect] | None = None,
             strengths: dict[str, float] | None = None, start: dict[str, float] | None = None,
             settings: DiagnosisSettings = DEFAULT_SETTINGS, workers: int = 1, quiet: bool = True) -> Diagnosis:
    """Calibrate, rank every candidate outside the model, refit the best, give the verdict (module docstring).

    `settings` are the method's (:mod:`parksteer.diagnose.settings`; by default the documented ones).

    `strengths` ({"effect.param": finite-difference step}) are strengths of effects already
    added to the model, calibrated with the base parameters (from `start`, e.g. an earlier fit).

    `workers` > 1 replays independent runs side by side (:mod:`parksteer.diagnose.parallel`; the
    result is the same); unless `quiet`, each step says on stderr where it is.
    """
    for f in files:  # the angle is a second signal where the file has one beside a measured rack, if asked for
        f.uses_angle = settings.use_handwheel_angle and f.angle_rad is not None
        f.replay_uncertainty_rad = f.replay_draws_rad = None
    problem = Problem(files, params, workers=max(int(workers), 1), settings=settings)
    progress = Progress(quiet)
    try:
        result = _diagnose(problem, effects, registry, strengths, start, settings, progress)
        # The lag was searched on the base model, which lacks the named effect: an effect at the reversals (a
        # stiction's breakaway) pulls it off. Searched again with the effect, a lag that moves by a step or more is
        # kept and the diagnosis made again with the lags held.
        if settings.torque_lag_fitted and result.verdict == "missing" and _lags_moved(
                problem, result.best.signature.model, result.best.refit.overrides, settings, progress,
                f" (again, with {result.best.name}; diagnosing again)"):
            held = replace(settings, torque_lag_fitted=False)
            problem.settings = held
            result = _diagnose(problem, effects, registry, strengths, start, held, progress)
            result.settings = problem.settings = settings
        return result
    finally:
        problem.close()


def _diagnose(problem: Problem, effects, registry, strengths, start, settings: DiagnosisSettings,
              progress: Progress) -> Diagnosis:
    clock = time.perf_counter()
    timings: dict[str, float] = {}

    def lap(name: str) -> None:
        nonlocal clock
        now = time.perf_counter()
        timings[name] = now - clock
        clock = now

    files = problem.files
    registry = registry if registry is not None else discover_effects()
    base = effects if isinstance(effects, list) and all(isinstance(e, Effect) for e in effects) \
        else resolve_effects(effects)
    progress(f"{len(files)} file(s), {problem.n} samples, {problem.workers} worker(s): replaying the base model "
             f"and its replay uncertainty ({settings.replay_ensemble_draws} racks per file)")
    if problem.uses_angle:
        progress("handwheel angle fitted beside the torque in " + ", ".join(f.label for f in files if f.uses_angle))
    nominal = problem.predict(base, {})
    problem.estimate_replay_uncertainty(base, start or {}, settings.replay_ensemble_draws,
                                        settings.replay_ensemble_seed)
    lap("nominal_and_replay_uncertainty")

    calibration = calibrate(problem, base, strengths=strengths, start=start, settings=settings,
                            announce=lambda keys: progress("calibrating " + ", ".join(keys)))
    # A lag and the calibrated parameters each absorb part of the other's signature: search again on the new
    # calibration, until no file's lag moves by a search step.
    for _ in range(settings.torque_lag_rounds):
        if not _lags_moved(problem, base, calibration.overrides, settings, progress,
                           " (replay uncertainty and calibration again at the lagged instants)"):
            break
        problem.estimate_replay_uncertainty(base, start or {}, settings.replay_ensemble_draws,
                                            settings.replay_ensemble_seed)
        calibration = calibrate(problem, base, strengths=strengths, start=start, settings=settings)
    lap("calibration")

    testable, untestable = candidate_effects(base, registry)
    floor = fit_statistics(problem, calibration.predictions)["noise_floor_Nm"]
    progress(f"ranking {len(testable)} candidates: " + ", ".join(e.name for e in testable))

    # Many candidates: one worker each (its model prepared once per file). The few refits spread their files.
    def signature_of(effect: Effect) -> Signature:
        signature = probe_signature(problem, base, effect, calibration.overrides,
                                    settings.probe_effect_noise_floors * floor, settings)
        signature.effect, signature.model = None, None  # travel back without the effects
        return signature

    candidates = []
    for effect, signature in zip(testable, _in_workers(problem, signature_of, testable, True)):
        signature.effect, signature.model = effect, sorted([*base, effect], key=lambda e: e.name)
        candidates.append(Candidate(signature, score(signature, calibration)))
    lap("signatures_and_scores")

    hopeful = sorted((c for c in candidates if c.score.removed_rss > 0.0), key=lambda c: -c.score.statistic)
    chosen = hopeful[: settings.refit_count]
    if chosen:
        progress("refitting " + ", ".join(c.name for c in chosen))

    def refit_of(candidate: Candidate) -> Fit:
        fit = refit(problem, calibration, candidate.signature, candidate.score.linear_strength, settings)
        fit.effects = None  # travels back without the effects
        return fit

    for candidate, fit in zip(chosen, _in_workers(problem, refit_of, chosen, False)):
        fit.effects = candidate.signature.model
        candidate.refit = fit
    lap("refits")

    refitted = [c for c in candidates if c.refit is not None]
    best, n_eff, rho = _compare_refits(problem, calibration, refitted)
    if best is not None and best.delta_bic > settings.bic_missing_threshold:
        # The replay's uncertainty was estimated with the base model; with the candidate, the torque may turn
        # more sharply where the rack data are least certain (a breakaway peak at each reversal). Weigh every
        # model by the larger of the two uncertainties and compare again.
        progress(f"{best.name} evidenced: replay uncertainty again with it")
        before = [f.sigma for f in problem.files]
        problem.estimate_replay_uncertainty(best.signature.model, best.refit.overrides,
                                            settings.replay_ensemble_draws, settings.replay_ensemble_seed,
                                            keep_larger=True)
        for fit in [calibration] + [c.refit for c in refitted]:
            reweigh(problem, fit, before)
        best, n_eff, rho = _compare_refits(problem, calibration, refitted)
    lap("selection")

    n = problem.n
    base_rss = calibration.rss
    base_ratio = math.sqrt(base_rss / n)
    excess = base_rss - n
    explained = (base_rss - best.refit.rss) / excess if (best is not None and excess > 0) else None
    after_ratio = math.sqrt(best.refit.rss / n) if best is not None else None
    spread_ratio = trimmed_rms(best.refit.weighted, settings.missing_ceiling_trim) if best is not None else None
    verdict = choose_verdict(base_ratio, best.delta_bic if best is not None else None, after_ratio, explained,
                             settings, spread_ratio)

    separations = []
    if verdict == "missing":
        for c in refitted:
            if c is not best and c.delta_bic >= best.delta_bic - settings.bic_indistinguishable:
                separations.append(separation(problem, best, c))
    lap("separation")
    progress("what these data fix: the calibrated parameters' intervals")
    identified = identification(problem, calibration, settings)
    confounded = confounded_candidates(candidates, settings) if settings.confound_tests else []
    if confounded:
        progress("where the confounded candidates would show: " + ", ".join(c.name for c in confounded))
    lap("identification")
    tested = confound_tests(problem, calibration, confounded)
    lap("confound_tests")
    progress(f"verdict: {verdict}" + (f" {best.name}" if verdict == "missing" else "")
             + f" ({problem.evaluations} replays)")
    return Diagnosis(problem, base, nominal, calibration, candidates, untestable, verdict, best, separations,
                     n_eff, rho, explained, timings, settings, identification=identified,
                     confound_tests=tested)
