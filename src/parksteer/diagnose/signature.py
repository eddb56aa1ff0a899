"""The residual's signature: what kind of effect the calibrated model lacks, read off the residual's shape.

:func:`signature_from_axes` regresses the calibrated model's weighted torque residual
``w_i = (measured_i - model_i) / sigma_i`` on nested bases along the axes of
:mod:`parksteer.diagnose.signature_axes` (dissipative, elastic, direction-dependent, speed, column, dissipative x
column), by weighted least squares (:func:`parksteer.portable.lstsq`). Each basis competes with the null by the
diagnosis's information criterion, ``BIC = n_eff ln(RSS / n) + k ln(n_eff)`` with ``n_eff`` from the lag-1
autocorrelation (:func:`parksteer.diagnose.statistics.effective_samples`); the lowest names the class, none when no
basis gains ``bic_missing_threshold``. Every axis gets its share of the weighted sum of squares and its
likelihood-ratio significance ``LR = Delta RSS n_eff / n`` against chi-square(k) (:func:`parksteer.portable.chi2_survival`).
A handwheel torque residual is read as a rack force through the handwheel-to-rack ratio (the Hooke joint's ripple
left out of this reading). :func:`signature_of` reads the axes off a diagnosis's files and calibrated predictions;
the result is frozen. The bases, the classes and what each means: docs/signature.md.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..measure.phases import PHASES
from ..parameters import Parameters
from .settings import DEFAULT_SETTINGS, DiagnosisSettings
from .signature_axes import Axes, Basis, axes_of, bases, rbf, smooth_sign, steering_values
from .statistics import bic_gain, effective_samples, pooled_lag1

CLASSES = ("dissipative", "elastic", "direction", "speed", "column", "dissipative_column")
WHERE = {"dissipative": "rack", "elastic": "rack", "direction": "rack", "speed": "rack", "column": "column",
         "dissipative_column": "column"}
# the classes whose suggested effect is a torque on the column shaft (the others: a force on the rack)
COLUMN_CLASSES = frozenset(c for c, where in WHERE.items() if where == "column")




@dataclass(frozen=True)
class AxisShare:
    """One axis: the share of the residual's weighted sum of squares it removes, and its significance."""

    axis: str
    columns: int
    share: float  # of the weighted residual sum of squares
    excess_share: float | None  # of the part above the noise (RSS - n); None when there is none
    statistic: float  # LR = Delta RSS n_eff / n
    p_value: float
    significant: bool


@dataclass(frozen=True)
class ModelScore:
    family: str
    label: str
    columns: int
    rss: float
    delta_bic: float  # gain over the null (positive: better)


@dataclass(frozen=True)
class Signature:
    """The residual's signature (module docstring): the axes' shares, the models' BIC gains, the class, its
    fitted shape and one sentence."""

    samples: int
    rss: float  # weighted residual sum of squares of the calibrated model
    rho: float
    n_eff: float
    axes: tuple[AxisShare, ...]
    models: tuple[ModelScore, ...]
    effect_class: str | None  # one of CLASSES, or None: no structure beyond the noise
    best: Basis | None
    coefficients: tuple[float, ...]  # of the best basis, N m per unit column
    sentence: str
    numbers: dict = field(default_factory=dict)
    indistinguishable: tuple[str, ...] = ()  # other classes within bic_indistinguishable of the best

    def as_dict(self) -> dict:
        """Plain JSON."""
        return {
            "class": self.effect_class,
            "where": WHERE.get(self.effect_class) if self.effect_class else None,
            "model": self.best.label if self.best is not None else None,
            "sentence": self.sentence,
            "numbers": self.numbers,
            "indistinguishable": list(self.indistinguishable),
            "samples": self.samples,
            "rho": self.rho,
            "n_eff": self.n_eff,
            "axes": [{"axis": a.axis, "columns": a.columns, "share": a.share, "excess_share": a.excess_share,
                      # the p-value goes through the C library's exp and log (scipy's chi-square), whose last
                      # digits may differ between machines: three significant digits are what it says
                      "statistic": a.statistic, "p_value": float(f"{a.p_value:.3g}"), "significant": a.significant}
                     for a in self.axes],
            "models": [{"family": m.family, "label": m.label, "columns": m.columns, "delta_bic": m.delta_bic}
                       for m in self.models],
        }


