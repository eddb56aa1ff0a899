"""The diagnosis against its peers: sparse regression of the calibrated residual, on the same records.

A user who has a calibrated model and its residual might not run :func:`parksteer.diagnose.select.diagnose`'s
score test, refits and BIC at all, and reach instead for one of two common tools:

- **STLSQ** (sequentially thresholded least squares, PySINDy's ``STLSQ`` optimizer): regress the residual on a
  library of terms, drop every term whose coefficient is below a threshold, regress again on what is left, until
  nothing changes;
- **FROLS** (forward regression with orthogonal least squares, SysIdentPy's method): rank the terms by their error
  reduction ratio (ERR, the share of the residual's sum of squares each explains once orthogonalised against the
  terms already taken), and stop at the minimum of an information criterion (AIC or BIC). SysIdentPy 0.9.0
  requires ``numpy<=2.3.5`` and does not install beside the project's numpy 2.4.6 (requirements/pipeline.lock),
  so :func:`frols` is this project's own implementation of the same algorithm (its ERR and its criteria as
  SysIdentPy computes them), not SysIdentPy.

Both get what the diagnosis has (:func:`record_library`, from one :class:`~parksteer.diagnose.select.Diagnosis`):
the calibrated base model's weighted residual ((measured - model) / sigma, sigma the attainable error the
diagnosis weights by, so a model at the noise floor leaves RMS 1), and a library of weighted terms, each scaled to
RMS 1 so that a coefficient is the term's RMS contribution in noise floors:

- generic terms built from the record (each file's smoothed rack at the replay's instants): a constant, the
  smoothed sign of the rack speed (``tanh`` with the model's own friction smoothing), the rack speed, the speed
  magnitude, the rack position x, x^2, x^3, |x| x, and sin and cos of one and two times the column angle (rack
  position times the handwheel-to-rack ratio); where the diagnosis fits the handwheel angle too, each generic term
  again on the angle's rows (named ``angle:...``);
- each observable candidate's own signature, the weighted sensitivity the diagnosis scores
  (:attr:`parksteer.diagnose.candidates.Signature.weighted`), named by its effect.

Their answers map onto the diagnosis's verdicts (:func:`verdict_of`): nothing selected is ``adequate``; a
selected candidate signature is ``missing`` that candidate (the one with the largest contribution: coefficient
for STLSQ, ERR for FROLS); only generic terms selected is ``unexplained``. The peers regress the residual as it
is: unlike the score test they do not project the calibrated parameters' sensitivities out of the terms, and
they say nothing about a candidate's sign (a strength that would be negative is still a selected term).
Each peer's setting is tuned over its grid, :data:`STLSQ_SETTINGS` (threshold and ridge) and
:data:`FROLS_SETTINGS` (criterion and ERR tolerance), on records of another seed (:func:`tune`), and scored with
the best setting on the benchmarks' records (:func:`score_method`).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass

import numpy as np

from .. import portable as pm
from ..diagnose.select import Diagnosis

# STLSQ thresholds tried, in noise floors RMS of a term's contribution (a coefficient of the unit-RMS terms)
STLSQ_THRESHOLDS = (0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0)
# STLSQ's ridge (PySINDy's alpha) tried, as a fraction of the rows (each unit-RMS term's own sum of squares): 0 is
# PySINDy's default alpha 0.05, which over thousands of rows barely counts; the others shrink the opposing
# coefficients of terms that nearly make one another (a sign term and a friction candidate's signature), 1 halving
# the coefficient of a term no other term makes
STLSQ_RIDGES = (0.0, 0.01, 0.1, 0.3, 1.0)
STLSQ_DEFAULT_ALPHA = 0.05
STLSQ_SETTINGS = tuple((t, r) for t in STLSQ_THRESHOLDS for r in STLSQ_RIDGES)
STLSQ_MAX_ITERATIONS = 20  # PySINDy's default
# FROLS: (information criterion, ERR tolerance): a term is kept up to the criterion's first minimum and while its
# ERR is at least the tolerance
FROLS_CRITERIA = ("aic", "bic")
FROLS_ERR_TOLERANCES = (0.0, 0.001, 0.003, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3)
FROLS_SETTINGS = tuple((c, t) for c in FROLS_CRITERIA for t in FROLS_ERR_TOLERANCES)
FROLS_MAX_TERMS = 15  # SysIdentPy's n_info_values default: the criterion is evaluated for 1..15 terms
METHODS = ("diagnose", "stlsq", "frols")
METHOD_LABELS = {"diagnose": "parksteer diagnose", "stlsq": "PySINDy STLSQ", "frols": "FROLS (own code after SysIdentPy)"}


@dataclass(frozen=True)
class Library:
    """The peers' regression problem: the weighted residual and the unit-RMS weighted terms (module docstring)."""

    names: tuple[str, ...]
    owners: tuple[str | None, ...]  # the candidate effect a term is the signature of; None for a generic term
    matrix: np.ndarray  # rows x terms, each column of RMS 1
    residual: np.ndarray  # weighted residual of the calibrated base model, in noise floors

    def column(self, name: str) -> np.ndarray:
        return self.matrix[:, self.names.index(name)]


