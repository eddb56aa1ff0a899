"""What the verdict owes to the assist's assumed values: each one moved to the ends of its band, the verdict again.

For every quantity of the assist that the vehicle file declares assumed (``provenance = "assumed"``, or no
provenance, or no entry: ``Parameters.provenance``) and that the model uses, this stage replays the final comparison
with it at each end of its band (:data:`BANDS`: the range the quantity's own source gives): the calibrated model
and the best candidate's refit replayed with the value moved, their residuals refitted to first order on the fit's
Jacobian, and :func:`~parksteer.diagnose.stages.verdict.choose_verdict` applied by the headline's rule
(:func:`~parksteer.diagnose.stages.select.may_headline`; against a baseline, a calibrated value that changed by its
interval against the baseline's value: :func:`clear_of_absence`); each end says why (:func:`end_reason`). A quantity whose
band's end changes the verdict decides it, and the report says so with how far the calibrated fit moves (noise
floors). Where ``parksteer assist identify`` fixed the product k_t eta_f N, the efficiency and the reduction move
with that product held (:func:`moved`). Four replays a quantity, none for a car without an assist (the ends'
replays are independent, and run side by side on the engine's workers); quantities the diagnosis fits are not here.
Why: docs/assist_identify.md, "Defaults that decide nothing silently".
"""

from __future__ import annotations

import math

import numpy as np

from ... import portable as pm
from ...model.symbolic.components import power_assist_of
from ..engine import ReplayEngine
from ..state import DiagnosisState
from ..statistics import bic_gain
from .base import Stage
from .verdict import choose_verdict, trimmed_rms

# The band of each assumed quantity of an electric assist (low, high), as its own source gives it
# (parksteer.model.symbolic.effects.electric_assist); the numerical smoothings' from a fifth of a bus's torque step
# (0.01 N m) to the default.
BANDS = {
    "motor_friction_torque": (0.01, 0.05),  # 0.01-0.05 N m for EPS motors (Harrer & Pfeffer, ch. 8.6)
    "motor_inertia": (1.0e-4, 5.0e-4),  # brushless EPS rotors 1-5e-4 kg m^2 (ch. 8.6)
    "efficiency": (0.75, 0.90),  # worm gears of EPS 0.75-0.9 (assumed)
    "back_efficiency": (0.75, 0.85),  # a worm of eta_f 0.80-0.87, rho 1-4 deg (reduction_efficiency)
    "torsion_bar_stiffness": (85.0, 170.0),  # EPS torsion bars 1.5-3 N m/deg (ch. 8.5)
    "torque_constant": (0.03, 0.07),  # 12 V EPS motors 0.03-0.07 N m/A (ch. 8.6)
    "motor_torque_limit": (3.0, 6.0),  # EPS motors 3-6 N m peak (ch. 8.6)
    "limit_smoothing": (0.002, 0.05),  # numerical
    "dead_band_smoothing": (0.002, 0.05),  # numerical: the boost line's corner
    "friction_speed": (0.1, 2.25),  # rad/s of the rotor: below a bus sample's reach to the car-wide smoothing's width
    "gain": (4.0, 10.0),  # the parking gain of EPS boost curves (ch. 8.2)
    "dead_band": (0.3, 1.5),  # published EPS boost curves (ch. 8.2)
}
BACK_EFFICIENCY_RACK = (0.80, 0.90)  # a back-driven ball nut (its forward 0.9-0.95)
REDUCTION = {"column": (15.0, 22.0), "pinion": (15.0, 25.0), "rack": (1500.0, 3500.0)}  # worm 15-22:1 (15-25:1 at
# the pinion), ball nut and belt 1500-3500 rad/m (ch. 8.3, 8.4)
# The boost line's quantities, unused when the file's [assist.boost] table gives the curve.
LINE_KEYS = ("gain", "dead_band", "dead_band_smoothing")


def is_assumed(params, dotted: str) -> bool:
    """Whether the vehicle file takes the value of `dotted` as assumed: its entry declares ``provenance =
    "assumed"``, or declares none, or there is no entry (the effect's default) (``Parameters.provenance``); a value
    declared measured or identified is the file's own."""
    return params.provenance(dotted) == "assumed"


def assumed_quantities(params, name: str, effect, calibrated: tuple[str, ...] = ()
                       ) -> list[tuple[str, float, str, tuple[float, float]]]:
    """(key, value, source, band) of each quantity of the assist `name` the file takes as assumed (module
    docstring), in the effect's order, but those in `calibrated` (keys the diagnosis fits)."""
    table = any(params.sections.get(name, {}).get(k, 0.0) for k in params.sections.get(name, {})
                if k.startswith("boost_assist_"))
    out = []
    for q in effect.quantities:
        key = q.name
        if (key not in BANDS and key != "reduction_ratio") or (table and key in LINE_KEYS):
            continue
        source = params.sources.get(f"{name}.{key}", "the effect's default")
        if not is_assumed(params, f"{name}.{key}") or f"{name}.{key}" in calibrated:
            continue
        band = BANDS.get(key)
        if key == "reduction_ratio":
            band = REDUCTION[effect.location]
        elif key == "back_efficiency" and effect.location == "rack":
            band = BACK_EFFICIENCY_RACK
        out.append((key, float(params[f"{name}.{key}"]), source, band))
    return out


