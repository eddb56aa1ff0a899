"""Learning a baseline (:func:`parksteer.diagnose.baseline.learn_baseline`): the absolute diagnosis of the healthy
records, the form they have that the model lacks, and the spread between healthy parts that sets the threshold of
"as the baseline" (the module docstring of :mod:`parksteer.diagnose.baseline`)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..model.symbolic.components import Effect, discover_effects, power_assist_of, resolve_effects
from ..parameters import Parameters
from .baseline import Baseline, HeldForm, Threshold, vehicle_fingerprint
from .calibrate import Fit, calibrate
from .engine import ReplayEngine
from .problem import FileData, Problem, prepare_file
from .settings import DiagnosisSettings

HALVES = ("first half", "second half")


def _say(progress):
    return progress if progress is not None else (lambda text: None)


def _estimates(fit: Fit, problem: Problem, settings: DiagnosisSettings, keys, source: str) -> dict:
    intervals = fit.intervals(problem, settings.interval_block_s)
    return {k: {"value": float(intervals[k]["value"]), "ci95": [float(c) for c in intervals[k]["ci95"]],
                "standard_error": float(intervals[k]["standard_error"]), "source": source}
            for k in keys if k in intervals}


def held_form(diagnosis, settings: DiagnosisSettings, say) -> tuple[HeldForm | None, Fit, Problem]:
    """What the healthy records have that the model lacks, with the fit it was read from: nothing where the
    absolute verdict is adequate; the named candidate at its fitted strength; or the form the residual's signature
    points to with its strengths fitted with the calibrated parameters (:func:`parksteer.diagnose.suggest.suggest`)."""
    from .signature import COLUMN_CLASSES
    from .suggest import suggest

    problem, labels = diagnosis.problem, ", ".join(f.label for f in diagnosis.problem.files)
    if diagnosis.verdict == "missing" and diagnosis.best is not None:
        best = diagnosis.best
        key = best.signature.key
        strengths = _estimates(best.refit, problem, settings, [key],
                               f"fitted with the calibrated parameters on {labels} (the absolute diagnosis)")
        return HeldForm("candidate", best.name, strengths), best.refit, problem
    signature = diagnosis.outputs.get("signature")
    if diagnosis.verdict != "unexplained" or signature is None or signature.effect_class is None:
        return None, diagnosis.calibration, problem
    say(f"baseline: the form the residual's signature points to ({signature.effect_class}), its strengths fitted")
    found = suggest(problem, diagnosis.calibration, signature, None, settings)
    shape = next(e for e in found.fit.effects if e.name.startswith("shape_"))
    free = [q.key for q in shape.quantities if q.free]
    places = {k: float(v) for k, v in found.fit.fixed.items() if k.startswith(shape.name + ".") and k not in free}
    strengths = _estimates(found.fit, problem, settings, free,
                           f"fitted with the calibrated parameters on {labels} (the signature's form)")
    kind, best = signature.effect_class, signature.best
    column = kind in COLUMN_CLASSES
    form = HeldForm("signature", shape.name, strengths, places, kind, 0 if column else len(best.knots),
                    tuple(best.orders) if column else (), signature.sentence)
    return form, found.fit, problem


def halves(f: FileData) -> tuple[FileData, FileData]:
    """One record cut in two between its first and last reversal (each half keeps a reversal to calibrate the
    friction on), each prepared as a record of its own."""
    from ..measure.io import Measurement

    t = f.time_s
    reversals = np.asarray(f.phases.reversal_times_s, dtype=float)
    cut = 0.5 * (reversals[0] + reversals[-1]) if reversals.size >= 2 else 0.5 * (t[0] + t[-1])
    i = int(np.searchsorted(t, cut))
    out = []
    for name, part in zip(HALVES, (slice(0, i), slice(i, None))):
        columns = {k: np.asarray(v)[part] for k, v in f.measurement.columns.items()}
        measurement = Measurement(f.measurement.path, columns, dict(f.measurement.metadata))
        out.append(prepare_file(measurement, f.case, label=f"{f.label} ({name})"))
    return out[0], out[1]


def _parts(files) -> tuple[str, list[tuple[list[FileData], FileData]]]:
    """(method, [(the records a form is fitted on, the part judged against it)])."""
    if len(files) >= 2:
        return ("leave one out: each healthy record judged against the form fitted on the others",
                [([g for j, g in enumerate(files) if j != i], f) for i, f in enumerate(files)])
    first, second = halves(files[0])
    return ("halves: each half of the one healthy record (cut between its reversals) judged against the form "
            "fitted on the other half", [([second], first), ([first], second)])


def refit_form(form: HeldForm, train, params: Parameters, model: list[Effect], start: dict,
               settings: DiagnosisSettings) -> HeldForm:
    """The form's strengths fitted again, with the calibrated parameters, on the records `train` alone."""
    problem = Problem(list(train), params.with_overrides(form.places))
    engine = ReplayEngine()
    strengths = None
    if form.source == "candidate":  # a library strength, stepped by a hundredth of its value
        strengths = {k: max(abs(float(v["value"])) * 1e-2, 1e-9) for k, v in form.strengths.items()}
    fit = calibrate(engine, problem, model, strengths=strengths, start={**start, **form.values}, settings=settings)
    values = fit.values
    return dataclasses.replace(form, strengths={k: {**v, "value": float(values.get(k, v["value"]))}
                                                for k, v in form.strengths.items()})