def generic_terms(x: np.ndarray, v: np.ndarray, column_ratio: float, sign_smoothing: float) -> dict[str, np.ndarray]:
    """The generic terms at rack position `x` (m) and speed `v` (m/s): column angle = `column_ratio` x (rad/m),
    smoothed sign tanh(`sign_smoothing` v) (s/m)."""
    theta = column_ratio * x
    return {"constant": np.ones_like(x), "sign(v)": pm.tanh(sign_smoothing * v), "v": v, "|v|": np.abs(v),
            "x": x, "x^2": x**2, "x^3": x**3, "|x|x": np.abs(x) * x, "sin(theta)": pm.sin(theta),
            "cos(theta)": pm.cos(theta), "sin(2theta)": pm.sin(2.0 * theta), "cos(2theta)": pm.cos(2.0 * theta)}


def library_from(residual: np.ndarray, terms: dict[str, np.ndarray], owners: dict[str, str | None]) -> Library:
    """A :class:`Library` of `terms` (weighted columns by name), each scaled to RMS 1; a column that is zero
    (RMS below 1e-12 of the largest) is left out."""
    columns = {k: np.asarray(c, dtype=float) for k, c in terms.items()}
    rms = {k: float(np.sqrt(np.mean(c**2))) for k, c in columns.items()}
    largest = max(rms.values(), default=0.0)
    kept = [k for k in columns if rms[k] > 1e-12 * largest and rms[k] > 0.0]
    matrix = np.column_stack([columns[k] / rms[k] for k in kept]) if kept else np.zeros((len(residual), 0))
    return Library(tuple(kept), tuple(owners.get(k) for k in kept), matrix, np.asarray(residual, dtype=float))


def record_library(diagnosis: Diagnosis) -> Library:
    """The library of one diagnosis's records: its calibrated weighted residual, the generic terms of each file's
    smoothed rack weighted as the residual is, and each observable candidate's weighted signature."""
    problem = diagnosis.problem
    params = problem.params
    ratio = float(params["steering.handwheel_to_rack_ratio"])
    smoothing = float(params["steering.friction_smoothing"])
    blocks: dict[str, list[np.ndarray]] = {}
    for f in problem.files:
        x, v, _ = f.rack.evaluate(f.replay_time_s)
        generic = generic_terms(x, v, ratio, smoothing)
        zeros = np.zeros(f.n)
        sigma = f.sigma  # the torque's, then the angle's, as the residual is stacked
        for name, term in generic.items():
            blocks.setdefault(name, []).append((np.concatenate([term, zeros]) if f.uses_angle else term) / sigma)
            if problem.uses_angle:
                angle = np.concatenate([zeros, term]) / sigma if f.uses_angle else np.zeros(f.m)
                blocks.setdefault(f"angle:{name}", []).append(angle)
    terms = {name: np.concatenate(parts) for name, parts in blocks.items()}
    owners: dict[str, str | None] = {name: None for name in terms}
    for candidate in diagnosis.candidates:
        if candidate.signature.observable:
            terms[candidate.name] = candidate.signature.weighted
            owners[candidate.name] = candidate.name
    return library_from(diagnosis.calibration.weighted, terms, owners)


