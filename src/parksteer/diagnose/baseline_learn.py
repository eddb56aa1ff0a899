"""Learning a baseline (:func:`parksteer.diagnose.baseline.learn_baseline`): the absolute diagnosis of the healthy
records, the form they have that the model lacks, and the spread between healthy parts that sets the threshold of
"as the baseline" (the module docstring of :mod:`parksteer.diagnose.baseline`)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import portable as pm

from ..model.symbolic.components import (Effect, discover_effects, power_assist_of, resolve_effects,
                                          with_effect_quantities)
from ..parameters import Parameters
from .baseline_file import identified_parameters
from .baseline_form import HeldForm, Threshold, vehicle_fingerprint
from .baseline_share import ShareFreeBasis, refit_in_basis, share_free_fit
from .calibrate import free_parameter, free_strengths, linear_parameter
from .fitting import Fit, least_squares, polish
from .engine import ReplayEngine
from .problem import FileData, Problem
from .settings import DiagnosisSettings

def _say(progress):
    return progress if progress is not None else (lambda text: None)


def _estimates(fit: Fit, problem: Problem, settings: DiagnosisSettings, keys, source: str) -> dict:
    """Value, 95 % interval and standard error of `keys` of `fit` (:meth:`Fit.intervals`), its sandwich's blocks
    short enough that there are twice as many as the fit's parameters (a form of 15 strengths on an 18 s record
    needs them under 0.6 s). Where the joint intervals are not finite (a form's strengths summing to a uniform
    friction trade with the calibrated rack friction: J^T J is singular), each is the interval with the fit's other
    parameters held at their values, and its source says so."""
    duration = sum(float(f.time_s[-1] - f.time_s[0]) for f in problem.files)
    block_s = min(settings.interval_block_s, duration / (2 * len(fit.parameters) + 2))
    intervals = fit.intervals(problem, block_s)
    chosen = [k for k in keys if k in intervals]
    if not all(math.isfinite(intervals[k]["standard_error"]) for k in chosen):
        index = [i for i, p in enumerate(fit.parameters) if p.key in chosen]
        alone = dataclasses.replace(fit, parameters=[fit.parameters[i] for i in index], theta=fit.theta[index],
                                    jacobian=fit.jacobian[:, index])
        intervals = {**intervals, **alone.intervals(problem, block_s)}
        source += "; interval with the fit's other parameters held (jointly these data do not fix them apart)"
    return {k: {"value": float(intervals[k]["value"]), "ci95": [float(c) for c in intervals[k]["ci95"]],
                "standard_error": float(intervals[k]["standard_error"]), "source": source}
            for k in chosen}


def held_form(diagnosis, settings: DiagnosisSettings, say) -> tuple[HeldForm | None, Fit, Problem,
                                                                    ShareFreeBasis | None]:
    """What the healthy records have that the model lacks, with the fit it was read from: nothing where the
    absolute verdict is adequate; the named candidate at its fitted strength; or the form the residual's signature
    points to (:func:`parksteer.diagnose.suggest.suggest`) with its strengths fitted with the calibrated parameters,
    confined to the directions the calibrated values do not carry
    (:func:`parksteer.diagnose.baseline_share.share_free_fit`), and that confinement."""
    from .signature import COLUMN_CLASSES
    from .suggest import suggest

    problem, labels = diagnosis.problem, ", ".join(f.label for f in diagnosis.problem.files)
    if diagnosis.verdict == "missing" and diagnosis.best is not None:
        best = diagnosis.best
        key = best.signature.key
        strengths = _estimates(best.refit, problem, settings, [key],
                               f"fitted with the calibrated parameters on {labels} (the absolute diagnosis)")
        return HeldForm("candidate", best.name, strengths), best.refit, problem, None
    signature = diagnosis.outputs.get("signature")
    if diagnosis.verdict != "unexplained" or signature is None or signature.effect_class is None:
        return None, diagnosis.calibration, problem, None
    say(f"baseline: the form the residual's signature points to ({signature.effect_class}), its strengths fitted")
    found = suggest(problem, diagnosis.calibration, signature, None, settings)  # the form and its knots' places
    shape = next(e for e in found.fit.effects if e.name.startswith("shape_"))
    free = [q.key for q in shape.quantities if q.free]
    places = {k: float(v) for k, v in found.fit.fixed.items() if k.startswith(shape.name + ".") and k not in free}
    fit, share = share_free_fit(problem, diagnosis.calibration, shape, places, free, settings)
    strengths = _estimates(fit, problem, settings, free,
                           f"fitted with the calibrated parameters on {labels} (the signature's form), in the "
                           "directions whose torque the calibrated values reproduce for at most half")
    kind, best = signature.effect_class, signature.best
    column = kind in COLUMN_CLASSES
    form = HeldForm("signature", shape.name, strengths, places, kind, 0 if column else len(best.knots),
                    tuple(best.orders) if column else (), signature.sentence)
    return form, fit, problem, share


def _parts(files) -> tuple[str, list[tuple[list[FileData], FileData]]]:
    """(method, [(the records the form is fitted on again, the record judged against it)]), for two or more."""
    return ("leave one out: each healthy record judged against the form fitted again on the others",
            [([g for j, g in enumerate(files) if j != i], f) for i, f in enumerate(files)])


def fold_of(f: FileData, folds: int, block_s: float) -> np.ndarray:
    """Each sample's fold: the record cut into blocks of `block_s` from its start (residuals within a block are
    dependent, blocks nearly independent: :attr:`DiagnosisSettings.interval_block_s`), the blocks dealt to `folds`
    folds in turn, so that every fold has blocks along the whole record (both strokes, every place of the rack)."""
    t = f.time_s
    return (np.floor((t - t[0]) / block_s).astype(int) % folds)


def left_out(f: FileData, held_out: np.ndarray) -> FileData:
    """`f` with the samples `held_out` weighted out of a fit (their attainable error a million noise floors): the
    replay still runs through them from the record's start, so the samples kept are replayed as in the whole
    record, and a fit of `f` is a fit to the others alone."""
    out = np.where(held_out, 1e6 * f.noise.total_rms, 0.0)
    return dataclasses.replace(f, replay_uncertainty_Nm=out)


def _ranked(found):
    """The best candidate and the second best (None where there is none: the calibration itself, gain 0), of those
    refitted, by BIC gain."""
    refitted = sorted((c for c in found.candidates if c.delta_bic is not None and c.refit is not None),
                      key=lambda c: c.delta_bic, reverse=True)
    return (refitted[0] if refitted else None), (refitted[1] if len(refitted) > 1 else None)


def _lead(best, second) -> float:
    """The best candidate's BIC gain over the second best's (a gain under 0 counts as the calibration's, 0), the
    margin a later record's name is held against the band with."""
    if best is None or best.delta_bic <= 0.0:
        return 0.0
    return best.delta_bic - max(second.delta_bic if second is not None else 0.0, 0.0)


def _share(value: float, before: np.ndarray, after: np.ndarray, index: np.ndarray, clipped: bool = True) -> float:
    """`value` times the fraction of the fall of the weighted sum of squares from `before` to `after` that falls
    on the samples `index` (`clipped` to 0-1, or signed): a fold's share of a gain over the whole record."""
    fall_all = float(np.sum(before**2 - after**2))
    fall_here = float(np.sum(before[index]**2 - after[index]**2))
    if fall_all <= 0.0:
        return 0.0
    return value * (min(max(fall_here / fall_all, 0.0), 1.0) if clipped else fall_here / fall_all)


def fold_row(found, label: str, mask: np.ndarray) -> dict:
    """One fold's row: its weighted RMS error in noise floors under the whole record's calibration with the form
    fitted without it held, its share of the best candidate's BIC gain (the gain times the fraction of the
    refit's fall of the weighted sum of squares that falls on the fold's samples), and its share of the best
    candidate's lead over the second best, scaled the same way (the lead times the fraction of the fall from the
    second best's refit to the best's that falls on the fold). The lead's share is signed: both candidates have one
    strength, so the lead is the log ratio of their sums of squares, and to first order the sum over samples of
    the difference of their squared residuals; where the second best fits a fold better, that fold counts against
    the lead, as it would in a later record's sum, and the folds' shares of one diagnosis add up to its lead."""
    f, prediction = found.problem.files[0], found.calibration.predictions[0]
    index = np.tile(mask, f.signals)
    weighted = (f.measured - prediction) / f.sigma
    samples = int(index.sum())
    best, second = _ranked(found)
    gain = lead = 0.0
    if best is not None and best.delta_bic > 0.0:
        after = (f.measured - best.refit.predictions[0]) / f.sigma
        gain = _share(best.delta_bic, weighted, after, index)
        runner = weighted if second is None or second.delta_bic <= 0.0 \
            else (f.measured - second.refit.predictions[0]) / f.sigma
        lead = _share(_lead(best, second), runner, after, index, clipped=False)
    return {"part": label, "samples": samples, "over_floor": float(np.sqrt(np.mean(weighted[index]**2))),
            **_best_of(best), "delta_bic": gain, "lead": lead, "verdict": found.verdict}


def _best_of(candidate) -> dict:
    """A part's best candidate as its row names it: none is left out, as the baseline file (TOML) leaves it."""
    return {} if candidate is None else {"best": candidate.name}


def refit_form(form: HeldForm, train, params: Parameters, model: list[Effect], start: dict,
               settings: DiagnosisSettings, share: ShareFreeBasis | None = None) -> HeldForm:
    """The form's strengths fitted again on the records `train` alone (samples weighted out of them,
    :func:`left_out`, take no part), the car's calibrated parameters held at `start` (the healthy records'
    calibration), and within `share`'s directions where the form was learnt in them (:func:`held_form`).
    Refitted together with them on a part, a form's strengths trade with the base parameters along
    the valley where the two give one torque (knots of rack friction summing to the calibrated one), and each part
    lands elsewhere along it: the parts' spread is then that trade's, which a later record, judged with the
    strengths and the calibration held, never sees."""
    problem = Problem(list(train), with_effect_quantities(params, model).with_overrides(form.places))
    engine = ReplayEngine()
    if form.source == "candidate":  # a library strength, stepped by a hundredth of its value
        parameters = [linear_parameter(model, k, max(abs(float(v["value"])) * 1e-2, 1e-9))
                      for k, v in form.strengths.items()]
    else:  # a form's free strengths, fitted as they stand within their bounds
        parameters = [free_parameter(engine, problem, model, q) for q in free_strengths(model)
                      if q.key in form.strengths]
    values = {**start, **form.values}
    theta0 = np.array([p.theta(values[p.key]) for p in parameters])
    fixed = {k: v for k, v in start.items() if k not in form.strengths}
    if share is not None and form.source == "signature":
        fitted = refit_in_basis(engine, problem, model, share, values, fixed, parameters[0].step, settings)
        return dataclasses.replace(form, strengths={k: {**v, "value": float(fitted.get(k, v["value"]))}
                                                    for k, v in form.strengths.items()})
    fit = least_squares(engine, problem, model, parameters, theta0, fixed, settings=settings,
                        refresh_at_end=not settings.calibration_polished)
    if settings.calibration_polished:
        fit = polish(engine, problem, fit, settings)
    fitted = fit.values
    return dataclasses.replace(form, strengths={k: {**v, "value": float(fitted.get(k, v["value"]))}
                                                for k, v in form.strengths.items()})


def _judged(make, judged, params, base, registry, form, train, start, settings, workers):
    """The relative diagnosis of the records `judged` against `form` (held) and the calibrated values `start`, with
    a threshold of the sensor's."""
    from .select import diagnose

    calibrated = {k: {"value": float(v)} for k, v in start.items()}
    part = make(None, vehicle_fingerprint(params), tuple(f.label for f in train), tuple(e.name for e in base),
                calibrated, "", math.nan, form, Threshold(0.0, 0.0, "the sensor's floor"))
    return diagnose(list(judged), params, base, registry, settings=settings, workers=workers, quiet=True,
                    baseline=part)


def prediction_bound(values) -> float:
    """The one-sided 95 % prediction bound for one more draw of what `values` are draws of: mean + t(0.95, k-1)
    s sqrt(1 + 1/k) (Student's t, k values, s their standard deviation). Two healthy parts fix the spread poorly,
    and the bound says so (t = 6.31 with one degree of freedom); more healthy records tighten it."""
    values = np.asarray(values, dtype=float)
    k = values.size
    if k < 2:
        return float(values.max())
    return float(values.mean() + pm.student_t_quantile(0.95, k - 1) * values.std(ddof=1) * math.sqrt(1.0 + 1.0 / k))


def _threshold(rows: list[dict], method: str) -> Threshold:
    over = prediction_bound([r["over_floor"] for r in rows])
    gain = prediction_bound([r["delta_bic"] / r["samples"] for r in rows])
    lead = prediction_bound([r["lead"] / r["samples"] for r in rows])
    return Threshold(over, max(gain, 0.0), method + "; the threshold is the one-sided 95 % prediction bound for "
                     "one more healthy part (Student's t over the parts), of the error, the best candidate's gain and "
                     "its lead over the second best", tuple(rows), max(lead, 0.0))


def pooled_bound(values, per_record: int) -> float:
    """The one-sided 95 % prediction bound for the mean of `per_record` more draws of what `values` are draws of:
    mean + t(0.95, k-1) s sqrt(1/m + 1/k) (k values, s their standard deviation, m = `per_record`). A later record
    is a mean over its blocks, as long as the healthy record: the spread of its mean is the blocks' spread pooled,
    not that of a few folds' means, each itself noisy (three folds give t = 2.92 on a spread from two degrees of
    freedom)."""
    values = np.asarray(values, dtype=float)
    k = values.size
    if k < 2:
        return float(values.max())
    return float(values.mean() + pm.student_t_quantile(0.95, k - 1) * values.std(ddof=1) * math.sqrt(1.0 / per_record + 1.0 / k))


def _block_threshold(rows: list[dict], method: str) -> Threshold:
    """The threshold of one record's blocks (:func:`_folds`): the bounds on a later record's mean square error,
    mean BIC gain per sample and mean lead of the best candidate over the second best per sample, over as many
    blocks as the healthy record has, pooled over its blocks."""
    k = len(rows)
    mean_square = pooled_bound([r["over_floor"] ** 2 for r in rows], k)
    gain = pooled_bound([r["delta_bic"] / r["samples"] for r in rows], k)
    lead = pooled_bound([r["lead"] / r["samples"] for r in rows], k)
    return Threshold(math.sqrt(max(mean_square, 0.0)), max(gain, 0.0), method + "; the threshold is the one-sided "
                     f"95 % prediction bound for a later record's mean over {k} blocks, of the error, the best "
                     "candidate's gain and its lead over the second best, the blocks' variance pooled (Student's t "
                     "over the blocks)", tuple(rows), max(lead, 0.0))


def _best_gain(found) -> float:
    return max([0.0, *(c.delta_bic for c in found.candidates if c.delta_bic is not None)])


def _record_lead(found) -> float:
    return _lead(*_ranked(found))


def blocks_of(f: FileData, block_s: float) -> int:
    """How many blocks of `block_s` a record holds (its last, shorter block one of them)."""
    return int(math.floor((f.time_s[-1] - f.time_s[0]) / block_s)) + 1


def _folds(make, f: FileData, params: Parameters, base: list[Effect], registry, form: HeldForm | None, start: dict,
           settings: DiagnosisSettings, workers: int, say, share: ShareFreeBasis | None = None) -> Threshold:
    """One healthy record's threshold, out of sample: each block of :attr:`DiagnosisSettings.interval_block_s` a fold
    (:func:`fold_of`), judged with the form fitted on the others (the record replayed whole, the block weighted out
    of the fit: :func:`left_out`) held, and the calibrated values of the whole record, as a later record is; the
    bound pooled over the blocks (:func:`_block_threshold`)."""
    block_s = settings.interval_block_s
    folds = blocks_of(f, block_s)
    fold = fold_of(f, folds, block_s)
    model = None if form is None else sorted([*base, form.model_effect(registry)], key=lambda e: e.name)
    rows, found = [], None
    for k in range(folds):
        label = f"{f.label} (block {k + 1} of {folds})"
        if form is not None:  # nothing held: every block is read off the one diagnosis of the record
            say(f"baseline: {label} against the form fitted on the other blocks")
            held = refit_form(form, [left_out(f, fold == k)], params, model, start, settings, share)
            found = _judged(make, [f], params, base, registry, held, [f], start, settings, workers)
        elif found is None:
            say(f"baseline: the {folds} blocks of {f.label}, nothing held")
            found = _judged(make, [f], params, base, registry, None, [f], start, settings, workers)
        rows.append(fold_row(found, label, fold == k))
    held = ("with the held form refitted on the other blocks (out of sample)"
            if form is not None else "with nothing held (the healthy record is adequate: one diagnosis of it)")
    method = (f"blocks: the one healthy record cut into blocks of {block_s:g} s, each left out in turn; each "
              f"block's weighted RMS error and share of the best candidate's BIC gain {held}, the car's "
              "calibrated values held, as a later record is judged")
    return _block_threshold(rows, method)


def spread(make, files, params: Parameters, base: list[Effect], registry, form: HeldForm | None, start: dict,
           settings: DiagnosisSettings, workers: int, say, share: ShareFreeBasis | None = None) -> Threshold:
    """The threshold of "as the baseline" from the healthy parts (module docstring of
    :mod:`parksteer.diagnose.baseline`)."""
    if len(files) == 1:
        return _folds(make, files[0], params, base, registry, form, start, settings, workers, say, share)
    method, parts = _parts(files)
    rows = []
    for train, judged in parts:
        say(f"baseline: {judged.label} against the form fitted on {', '.join(f.label for f in train)}")
        held = form
        if form is not None:
            model = sorted([*base, form.model_effect(registry)], key=lambda e: e.name)
            held = refit_form(form, train, params, model, start, settings, share)
        found = _judged(make, [judged], params, base, registry, held, train, start, settings, workers)
        n = found.problem.n
        rows.append({"part": judged.label, "samples": int(n), "over_floor": math.sqrt(found.calibration.rss / n),
                     **_best_of(found.best), "delta_bic": _best_gain(found), "lead": _record_lead(found),
                     "verdict": found.verdict})
    return _threshold(rows, method)


def learn(make, files, params: Parameters, effects=None, settings: DiagnosisSettings | None = None, *, vehicle=None,
          progress=None, registry: dict[str, Effect] | None = None, workers: int = 1):
    """:func:`parksteer.diagnose.baseline.learn_baseline`; `make` is the baseline's class (the parts are judged
    against baselines of their own)."""
    from .select import diagnose
    from .settings import DEFAULT_SETTINGS

    settings = settings or DEFAULT_SETTINGS
    say = _say(progress)
    registry = registry if registry is not None else discover_effects()
    base = effects if isinstance(effects, list) and all(isinstance(e, Effect) for e in effects) \
        else resolve_effects(effects)
    fingerprint = vehicle_fingerprint(params)
    identified = None
    if power_assist_of(base) is not None:
        from .baseline_assist import identified_vehicle

        identified = identified_vehicle(files, params, base, vehicle, say)
        if identified is not None:
            params = identified_parameters(identified)
    say(f"baseline: the absolute diagnosis of {len(files)} healthy record(s)")
    absolute = diagnose(files, params, base, registry, settings=settings, workers=workers, quiet=progress is None)
    form, fit, problem, share = held_form(absolute, settings, say)
    held = set(form.strengths) if form is not None else set()
    keys = [p.key for p in absolute.calibration.parameters if p.key not in held]
    labels = ", ".join(f.label for f in files)
    calibrated = _estimates(fit, problem, settings, keys, f"calibrated on {labels}"
                            + (f" with {form.effect}" if form is not None else ""))
    start = {k: v["value"] for k, v in calibrated.items()}
    threshold = spread(make, files, params, base, registry, form, start, settings, workers, say, share)
    say(f"baseline: as the baseline up to {threshold.over_floor:.2f} noise floors, a BIC gain of "
        f"{threshold.bic_per_sample:.4f} and a lead of {threshold.lead_per_sample:.4f} per sample "
        f"({threshold.method.split(':')[0]})")
    return make(None if vehicle is None else str(vehicle), fingerprint, tuple(f.label for f in files),
                    tuple(e.name for e in base), calibrated, absolute.verdict,
                    math.sqrt(absolute.calibration.rss / absolute.problem.n), form, threshold, identified)