def _fit(columns: np.ndarray, weighted: np.ndarray, sigma: np.ndarray, nuisance: np.ndarray | None = None
         ) -> tuple[np.ndarray, float]:
    """Weighted least squares of the weighted residual on `columns` / sigma and the `nuisance` columns (already
    weighted): (the coefficients of `columns`, leftover RSS)."""
    design = columns / sigma[:, None]
    k = design.shape[1]
    if nuisance is not None and nuisance.shape[1]:
        design = np.column_stack([design, nuisance])
    coefficients = pm.lstsq(design, weighted)
    left = weighted - pm.matmul(design, coefficients)
    return coefficients[:k], pm.dot(left, left)


def _axis_groups(axes: Axes, models: list[Basis]) -> list[tuple[str, np.ndarray]]:
    """The axes reported with their shares: each family's richest basis, the column orders one by one, the cycle
    phase (each phase's mean and its mean times the sign of the speed) and, where the records differ in load
    case or surface, the record (each record's mean and mean times the sign)."""
    richest: dict[str, Basis] = {}
    for b in models:
        if b.family != "column" and (b.family not in richest or b.columns.shape[1] > richest[b.family].columns.shape[1]):
            richest[b.family] = b
    names = {"dissipative": "odd in rack speed (dissipative), along the stroke",
             "elastic": "rack position, even in speed (elastic)",
             "direction": "while moving, not reversing (direction-dependent)",
             "speed": "odd in rack speed, by speed magnitude"}
    out = [(names[f], richest[f].columns) for f in ("dissipative", "elastic", "direction", "speed") if f in richest]
    out += [(f"column angle, {b.label}", b.columns) for b in models if b.family == "column" and len(b.orders) == 1]
    out += [(f"odd in rack speed times column angle, {b.label}", b.columns) for b in models
            if b.family == "dissipative_column" and len(b.orders) == 1]
    s = smooth_sign(axes)
    present = [p for p in PHASES if np.any(axes.phase == p)]
    if present:
        indicator = np.column_stack([(axes.phase == p).astype(float) for p in present])
        out.append(("cycle phase (" + ", ".join(present) + ")", np.column_stack([indicator, indicator * s[:, None]])))
    if len(set(axes.conditions)) > 1:
        records = np.column_stack([(axes.record == r).astype(float) for r in range(len(axes.conditions))])
        out.append(("load case and surface across records", np.column_stack([records, records * s[:, None]])))
    return out


def _in_line(function: Callable, items: list) -> list:
    return [function(item) for item in items]


def signature_from_axes(axes: Axes, settings: DiagnosisSettings = DEFAULT_SETTINGS,
                        calibrated_rack_friction_N: float | None = None, nuisance: np.ndarray | None = None,
                        map_fits: Callable[[Callable, list], list] = _in_line) -> Signature:
    """The signature of the residual on `axes` (module docstring). `calibrated_rack_friction_N`, if given, is
    what a dissipative change along the stroke is stated relative to.

    `nuisance` (samples x p, in weighted units): the calibration's sensitivities d(model / sigma)/d(theta). Every
    basis is fitted beside them, so that a shape counts by what the calibrated parameters cannot take up when
    they are fitted again with it (as the suggested effect will be): the calibration has already absorbed the
    part of the truth along its own directions, and the residual is the truth less that projection, which a
    basis alone would have to mimic.

    `map_fits(function, items)` gives ``[function(item) for item in items]``: the least-squares fits, independent of
    each other, may run side by side (:meth:`parksteer.diagnose.engine.ReplayEngine.map`), with the same numbers."""
    sigma = np.asarray(axes.sigma_Nm, dtype=float)
    weighted = np.asarray(axes.residual_Nm, dtype=float) / sigma
    n = weighted.size
    if nuisance is not None and nuisance.shape[0] != n:
        raise UsageError(f"signature: {nuisance.shape[0]} rows of sensitivities for {n} samples")
    models = bases(axes, settings)
    groups = _axis_groups(axes, models)
    design = np.column_stack([b.columns for b in models]) / sigma[:, None]
    if nuisance is not None:
        design = np.column_stack([design, nuisance])

    def fitted(columns: np.ndarray | None):  # None: every basis together (the largest fit, so sent first)
        return pm.lstsq(design, weighted) if columns is None else _fit(columns, weighted, sigma, nuisance)

    blocks = [np.zeros((n, 0)), *(b.columns for b in models), *(columns for _, columns in groups)]
    together, (_, rss0), *rest = map_fits(fitted, [None, *blocks])
    fits, group_fits = rest[:len(models)], rest[len(models):]
    left = weighted - pm.matmul(design, together)
    rho = pooled_lag1(left[axes.record == r] for r in np.unique(axes.record))
    n_eff = effective_samples(n, rho)

    scores = []
    for b, (_, rss) in zip(models, fits):
        k = b.columns.shape[1]
        gain = bic_gain(rss0, rss, n_eff, k)
        scores.append(ModelScore(b.family, b.label, k, float(rss), float(gain)))
    shares = []
    excess = rss0 - n
    for (name, columns), (_, rss) in zip(groups, group_fits):
        k = columns.shape[1]
        statistic = (rss0 - rss) * n_eff / n
        p = pm.chi2_survival(statistic, k)
        shares.append(AxisShare(name, k, float((rss0 - rss) / rss0), float((rss0 - rss) / excess) if excess > 0 else None,
                                float(statistic), p, p < settings.signature.significance))
    best_index = max(range(len(models)), key=lambda i: (scores[i].delta_bic, -scores[i].columns))
    best_score = scores[best_index]
    if best_score.delta_bic <= settings.bic_missing_threshold:
        sentence = (f"no structure beyond the noise: no basis gains more than {settings.bic_missing_threshold:g} in BIC "
                    f"(best: {best_score.family}, {best_score.label}, {best_score.delta_bic:.1f})")
        return Signature(n, float(rss0), float(rho), float(n_eff), tuple(shares), tuple(scores), None, None, (),
                         sentence, {"best_delta_bic": best_score.delta_bic})
    best = models[best_index]
    coefficients = fits[best_index][0]
    sentence, numbers = describe(axes, best, coefficients, calibrated_rack_friction_N)
    group = tuple(sorted({m.family for m in scores if m.family != best.family
                          and m.delta_bic >= best_score.delta_bic - settings.bic_indistinguishable}))
    if group:
        sentence += (f"; these data cannot tell it from the {' or '.join(group)} class (BIC within "
                     f"{settings.bic_indistinguishable:g})")
    numbers.update({"delta_bic": best_score.delta_bic,
                    "share": float((rss0 - best_score.rss) / rss0),
                    "excess_share": float((rss0 - best_score.rss) / excess) if excess > 0 else None})
    return Signature(n, float(rss0), float(rho), float(n_eff), tuple(shares), tuple(scores), best.family, best,
                     tuple(float(c) for c in coefficients), sentence, numbers, group)