def portable_stlsq(**options):
    """PySINDy's ``STLSQ`` optimizer with its regressions on the project's fixed-order kernels.

    PySINDy's thresholding loop runs as it is (regress on the terms left, zero the coefficients below the
    threshold, until the support stops changing, then an unbiased least-squares refit on the support). Its three
    linear solves, scikit-learn's ``ridge_regression`` (Cholesky on the normal equations), the initial
    ``np.linalg.lstsq`` and the ``LinearRegression`` of the unbiasing step, go through LAPACK and the BLAS, whose
    results depend on the CPU and the BLAS kernel; here they are the same equations solved by
    :mod:`parksteer.portable`: (X^T X + alpha I) w = X^T y by Gaussian elimination with partial pivoting, and the
    unbiased refit by Householder QR. The initial guess only seeds the first support comparison, where every
    term is in: ones serve as the least-squares solution does."""
    from pysindy.optimizers import STLSQ

    class PortableSTLSQ(STLSQ):
        def _regress(self, x, y, dim, sparse_sub):
            self.iters += 1
            gram = pm.matmul(x.T, x) + self.alpha * np.eye(x.shape[1])
            return pm.solve(gram, pm.matmul(x.T, y))

        def _unbias(self, x, y):
            coef = np.zeros((y.shape[1], x.shape[1]))
            for i in range(self.ind_.shape[0]):
                if np.any(self.ind_[i]):
                    coef[i, self.ind_[i]] = pm.lstsq(x[:, self.ind_[i]], y[:, i])
            self.coef_ = coef

    return PortableSTLSQ(**options)


def stlsq(library: Library, threshold: float, ridge: float = 0.0) -> dict[str, float]:
    """PySINDy's STLSQ (:func:`portable_stlsq`) on the library, its ridge alpha `ridge` times the rows (PySINDy's
    default where 0): {selected term: coefficient (its RMS contribution in noise floors)}."""
    if not library.names:
        return {}
    alpha = ridge * library.residual.size if ridge > 0.0 else STLSQ_DEFAULT_ALPHA
    optimizer = portable_stlsq(threshold=threshold, alpha=alpha, max_iter=STLSQ_MAX_ITERATIONS,
                               normalize_columns=False, initial_guess=np.ones((1, len(library.names))))
    with warnings.catch_warnings():  # "eliminated all coefficients" is the answer adequate, not a fault
        warnings.simplefilter("ignore", UserWarning)
        optimizer.fit(library.matrix, library.residual)
    coefficients = np.asarray(optimizer.coef_, dtype=float).reshape(-1)
    return {name: float(c) for name, c in zip(library.names, coefficients) if c != 0.0}


@dataclass(frozen=True)
class FrolsRanking:
    """FROLS's forward ranking: the terms in the order taken, each one's ERR, and the criteria after each."""

    names: tuple[str, ...]
    err: tuple[float, ...]
    aic: tuple[float, ...]
    bic: tuple[float, ...]


def frols_ranking(library: Library, max_terms: int = FROLS_MAX_TERMS) -> FrolsRanking:
    """Orthogonal forward regression with the error reduction ratio (Billings; SysIdentPy's FROLS): at each step
    the term whose part orthogonal to the terms taken (classical Gram-Schmidt) explains the largest share
    ERR = (w.y)^2 / ((w.w)(y.y)) of the residual's sum of squares. After k terms, AIC = n ln(s2) + 2 k and
    BIC = n ln(s2) + k ln(n), s2 the variance (ddof 1) of what the least-squares fit on the k terms leaves
    (SysIdentPy's formulas; it fits by recursive least squares by default, here exactly)."""
    y = library.residual
    n = y.size
    yy = pm.dot(y, y)
    remaining = list(range(len(library.names)))
    basis: list[np.ndarray] = []
    names, errs, aics, bics = [], [], [], []
    left = y.copy()
    for _ in range(min(max_terms, len(remaining))):
        best, best_err, best_w = None, -1.0, None
        for j in remaining:
            w = library.matrix[:, j].copy()
            for q in basis:
                w -= pm.dot(q, w) * q
            ww = pm.dot(w, w)
            if ww <= 1e-10 * n:  # a term the ones taken already make
                continue
            err = pm.dot(w, y) ** 2 / (ww * yy)
            if err > best_err:
                best, best_err, best_w = j, err, w / math.sqrt(ww)
        if best is None:
            break
        remaining.remove(best)
        basis.append(best_w)
        left = left - pm.dot(best_w, left) * best_w
        variance = max(float(np.var(left, ddof=1)), 1e-300)
        k = len(basis)
        names.append(library.names[best])
        errs.append(best_err)
        aics.append(n * pm.log(variance) + 2.0 * k)
        bics.append(n * pm.log(variance) + k * pm.log(n))
    return FrolsRanking(tuple(names), tuple(errs), tuple(aics), tuple(bics))