def moved(params, name: str, key: str, value: float) -> dict[str, float]:
    """The overrides that move `key` of the assist `name` to `value`, holding what the data fixed. Where a value was
    identified (``parksteer assist identify``: its entry declares ``provenance = "identified"``), the column balance
    fixed a product, not its factors: the product k_t eta_f N (the torque constant), the back-driven delivery N k_t
    / eta_b per ampere (eta_f eta_b, with the torque constant held), the rotor's reflected inertia N^2 J_m and
    friction N T_f. Moving the efficiency or the reduction keeps each identified product, its other factor taking up
    the rest."""
    v = lambda k: float(params[f"{name}.{k}"])  # noqa: E731
    fixed = lambda k: params.provenance(f"{name}.{k}") == "identified"  # noqa: E731
    out = {f"{name}.{key}": value}
    if key == "efficiency":
        if fixed("torque_constant"):
            out[f"{name}.torque_constant"] = v("torque_constant") * v("efficiency") / value
        if fixed("back_efficiency"):
            out[f"{name}.back_efficiency"] = min(v("back_efficiency") * v("efficiency") / value, 1.0)
    elif key == "reduction_ratio":
        ratio = v("reduction_ratio") / value
        if fixed("torque_constant"):
            out[f"{name}.torque_constant"] = v("torque_constant") * ratio
        if fixed("motor_inertia"):
            out[f"{name}.motor_inertia"] = v("motor_inertia") * ratio * ratio
        if fixed("motor_friction_torque"):
            out[f"{name}.motor_friction_torque"] = v("motor_friction_torque") * ratio
    return out


def _refitted_rss(fit, problem, moved: list[np.ndarray]) -> tuple[float, np.ndarray, np.ndarray]:
    """The weighted RSS of `fit` with its model moved to `moved`, refitted to first order on its Jacobian; with the
    weighted residual and the fitted variables (theta) after that refit."""
    change = problem.scale([m - p for m, p in zip(moved, fit.predictions)])
    weighted = fit.weighted - change
    theta = np.asarray(fit.theta, dtype=float)
    if fit.jacobian.size:
        step = pm.lstsq(fit.jacobian, weighted)  # the portable routines: these numbers reach the report
        weighted = weighted - pm.matmul(fit.jacobian, step)
        theta = theta + step
    return pm.dot(weighted, weighted), weighted, theta


def clear_of_absence(parameter, theta: float, half: float, interval_rule: bool) -> bool:
    """The headline's condition on a candidate at a band end (stages/select.py, ``may_headline``; against a
    baseline, diagnose/baseline_changed.py): a library strength, fitted as it stands, is absent at 0, so it must be
    above 0 and, with `interval_rule`, its 95 % interval (`theta` +- `half`) clear of 0; a calibrated value freed
    against a baseline, fitted from the baseline's value (in its logarithm, theta 0 there, or as it stands from
    it), is absent at that value, and its interval must leave it out."""
    if parameter.transform == "linear":
        return bool(theta > 0.0 and (theta - half > 0.0 or not interval_rule))
    absent = parameter.reference if parameter.transform == "offset" else 0.0
    return bool(theta != absent and (abs(theta - absent) > half or not interval_rule))


def end_reason(end: dict, settings, absent: str = "0") -> str:
    """Why the rule gives an end's verdict (:func:`~parksteer.diagnose.stages.verdict.choose_verdict`, with the
    headline's condition that a named candidate is clear of its absence, :func:`clear_of_absence`: `absent` says
    where that is, 0 or the baseline's value): the thresholds each figure was held against, so that an end that
    is not adequate says why."""
    over, gain, name = end["calibrated_over_floor"], end["delta_bic"], end["candidate"]
    base = (f"the calibrated model {over:.3g} noise floors, "
            + ("within" if over <= settings.adequate_rms_factor else "above")
            + f" the {settings.adequate_rms_factor:g} of adequate")
    if end["verdict"] == "missing":
        return (f"{name} evidenced (BIC gain {gain:.3g} > {settings.bic_missing_threshold:g}), "
                f"{end['after_over_floor']:.3g} floors with it")
    if name is not None and not end["candidate_clear_of_zero"]:
        candidate = (f"{name}'s strength here holds 0, so it may not be named" if absent == "0" else
                     f"{name}'s interval here holds {absent}, so it may not be named")
    elif gain is None or gain <= settings.bic_missing_threshold:
        candidate = ("no candidate evidenced" if gain is None else
                     f"{name} not evidenced (BIC gain {gain:.3g}, {settings.bic_missing_threshold:g} needed)")
    else:
        candidate = (f"{name} evidenced (BIC gain {gain:.3g}) but leaves {end['after_over_floor']:.3g} floors "
                     f"({end['spread_over_floor']:.3g} without its largest residuals; a name needs "
                     f"{settings.adequate_rms_factor:g}, or {settings.explained_fraction_missing:g} of the excess "
                     f"explained within {settings.missing_rms_ceiling:g})")
    return f"{base}; {candidate}"