def shape_on(best: Basis, coefficients, grid: np.ndarray) -> np.ndarray:
    """The fitted shape (N m at the handwheel) of a knotted basis on `grid` (its axis's units)."""
    return pm.matmul(rbf(grid, best.knots, best.width), np.asarray(coefficients, dtype=float))


def _localised(grid: np.ndarray, values: np.ndarray) -> tuple[float, float, float, float]:
    """(where the shape departs most from its median, by how much, its half width at half that departure, the
    median): a bump (or a dip) and its extent."""
    median = float(np.median(values))
    departure = values - median
    i = int(np.argmax(np.abs(departure)))
    peak = float(departure[i])
    inside = np.abs(departure) >= 0.5 * abs(peak)
    lo = i
    while lo > 0 and inside[lo - 1]:
        lo -= 1
    hi = i
    while hi < len(grid) - 1 and inside[hi + 1]:
        hi += 1
    return float(grid[i]), peak, 0.5 * float(grid[hi] - grid[lo]), median


def describe(axes: Axes, best: Basis, coefficients, friction_N: float | None) -> tuple[str, dict]:
    """One sentence for the best model, and the numbers behind it (rack forces in N: G times the handwheel
    torque)."""
    G = axes.ratio_rad_m
    c = np.asarray(coefficients, dtype=float)
    if best.family == "dissipative_column":
        return _describe_dissipative_column(best, c)
    if best.family == "column":
        amplitudes = {m: float(pm.hypot(c[2 * i], c[2 * i + 1])) for i, m in enumerate(best.orders)}
        top = max(amplitudes, key=amplitudes.get)
        orders = " and ".join(f"{m} per column turn ({amplitudes[m]:.3g} N m)" for m in best.orders)
        return (f"a torque on the steering column periodic in the column angle, {orders}",
                {"orders": list(best.orders), "amplitudes_Nm": {str(m): a for m, a in amplitudes.items()},
                 "dominant_order": top})
    if best.family == "speed":
        grid = np.linspace(0.0, 1.25, 26)
        values = G * shape_on(best, c, grid)
        scale = float(np.quantile(np.abs(axes.speed_m_s), 0.9))
        low, high = float(np.mean(values[grid <= 0.3])), float(np.mean(values[(grid >= 0.7) & (grid <= 1.0)]))
        kind = "growing with the speed (viscous-like)" if abs(high) > abs(low) else \
            "falling with the speed (Stribeck-like)"
        return (f"a dissipative force on the rack {kind}: {low:.3g} N at low speed, {high:.3g} N near "
                f"{1000 * scale:.3g} mm/s", {"low_speed_force_N": low, "high_speed_force_N": high,
                                             "speed_90_m_s": scale, "kind": kind})
    low, high = float(np.min(axes.rack_m)), float(np.max(axes.rack_m))
    grid = np.linspace(low, high, 121)
    values = G * (np.full(grid.size, c[0]) if not best.knots else shape_on(best, c, grid))
    where, peak, half, median = _localised(grid, values)
    what = {"dissipative": "a dissipative force on the rack (reversing with the rack speed)",
            "direction": "a force on the rack while it moves that does not reverse with the direction "
                         "(direction-dependent)",
            "elastic": "a force on the rack set by its position alone, the same both ways (elastic)"}[best.family]
    numbers = {"peak_at_m": where, "departure_N": peak, "half_width_m": half, "median_N": median,
               "range_m": [low, high]}
    if not best.knots:
        return f"{what}, uniform along the stroke: {values[0]:.3g} N", {"uniform_N": float(values[0])}
    if best.family == "elastic":
        odd = float(np.mean(values[grid > 0]) - np.mean(values[grid < 0])) / 2.0
        numbers["odd_part_N"] = odd
        return (f"{what}, up to {float(np.max(np.abs(values))):.3g} N, departing most ({peak:+.3g} N from its "
                f"median) at {1000 * where:+.0f} mm, within +-{1000 * half:.0f} mm of it; on average "
                f"{odd:+.3g} N more to the right than to the left", numbers)
    edge = abs(where - low) < 0.1 * (high - low) or abs(high - where) < 0.1 * (high - low)
    relative = ""
    if friction_N:
        numbers["relative_to_rack_friction"] = peak / friction_N
        relative = f" ({100 * peak / friction_N:+.0f} % of the calibrated rack friction)"
    if edge:
        return (f"{what}, growing toward the lock at {1000 * where:+.0f} mm by {peak:+.3g} N{relative}", numbers)
    return (f"{what}, larger by {peak:+.3g} N{relative} within +-{1000 * half:.0f} mm of {1000 * where:+.0f} mm",
            numbers)