def frols(ranking: FrolsRanking, criterion: str, err_tolerance: float) -> dict[str, float]:
    """FROLS's selection from `ranking`: the terms up to the `criterion`'s first minimum (SysIdentPy's
    ``get_min_info_value``: the terms before the criterion first rises; at least one), then cut at the first
    whose ERR is below `err_tolerance`: {term: ERR}. SysIdentPy's own ``err_tol`` stops once the ERRs add up to
    it and always keeps a term; the per-term floor is what lets FROLS answer that nothing is missing."""
    values = ranking.aic if criterion == "aic" else ranking.bic
    if not values:
        return {}
    rises = np.flatnonzero(np.diff(values) > 0)
    order = int(rises[0]) + 1 if rises.size else len(values)
    selected = {}
    for name, err in zip(ranking.names[:order], ranking.err[:order]):
        if err < err_tolerance:
            break
        selected[name] = err
    return selected


def verdict_of(selected: dict[str, float], library: Library) -> tuple[str, str | None]:
    """(verdict, named effect) of a peer's selection {term: weight}: nothing is ``adequate``; a candidate's
    signature is ``missing`` the candidate of the largest |weight| among them; only generic terms is
    ``unexplained``."""
    if not selected:
        return "adequate", None
    owner = dict(zip(library.names, library.owners))
    named = [(abs(w), owner[t]) for t, w in selected.items() if owner.get(t) is not None]
    if not named:
        return "unexplained", None
    return "missing", max(named)[1]


def peer_answers(library: Library) -> dict:
    """Every peer's answer at every setting of its grid, and each peer's own time (s) for the whole grid:
    {"stlsq": {"threshold=0.3 ridge=0n": {...}}, "frols": {"aic err>=0.01": {...}}, "time_s": {...}}."""
    import pysindy.optimizers  # noqa: F401  (imported before the clock starts: once per process, not per record)

    answers: dict = {"stlsq": {}, "frols": {}, "time_s": {}}
    start = time.perf_counter()
    for threshold, ridge in STLSQ_SETTINGS:
        selected = stlsq(library, threshold, ridge)
        verdict, effect = verdict_of(selected, library)
        answers["stlsq"][setting_label("stlsq", (threshold, ridge))] = {"verdict": verdict, "effect": effect,
                                                                        "selected": selected}
    answers["time_s"]["stlsq"] = (time.perf_counter() - start) / len(STLSQ_SETTINGS)  # one fit
    start = time.perf_counter()
    ranking = frols_ranking(library)
    ranked = time.perf_counter() - start
    for criterion, tolerance in FROLS_SETTINGS:
        selected = frols(ranking, criterion, tolerance)
        verdict, effect = verdict_of(selected, library)
        answers["frols"][setting_label("frols", (criterion, tolerance))] = {"verdict": verdict, "effect": effect,
                                                                            "selected": selected}
    answers["time_s"]["frols"] = ranked  # one ranking serves every setting
    answers["frols_ranking"] = [{"term": t, "err": e, "aic": a, "bic": b}
                                for t, e, a, b in zip(ranking.names, ranking.err, ranking.aic, ranking.bic)]
    return answers


def setting_label(method: str, setting) -> str:
    if method == "stlsq":
        threshold, ridge = setting
        return f"threshold={threshold:g} ridge={ridge:g}n"
    criterion, tolerance = setting
    return f"{criterion} err>={tolerance:g}"


def settings_of(method: str) -> list[str]:
    grid = STLSQ_SETTINGS if method == "stlsq" else FROLS_SETTINGS
    return [setting_label(method, s) for s in grid]