class AssumedValues(Stage):
    name = "assumed"

    def message(self, state: DiagnosisState) -> str | None:
        if power_assist_of(state.base) is None or not state.settings.assumed_values_replayed:
            return None
        return "what the verdict owes to the assist's assumed values"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        effect = power_assist_of(state.base)
        if (effect is None or effect.power_assist != "electric" or state.calibration is None
                or not state.settings.assumed_values_replayed):
            return state
        problem, settings, calibration = state.problem, state.settings, state.calibration
        n = problem.n
        best = state.best_candidate
        refit = best.refit if best is not None else None

        strength_key = best.signature.key if best is not None else None
        strength_index = None if refit is None else [p.key for p in refit.parameters].index(strength_key)
        parameter = None if refit is None else refit.parameters[strength_index]
        absent = "0" if parameter is None or parameter.transform == "linear" else "the baseline's value"
        quantities = assumed_quantities(problem.params, effect.name, effect, settings.calibrated_parameters)

        def replayed(item: tuple[str, float] | None):
            """The calibrated model and the best candidate's refit replayed with one quantity at one band end; for
            None, the candidate's 95 % interval as it stands (no replay: worked out beside the ends' replays)."""
            if item is None:
                return refit.intervals(problem, settings.interval_block_s)[strength_key]["ci95"]
            change = moved(problem.params, effect.name, *item)
            return (engine.predict(problem, calibration.effects, {**calibration.overrides, **change}),
                    None if refit is None else engine.predict(problem, refit.effects, {**refit.overrides, **change}))

        # every end's replays are independent: spread over the workers (or, with several files, each prediction
        # spreads its files), the first-order refits below in this process, in the table's order
        items = ([None] if refit is not None else []) + [(key, end) for key, _, _, band in quantities for end in band]
        predicted = iter(engine.in_workers(problem, replayed, items, False))
        # the candidate's 95 % half-width as it stands, in its fitted variable (a freed calibrated value's in its
        # logarithm): moving an assumed value shifts its strength, to first order not its spread
        halfwidth = None
        if refit is not None:
            low, high = next(predicted)
            halfwidth = (parameter.theta(high) - parameter.theta(low)) / 2.0

        def verdict_of(base_rss: float, with_fit: tuple[float, np.ndarray, np.ndarray] | None) -> dict:
            """The verdict by the headline's rule: choose_verdict, with a candidate that may be named only while its
            strength is above 0 and its interval clear of 0 (stages/select.py, may_headline)."""
            delta_bic = after = spread = explained = None
            clear = None
            if with_fit is not None:
                with_rss, with_weighted, theta = with_fit
                clear = clear_of_absence(parameter, float(theta[strength_index]), halfwidth,
                                         settings.headline_interval_clear_of_zero)
                delta_bic = bic_gain(base_rss, with_rss, state.n_eff or n, 1)
                after = math.sqrt(with_rss / n)
                spread = trimmed_rms(with_weighted, settings.missing_ceiling_trim)
                explained = (base_rss - with_rss) / (base_rss - n) if base_rss > n else None
            verdict = choose_verdict(math.sqrt(base_rss / n), delta_bic if clear else None, after if clear else None,
                                     explained if clear else None, settings, spread if clear else None)
            end = {"calibrated_over_floor": math.sqrt(base_rss / n), "delta_bic": delta_bic, "verdict": verdict,
                   "candidate": best.name if best is not None else None, "candidate_clear_of_zero": clear,
                   "after_over_floor": after, "spread_over_floor": spread}
            end["why"] = end_reason(end, settings, absent)
            return end

        # the same rule on the fits as they stand: the reference the moved values are held against
        nominal = verdict_of(calibration.rss, None if refit is None else (refit.rss, refit.weighted, refit.theta))
        rows = []
        for key, value, source, band in quantities:
            ends = []
            for end in band:
                calibrated, with_candidate = next(predicted)
                base_rss, _, _ = _refitted_rss(calibration, problem, calibrated)
                with_fit = None if refit is None else _refitted_rss(refit, problem, with_candidate)
                ends.append({"value": end, **verdict_of(base_rss, with_fit)})
            rows.append({"quantity": f"{effect.name}.{key}", "value": value, "source": source, "band": list(band),
                         "ends": ends, "decides": any(e["verdict"] != nominal["verdict"] for e in ends)})
        return state.with_output(self.name, {"verdict": state.verdict, "nominal": nominal, "quantities": rows})