def _describe_dissipative_column(best: Basis, c: np.ndarray) -> tuple[str, dict]:
    """The sentence of a friction periodic in the column angle: each order's amplitude (N m at the handwheel, the
    torque's swing above and below the friction's mean) and the column angle where the friction is largest."""
    amplitudes = {m: float(pm.hypot(c[2 * i], c[2 * i + 1])) for i, m in enumerate(best.orders)}
    # the angle where sum_m a_m sin(m theta) + b_m cos(m theta) peaks, on a grid of one turn
    grid = np.linspace(0.0, 2.0 * np.pi, 361)[:-1]
    shape = sum(c[2 * i] * pm.sin(m * grid) + c[2 * i + 1] * pm.cos(m * grid) for i, m in enumerate(best.orders))
    peak = float(grid[int(np.argmax(shape))])
    top = max(amplitudes, key=amplitudes.get)
    orders = " and ".join(f"{m} per column turn ({amplitudes[m]:.3g} N m)" for m in best.orders)
    return (f"a friction on the steering column (reversing with the motion) that rises and falls with the column "
            f"angle, {orders}, largest near {np.degrees(peak):.0f} deg of column angle",
            {"orders": list(best.orders), "amplitudes_Nm": {str(m): a for m, a in amplitudes.items()},
             "dominant_order": top, "peak_column_angle_rad": peak})


def signature_of(files, predictions: list[np.ndarray], params: Parameters, overrides: dict[str, float] | None = None,
                 jacobian: np.ndarray | None = None, settings: DiagnosisSettings = DEFAULT_SETTINGS,
                 map_fits: Callable[[Callable, list], list] = _in_line) -> Signature:
    """The signature of the torque residual of a diagnosis's files (:class:`parksteer.diagnose.problem.FileData`)
    under the calibrated model's `predictions`, with the model's parameters `params` and `overrides` (the
    calibration's values) and, if given, the calibration's `jacobian` (``Fit.jacobian``: its sensitivities,
    fitted beside every basis, :func:`signature_from_axes`, whose fits `map_fits` runs)."""
    axes = axes_of(files, predictions, params, overrides)
    values = {**steering_values(params), **(overrides or {})}
    nuisance = None
    if jacobian is not None:  # the torque's rows of each file's block (a fitted angle's rows follow them)
        rows, start = [], 0
        for f in files:
            rows.append(np.arange(start, start + f.n))
            start += f.m
        nuisance = np.asarray(jacobian, dtype=float)[np.concatenate(rows)]
    return signature_from_axes(axes, settings, values.get("steering.rack_friction_force"), nuisance, map_fits)