# --- one case: the diagnosis and its peers on the same records ------------------------------------------------

def case_result(truth: dict, diagnosis: Diagnosis, result: dict, wall_s: float, split: str, benchmark: str) -> dict:
    """A case's record for the comparison: the truth, the diagnosis's answer (`result` its JSON dict, with the
    outcome of its benchmark), the peers' answers on the same residual and signatures, the times."""
    library = record_library(diagnosis)
    answers = peer_answers(library)
    timings = diagnosis.timings_s
    # what the peers need and a diagnosis computes anyway: replay uncertainty, calibration, signatures
    upstream = sum(timings.get(k, 0.0) for k in ("nominal_and_replay_uncertainty", "calibration", "torque_lag",
                                                  "signatures_and_scores"))
    return {
        "name": truth["name"], "split": split, "benchmark": benchmark, "truth": truth,
        "diagnosis": {"verdict": result["verdict"], "effect": result.get("effect"),
                      "indistinguishable": [s["effect"] for s in result["indistinguishable"]],
                      "outcome": _benchmark_outcome(benchmark, truth, result)},
        "terms": list(library.names), "rows": int(library.residual.size),
        "residual_rms": float(np.sqrt(np.mean(library.residual**2))),
        "stlsq": answers["stlsq"], "frols": answers["frols"], "frols_ranking": answers["frols_ranking"],
        "time_s": {"diagnose": wall_s, "upstream": upstream, "stlsq": answers["time_s"]["stlsq"],
                   "frols": answers["time_s"]["frols"]},
        # model replays (the same on any machine): the whole diagnosis's, and those up to its signatures
        "replays": {"diagnose": diagnosis.replays,
                    "upstream": diagnosis.replays_by_stage["signatures_and_scores"]},
    }


def _benchmark_outcome(benchmark: str, truth: dict, result: dict) -> dict:
    if benchmark == "outclass":
        from .outclass import outcome
    else:
        from .variations import outcome
    row = outcome(truth, result)
    keep = ("named", "false_alarm", "relation", "confident_wrong", "adequate_at_3_steps", "said", "verdict")
    return {k: getattr(row, k) for k in keep if hasattr(row, k)}


def diagnose_case(params, folder, truth: dict, benchmark: str, split: str) -> dict:
    """Diagnose the records of one benchmark case (its files in `folder`, in the truth's order) as its benchmark
    does, and run the peers on the same residual and signatures (:func:`case_result`)."""
    from dataclasses import replace
    from pathlib import Path

    from ..synthetic.datasets import file_name
    from ..synthetic.variations import variation_by_name
    from .benchmark import BENCHMARK_SETTINGS
    from ..diagnose.intake import Request, intake
    from ..reporting.report import diagnosis_dict

    settings = BENCHMARK_SETTINGS
    if benchmark == "variations":  # as variations.run_case diagnoses it
        variation = variation_by_name(truth["variation"])
        settings = replace(settings, use_handwheel_angle=variation.uses_angle,
                           torque_lag_fitted=variation.logger.torque_lag_s > 0.0)
    paths = [Path(folder) / file_name(f["case"], f["surface"]) for f in truth["files"]]
    start = time.perf_counter()
    diagnosis = intake(Request(paths, params, settings=settings)).diagnose()
    wall = time.perf_counter() - start
    return case_result(truth, diagnosis, diagnosis_dict(diagnosis), wall, split, benchmark)


# --- scoring ------------------------------------------------------------------------------------------------

def answer_of(case: dict, method: str, setting: str | None) -> tuple[str, str | None]:
    if method == "diagnose":
        return case["diagnosis"]["verdict"], case["diagnosis"]["effect"]
    entry = case[method][setting]
    return entry["verdict"], entry["effect"]


def _named(case: dict, method: str, verdict: str, effect: str | None) -> bool:
    hidden = case["truth"]["hidden"]
    if method == "diagnose":  # the variation benchmark's own count: named first or in the reported group
        return bool(case["diagnosis"]["outcome"].get("named"))
    return verdict == "missing" and effect == hidden


