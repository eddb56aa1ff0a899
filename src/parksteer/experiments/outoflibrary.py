"""The signature benchmark: records with out-of-library effects, scored on the signature and the suggested effect.

The truth forms (:mod:`parksteer.synthetic.outoflibrary`) are everyday mechanisms in forms no candidate has,
two or more per signature class. Each record is made as the variation benchmark makes its records
(:mod:`parksteer.synthetic.variations`: another hand, another logger, the prescribed-rack solve), with the base
parameters moved off the parameter file's as the benchmarks move them, the truth effect sized to change the
clean torque by ``steps`` converter steps RMS, and diagnosed from the written file as a user would. Nulls are
the same records with nothing hidden.

Scored per record:

- the signature's class is the truth form's class (target: :data:`CLASS_TARGET` of the out-of-library records);
- the suggested effect (:func:`parksteer.diagnose.suggest.suggest`, fitted with the calibrated parameters) takes
  the weighted error to within :data:`AFTER_LIMIT` noise floors (target :data:`SUGGESTION_TARGET`);
- a null gets no suggestion (the diagnosis writes one only when its verdict is ``unexplained`` and the signature
  has a class): target, none on any null.

Every truth form is linear in its strength, and with the rack prescribed the torque change of an added force
is linear in it to within the column's dynamics, so one probe sizes it: ``A = A_probe target / change``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..measure.io import write_measurement
from ..model.symbolic.components import resolve_effects
from ..parameters import Parameters
from ..synthetic.datasets import BASE_PERTURBATION, perturbed_base
from ..synthetic.size_search import rms_difference
from ..measure.converter import quantisation_step
from ..synthetic.outoflibrary import COMBINED_FORMS, FORMS, TruthForm, form_by_name
from ..synthetic.variations import VARIATIONS, variation_rack, variation_record
from .benchmark import BENCHMARK_SETTINGS
from ..diagnose.intake import Request, intake
from ..diagnose.signature import signature_of
from ..errors import UsageError
from ..diagnose.suggest import suggest
from ..names import TORQUE

CLASS_TARGET = 0.80
SUGGESTION_TARGET = 0.70
AFTER_LIMIT = 1.3  # noise floors
PROBE_DT_S = 0.01


@dataclass(frozen=True)
class SignatureCase:
    name: str
    form: str | None  # a truth form's effect name; None: a null
    steps: float
    variation: str
    seed: int


@dataclass(frozen=True)
class SignatureDesign:
    """The grid: every truth form at each size in `steps`, on variations taken in turn from `variations` of
    VARIATIONS starting at `first_variation`, and `nulls` records with nothing hidden; then the forms named in
    `combined` of those that are products of two classes (COMBINED_FORMS) at each size, the variations still in
    turn."""

    steps: tuple[float, ...] = (5.0,)
    nulls: int = 4
    variations: int = 6
    seed: int = 2411
    first_variation: int = 0
    combined: tuple[str, ...] = tuple(f.effect.name for f in COMBINED_FORMS)
    perturbation: dict = field(default_factory=lambda: dict(BASE_PERTURBATION))

    def cases(self) -> list[SignatureCase]:
        out, k = [], 0
        for steps in self.steps:
            for form in FORMS:
                variation = VARIATIONS[self.first_variation + k % self.variations]
                out.append(SignatureCase(f"{form.effect.name}_{steps:g}", form.effect.name, steps, variation.name,
                                         self.seed + k))
                k += 1
        for i in range(self.nulls):
            variation = VARIATIONS[self.first_variation + k % self.variations]
            out.append(SignatureCase(f"null_{i}", None, 0.0, variation.name, self.seed + k))
            k += 1
        for steps in self.steps:
            for form in [f for f in COMBINED_FORMS if f.effect.name in self.combined]:
                variation = VARIATIONS[self.first_variation + k % self.variations]
                out.append(SignatureCase(f"{form.effect.name}_{steps:g}", form.effect.name, steps, variation.name,
                                         self.seed + k))
                k += 1
        return out


def design_from_config(config: dict) -> SignatureDesign:
    """The grid of config["signature"] (config/config.yaml)."""
    try:
        design = SignatureDesign(steps=tuple(float(s) for s in config["steps"]), nulls=int(config["nulls"]),
                                 variations=int(config["variations"]), seed=int(config["seed"]),
                                 first_variation=int(config["first_variation"]),
                                 combined=tuple(str(n) for n in config["combined_forms"]))
    except KeyError as missing:
        raise UsageError(f"config signature: no {missing.args[0]!r}") from None
    known = [f.effect.name for f in COMBINED_FORMS]
    unknown = [n for n in design.combined if n not in known]
    if unknown:
        raise UsageError(f"config signature: combined_forms: no form {unknown[0]!r} (the forms: {', '.join(known)})")
    return design


def case_names(design: SignatureDesign) -> list[str]:
    return [c.name for c in design.cases()]


def truth_effects(form: TruthForm) -> list:
    """The effects a record of the truth form `form` is made with: the default set and the form (the set the
    package ships pre-derived, `parksteer derive --prebuilt`)."""
    return resolve_effects([*resolve_effects(None), form.effect])


def make_record(params: Parameters, case: SignatureCase, design: SignatureDesign):
    """(measurement, truth) of `case`: the variation's hand and logger, the perturbed base, the truth form sized
    to `steps` converter steps of clean torque change RMS (one probe, module docstring)."""
    from ..model.numeric.simulate import simulate

    variation = next(v for v in VARIATIONS if v.name == case.variation)
    hand, logger = variation.settings(case.seed)
    base = perturbed_base(params, case.seed, design.perturbation)
    truth = {"name": case.name, "form": case.form, "variation": case.variation, "steps": case.steps,
             "class": None, "strength": 0.0}
    if case.form is None:
        return variation_record(params, hand, logger, overrides=base), truth
    form = form_by_name(case.form)
    effects = truth_effects(form)
    key = f"{form.effect.name}.strength"
    drive = variation_rack(params, hand)

    def torque(strength: float) -> np.ndarray:
        return np.asarray(simulate("unladen", effects=effects, overrides={**base, key: strength}, rack_drive=drive,
                                   params=params, output_dt_s=PROBE_DT_S).columns[TORQUE])

    target = case.steps * quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
    probe = {"N": 100.0, "N s/m": 1000.0, "N s^2/m^2": 10000.0}.get(form.effect.quantities[0].unit, 0.5)
    change = rms_difference(torque(probe), torque(0.0))
    strength = probe * target / change
    truth.update({"class": form.signature_class, "strength": strength, "key": key})
    return variation_record(params, hand, logger, overrides={**base, key: strength}, effects=effects), truth


def run_case(params: Parameters, case: SignatureCase, design: SignatureDesign, folder: str | Path) -> dict:
    """Make, write, read back and diagnose one record; its signature, and its suggested effect where the
    signature has a class (the diagnosis would write it only when unexplained: both are recorded)."""
    measurement, truth = make_record(params, case, design)
    path = Path(folder) / f"{case.name}.csv"
    write_measurement(path, measurement, params)
    start = time.perf_counter()
    # as a user would: the torque lag searched for where the logger is known to delay its torque channel
    logger = next(v for v in VARIATIONS if v.name == case.variation).logger
    settings = replace(BENCHMARK_SETTINGS, torque_lag_fitted=logger.torque_lag_s > 0.0)
    diagnosis = intake(Request([path], params, settings=settings)).diagnose()
    diagnosed = time.perf_counter()
    sig = signature_of(diagnosis.problem.files, diagnosis.calibration.predictions, params,
                       diagnosis.calibration.overrides, diagnosis.calibration.jacobian)
    signed = time.perf_counter()
    suggestion = None
    if sig.effect_class is not None and (truth["form"] is not None or diagnosis.verdict == "unexplained"):
        suggestion = suggest(diagnosis.problem, diagnosis.calibration, sig, settings=settings)
    suggested = time.perf_counter()
    stats = diagnosis.statistics(diagnosis.calibration.predictions)
    would_write = diagnosis.verdict == "unexplained" and sig.effect_class is not None
    return {
        **truth,
        "verdict": diagnosis.verdict,
        "named": diagnosis.effect,
        "said_class": sig.effect_class,
        "sentence": sig.sentence,
        "class_right": truth["class"] is not None and sig.effect_class == truth["class"],
        "class_in_group": truth["class"] is not None and truth["class"] in (sig.effect_class, *sig.indistinguishable),
        "indistinguishable": list(sig.indistinguishable),
        "calibrated_over_floor": stats["weighted_rms_Nm"] / stats["noise_floor_Nm"],
        "after_over_floor": suggestion.after_over_floor if suggestion else None,
        "within": bool(suggestion and suggestion.after_over_floor <= AFTER_LIMIT),
        "suggestion_written": would_write,
        "diagnosis_s": diagnosed - start,
        "signature_s": signed - diagnosed,
        "suggestion_s": suggested - signed,
    }


def summarise(rows: list[dict]) -> dict:
    """Per signature class: records, class right, suggestion within AFTER_LIMIT; the nulls; the targets."""
    hidden = [r for r in rows if r["form"] is not None]
    nulls = [r for r in rows if r["form"] is None]
    table = {}
    for cls in sorted({r["class"] for r in hidden}):
        rs = [r for r in hidden if r["class"] == cls]
        table[cls] = {"records": len(rs), "class_right": sum(r["class_right"] for r in rs),
                      "class_in_group": sum(r.get("class_in_group", r["class_right"]) for r in rs),
                      "within": sum(r["within"] for r in rs),
                      "said": [r["said_class"] or "none" for r in rs],
                      "verdicts": [r["verdict"] + (f" {r['named']}" if r["named"] else "") for r in rs]}
    class_rate = sum(r["class_right"] for r in hidden) / len(hidden) if hidden else None
    within_rate = sum(r["within"] for r in hidden) / len(hidden) if hidden else None
    suggested_on_null = [r["name"] for r in nulls if r["suggestion_written"]]
    return {
        "records": len(rows), "out_of_library": len(hidden), "nulls": len(nulls), "table": table,
        "class_right_rate": class_rate, "within_rate": within_rate, "suggestions_on_nulls": suggested_on_null,
        "targets_met": {"class": class_rate is not None and class_rate >= CLASS_TARGET,
                        "suggestion": within_rate is not None and within_rate >= SUGGESTION_TARGET,
                        "nulls": not suggested_on_null},
        "time_s": {k: float(np.median([r[k] for r in rows])) for k in ("diagnosis_s", "signature_s", "suggestion_s")},
    }
