"""The peers' own methods on a record's library: the library of weighted terms (:func:`record_library`), PySINDy's
STLSQ in fixed-order arithmetic (:func:`stlsq`), FROLS (:func:`frols_ranking`, :func:`frols`), the verdict their
selection gives (:func:`verdict_of`) and the settings each is tuned over. :mod:`parksteer.experiments.peers` says
what they are compared on and why."""

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