def score_method(cases: list[dict], method: str, setting: str | None = None) -> dict:
    """One method's numbers over `cases`: hidden library effects named (of those of at least NAMED_MIN_STEPS),
    nulls called adequate, and on the out-of-class rivals what it said (closest or related candidate, unrelated
    candidate, unexplained, adequate). A peer's unrelated candidate is a confident wrong answer (a peer reports no
    doubt beside it); the diagnosis's is confident when its BIC margin is beyond its indistinguishable band
    (:func:`parksteer.experiments.outclass.outcome`)."""
    from .variations import NAMED_MIN_STEPS

    hidden = [c for c in cases if c["benchmark"] == "variations" and c["truth"]["hidden"] is not None
              and (c["truth"]["steps_requested"] or 0.0) >= NAMED_MIN_STEPS]
    nulls = [c for c in cases if (c["benchmark"] == "variations" and c["truth"]["hidden"] is None)
             or (c["benchmark"] == "outclass" and c["truth"]["kind"] == "null")]
    rivals = [c for c in cases if c["benchmark"] == "outclass" and c["truth"]["kind"] == "rival"]
    named = sum(_named(c, method, *answer_of(c, method, setting)) for c in hidden)
    adequate = sum(answer_of(c, method, setting)[0] == "adequate" for c in nulls)
    relations = {"closest or related": 0, "unrelated": 0, "unexplained": 0, "adequate": 0}
    confident_wrong = 0
    for c in rivals:
        verdict, effect = answer_of(c, method, setting)
        related = {c["truth"].get("closest")} | set(c["truth"].get("related") or ())
        if verdict != "missing":
            relations[verdict] += 1
        elif effect in related:
            relations["closest or related"] += 1
        else:
            relations["unrelated"] += 1
            confident_wrong += 1 if method != "diagnose" else int(bool(c["diagnosis"]["outcome"]["confident_wrong"]))
    times = [c["time_s"]["diagnose"] if method == "diagnose" else c["time_s"][method] for c in cases]
    upstream = [c["time_s"]["upstream"] for c in cases]
    replays = [c["replays"]["diagnose"] if method == "diagnose" else 0 for c in cases]
    replays_upstream = [c["replays"]["diagnose" if method == "diagnose" else "upstream"] for c in cases]
    return {
        "method": method, "label": METHOD_LABELS[method], "setting": setting,
        "named": [named, len(hidden)], "named_rate": named / len(hidden) if hidden else None,
        "null_adequate": [adequate, len(nulls)], "null_adequate_rate": adequate / len(nulls) if nulls else None,
        "outclass": relations, "outclass_rivals": len(rivals), "confident_wrong": confident_wrong,
        # model replays a record (the same on any machine): a peer's own are none, it regresses what it is given
        "replays_median": _median_count(replays), "replays_with_upstream_median": _median_count(replays_upstream),
        # machine times (benchmarks/bench_peers.py prints them; the paper quotes the replays)
        "time_s_median": float(np.median(times)) if times else None,
        # a peer needs the calibrated residual and the signatures: the diagnosis's own steps up to its scores
        "time_with_upstream_s_median": (float(np.median(np.add(times, upstream))) if method != "diagnose"
                                        else (float(np.median(times)) if times else None)),
    }


def _median_count(counts: list[int]) -> int | float | None:
    """The median of whole counts: whole, or a half where it falls between two."""
    if not counts:
        return None
    median = float(np.median(counts))
    return int(median) if median.is_integer() else median


def tuning_score(numbers: dict) -> float:
    """What a setting is tuned for: the mean of the named rate and the nulls' adequate rate (each counted where
    the split has cases of its kind)."""
    rates = [r for r in (numbers["named_rate"], numbers["null_adequate_rate"]) if r is not None]
    return float(np.mean(rates)) if rates else 0.0


def tune(cases: list[dict], method: str) -> tuple[str, list[dict]]:
    """The setting of `method`'s grid that scores best on the tuning `cases` (:func:`tuning_score`; among equals,
    the most conservative: the largest threshold and ridge, the largest ERR tolerance, BIC before AIC), and every
    setting's numbers."""
    table = []
    for setting in settings_of(method):
        numbers = score_method(cases, method, setting)
        table.append({"setting": setting, "score": tuning_score(numbers), "named": numbers["named"],
                      "null_adequate": numbers["null_adequate"]})
    best = max(range(len(table)), key=lambda i: (table[i]["score"], _conservative(method, i)))
    return table[best]["setting"], table