def spread(files, params: Parameters, base: list[Effect], registry, form: HeldForm | None, start: dict,
           settings: DiagnosisSettings, workers: int, say) -> Threshold:
    """The threshold of "as the baseline" from the healthy parts (module docstring of
    :mod:`parksteer.diagnose.baseline`)."""
    from .select import diagnose

    method, parts = _parts(files)
    rows = []
    open_threshold = Threshold(0.0, 0.0, "none")
    for train, judged in parts:
        say(f"baseline: {judged.label} against the form fitted on {', '.join(f.label for f in train)}")
        held = None
        if form is not None:
            model = sorted([*base, form.model_effect(registry)], key=lambda e: e.name)
            held = refit_form(form, train, params, model, start, settings)
        part = Baseline(None, vehicle_fingerprint(params), tuple(f.label for f in train), tuple(e.name for e in base), {}, "",
                        math.nan, held, open_threshold)
        found = diagnose([judged], params, base, registry, settings=settings, workers=workers, quiet=True,
                         baseline=part)
        n = found.problem.n
        gains = [c.delta_bic for c in found.candidates if c.delta_bic is not None]
        best_gain = max([0.0, *gains])
        rows.append({"part": judged.label, "samples": int(n), "over_floor": math.sqrt(found.calibration.rss / n),
                     "best": found.best.name if found.best is not None else None, "delta_bic": float(best_gain),
                     "verdict": found.verdict})
    return Threshold(max(r["over_floor"] for r in rows), max(r["delta_bic"] / r["samples"] for r in rows),
                     method, tuple(rows))


def learn(files, params: Parameters, effects=None, settings: DiagnosisSettings | None = None, *, vehicle=None,
          progress=None, registry: dict[str, Effect] | None = None, workers: int = 1) -> Baseline:
    """:func:`parksteer.diagnose.baseline.learn_baseline`."""
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
            from .baseline_file import identified_parameters

            params = identified_parameters(identified)
    say(f"baseline: the absolute diagnosis of {len(files)} healthy record(s)")
    absolute = diagnose(files, params, base, registry, settings=settings, workers=workers, quiet=progress is None)
    form, fit, problem = held_form(absolute, settings, say)
    held = set(form.strengths) if form is not None else set()
    keys = [p.key for p in absolute.calibration.parameters if p.key not in held]
    labels = ", ".join(f.label for f in files)
    calibrated = _estimates(fit, problem, settings, keys, f"calibrated on {labels}"
                            + (f" with {form.effect}" if form is not None else ""))
    start = {k: v["value"] for k, v in calibrated.items()}
    threshold = spread(files, params, base, registry, form, start, settings, workers, say)
    say(f"baseline: as the baseline up to {threshold.over_floor:.2f} noise floors and a BIC gain of "
        f"{threshold.bic_per_sample:.4f} per sample ({threshold.method.split(':')[0]})")
    return Baseline(None if vehicle is None else str(vehicle), fingerprint, tuple(f.label for f in files),
                    tuple(e.name for e in base), calibrated, absolute.verdict,
                    math.sqrt(absolute.calibration.rss / absolute.problem.n), form, threshold, identified)