def _conservative(method: str, index: int) -> tuple:
    if method == "stlsq":
        return STLSQ_SETTINGS[index]
    criterion, tolerance = FROLS_SETTINGS[index]
    return (tolerance, criterion == "bic")


def compare(cases: list[dict]) -> dict:
    """The comparison: each peer tuned on the tuning split, then every method scored on the evaluation split."""
    tuning = [c for c in cases if c["split"] == "tuning"]
    evaluation = [c for c in cases if c["split"] == "evaluation"]
    grids, rows = {}, [score_method(evaluation, "diagnose")]
    for method in ("stlsq", "frols"):
        best, table = tune(tuning, method)
        grids[method] = {"best": best, "tuning": table,
                         "evaluation": [{"setting": s, **_brief(score_method(evaluation, method, s))}
                                        for s in settings_of(method)]}
        # every setting tied with the best on the tuning split, and the spread of their evaluation numbers: the
        # tie-break's share of the result
        top = max(row["score"] for row in table)
        tied = [e for row, e in zip(table, grids[method]["evaluation"]) if row["score"] == top]
        count = {"named": lambda e: e["named"][0], "null_adequate": lambda e: e["null_adequate"][0],
                 "confident_wrong": lambda e: e["confident_wrong"]}
        grids[method]["tied_best"] = [e["setting"] for e in tied]
        grids[method]["tied_best_evaluation"] = {key: [min(map(f, tied)), max(map(f, tied))]
                                                 for key, f in count.items()}
        if method == "stlsq":  # PySINDy's own ridge: the best of its thresholds on the tuning split
            default = [row for row, (_t, ridge) in zip(table, STLSQ_SETTINGS) if ridge == 0.0]
            grids[method]["default_ridge_best"] = max(default, key=lambda row: row["score"])
        rows.append(score_method(evaluation, method, best))
    rows_tuning = [score_method(tuning, "diagnose")] + [score_method(tuning, m, grids[m]["best"])
                                                         for m in ("stlsq", "frols")]
    return {"methods": rows, "tuning_split": rows_tuning, "grids": grids,
            "records": {"tuning": len(tuning), "evaluation": len(evaluation)},
            "peer_wins": peer_wins(rows),
            "cases": [_case_row(c, grids) for c in evaluation]}


def _brief(numbers: dict) -> dict:
    return {k: numbers[k] for k in ("named", "null_adequate", "confident_wrong")}


def peer_wins(rows: list[dict]) -> list[str]:
    """Where a peer does better than the diagnosis, in words (empty if nowhere)."""
    ours = rows[0]
    wins = []
    for row in rows[1:]:
        if (row["named_rate"] or 0.0) > (ours["named_rate"] or 0.0):
            wins.append(f"{row['label']} names more hidden effects ({row['named'][0]}/{row['named'][1]} against "
                        f"{ours['named'][0]}/{ours['named'][1]})")
        if (row["null_adequate_rate"] or 0.0) > (ours["null_adequate_rate"] or 0.0):
            wins.append(f"{row['label']} calls more nulls adequate")
        if row["outclass"]["closest or related"] > ours["outclass"]["closest or related"]:
            wins.append(f"{row['label']} names the closest or a related candidate for more out-of-class rivals "
                        f"({row['outclass']['closest or related']} of {row['outclass_rivals']} against "
                        f"{ours['outclass']['closest or related']})")
        if row["confident_wrong"] < ours["confident_wrong"]:
            wins.append(f"{row['label']} gives fewer confident wrong answers out of class")
        if row["replays_with_upstream_median"] < ours["replays_median"]:
            wins.append(f"{row['label']} needs fewer model replays: {row['replays_with_upstream_median']} a record "
                        f"for the replay uncertainty, calibration and signatures it regresses, against the "
                        f"diagnosis's {ours['replays_median']}")
    return wins


def _case_row(case: dict, grids: dict) -> dict:
    row = {"name": case["name"], "benchmark": case["benchmark"], "hidden": case["truth"]["hidden"] or "nothing"}
    for method in METHODS:
        verdict, effect = answer_of(case, method, grids.get(method, {}).get("best"))
        row[method] = effect if verdict == "missing" else verdict
    return row


# --- the pipeline's jobs: a case's peers written beside nothing else ----------------------------------------

def tuning_design(design, seed: int):
    """The tuning split: the variation benchmark's grid with records of another `seed`."""
    from dataclasses import replace

    return replace(design, seed=int(seed))


def run_tuning_case(params, design, name: str, folder) -> dict:
    """Make tuning case `name`'s records as the variation benchmark makes its own (other seed), write them into
    `folder`, and diagnose them from the files with the peers beside (:func:`diagnose_case`)."""
    from pathlib import Path

    from ..measure.io import write_measurement
    from ..synthetic.datasets import file_name
    from .variations import case_records

    truth, records, _settings = case_records(params, design, name)
    Path(folder).mkdir(parents=True, exist_ok=True)
    for case, surface, measurement in records:
        write_measurement(Path(folder) / file_name(case, surface), measurement, params)
    return diagnose_case(params, folder, truth, "variations", "tuning")


def run_peer_batch(parameters_path, jobs: list[str], folder, tuning=None) -> None:
    """Run one job's cases into `folder` (<split>__<case>.peers.json each: a tuning case has its evaluation twin's
    name). A job is ``tuning:<case name>`` (made with the `tuning` design, its records in folder/tuning/<case>) or ``variations:<truth file>`` / ``outclass:<truth file>`` (a
    benchmark case's truth, its records in the folder of its name beside it)."""
    import json
    from pathlib import Path

    from ..errors import UsageError
    from ..parameters import load_parameters
    from ..tables import write_json

    params = load_parameters(parameters_path)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    for job in jobs:
        kind, _, what = job.partition(":")
        if kind == "tuning":
            if tuning is None:
                raise UsageError(f"peers job {job!r}: no tuning design given")
            result = run_tuning_case(params, tuning, what, out / "tuning" / what)
        elif kind in ("variations", "outclass"):
            path = Path(what)
            truth = json.loads(path.read_text(encoding="utf-8"))
            result = diagnose_case(params, path.parent / truth["name"], truth, kind, "evaluation")
            written = path.with_name(f"{truth['name']}.diagnosis.json")  # the benchmark's own diagnosis
            if written.exists():
                said = json.loads(written.read_text(encoding="utf-8"))
                result["diagnosis"]["benchmark_said"] = said["effect"] if said["verdict"] == "missing" \
                    else said["verdict"]
        else:
            raise UsageError(f"peers job {job!r}: not tuning:, variations: or outclass:")
        write_json(out / peers_file_name(result["split"], result["name"]), result)


def peers_beside(benchmark: str):
    """The `on_diagnosis` of the variation or out-of-class benchmark's batch (`benchmark`): each case's peers run on
    the diagnosis the batch has just made, written beside its diagnosis as ``evaluation__<case>.peers.json``, the
    record :func:`run_peer_batch` would make by diagnosing the written files again (the same records and settings,
    so the same diagnosis): the comparison's evaluation split costs no replay of its own."""
    import json
    from pathlib import Path

    from ..tables import write_json

    def write(diagnosis: Diagnosis, result: dict, truth_path, diagnosis_path) -> None:
        truth = json.loads(Path(truth_path).read_text(encoding="utf-8"))  # as a peers job reads it back
        record = case_result(truth, diagnosis, result, result["cost"]["wall_s"], "evaluation", benchmark)
        record["diagnosis"]["benchmark_said"] = result["effect"] if result["verdict"] == "missing" \
            else result["verdict"]
        write_json(Path(diagnosis_path).with_name(peers_file_name("evaluation", truth["name"])), record)

    return write


def peers_file_name(split: str, name: str) -> str:
    return f"{split}__{name}.peers.json"


def read_cases(paths) -> list[dict]:
    """The cases' peers files, in name order within each split."""
    import json
    from pathlib import Path

    cases = [json.loads(Path(p).read_text(encoding="utf-8")) for p in paths]
    return sorted(cases, key=lambda c: (c["split"], c["benchmark"], c["name"]))
