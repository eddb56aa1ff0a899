"""The variation benchmark: diagnose records made by another hand, another logger and another drive.

Each record comes from :mod:`parksteer.synthetic.variations` (one of its
:data:`~parksteer.synthetic.variations.VARIATIONS`: another hand, logger and drive than the in-class benchmark's,
:mod:`parksteer.experiments.benchmark`), the torque from the prescribed-rack solve and the base parameters moved as
the in-class benchmark moves them. In each variation and replicate the same records are diagnosed with nothing
hidden (``adequate`` right, ``missing`` a false alarm) and with each hidden library effect at each size (converter
steps of torque RMS; the strength from a probe and secant steps in log-log): *named* when the verdict is ``missing``
and the effect is the one named or in its indistinguishable group; each such record keeps the part of its hidden
change the calibrated parameters cannot absorb (:func:`hidden_strength`). Coverage: each reported 95 % interval
against the true value. The targets are the project's requirement, not tuned here: NAMED_TARGET named of hidden
effects of at least NAMED_MIN_STEPS steps, NULL_ADEQUATE_TARGET nulls adequate, COVERAGE_TARGET covering;
:func:`parksteer.experiments.variation_summary.summarise` reports each and the variations that miss it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..parameters import Parameters, load_parameters
from ..synthetic.datasets import BASE_PERTURBATION, perturbed_base
from ..synthetic.size_search import SizeSearch, rms_difference, strength_for_rms
from ..measure.converter import quantisation_step
from ..synthetic.variations import VARIATIONS, Variation, variation_by_name, variation_rack, variation_record
from .benchmark import BENCHMARK_SETTINGS, diagnose_written
from ..diagnose.calibrate import calibrated_keys
from ..diagnose.settings import DEFAULT_SETTINGS, DiagnosisSettings
from ..names import TORQUE

NAMED_MIN_STEPS = 2.0  # converter steps RMS: hidden effects at least this large count towards the named rate
NAMED_TARGET = 0.90  # of those, named first or in the reported group
NULL_ADEQUATE_TARGET = 0.95  # of records with nothing hidden, called adequate
COVERAGE_TARGET = 0.90  # of the reported model's 95 % intervals, holding the true value
SEARCH_DT_S = 0.01  # s, output spacing of the clean runs the hidden strength is searched on
SEARCH_STEPS = 3  # evaluations of that search after the probe
SEARCH_TOLERANCE = 0.02  # accepted relative error of the hidden RMS change


@dataclass(frozen=True)
class VariationDesign:
    """The variation benchmark's design (config/config.yaml, section ``variations``): which variations, how many
    replicates of each (other seeds), the hidden library effects and their sizes in converter steps, the files a
    case draws from, the seed. The base perturbation is :data:`parksteer.synthetic.datasets.BASE_PERTURBATION`."""

    variations: tuple[str, ...]
    replicates: int
    hidden: tuple[str, ...]
    steps: tuple[float, ...]
    files: tuple[tuple[str, str], ...]
    seed: int
    perturbation: dict[str, float]
    hidden_with_angle: tuple[str, ...] | None = None  # hidden instead of `hidden` where the angle is fitted

    def hidden_in(self, variation: Variation) -> tuple[str, ...]:
        """The effects hidden in `variation`'s cases: ``hidden_with_angle`` (the effects the angle makes
        observable) where the diagnosis fits the handwheel angle and the grid names them, else ``hidden``."""
        if variation.uses_angle and self.hidden_with_angle is not None:
            return self.hidden_with_angle
        return self.hidden

    @classmethod
    def from_config(cls, section: dict) -> VariationDesign:
        grid = section["full"] if section["full_grid"] else section["small"]
        names = tuple(str(v) for v in grid["variations"])
        for name in names:
            variation_by_name(name)
        with_angle = grid.get("hidden_with_angle")
        design = cls(names, int(grid["replicates"]), tuple(str(h) for h in grid["hidden"]),
                     tuple(float(s) for s in grid["steps"]),
                     tuple((str(c), str(s)) for c, s in section["files"]), int(section["seed"]),
                     dict(BASE_PERTURBATION),
                     None if with_angle is None else tuple(str(h) for h in with_angle))
        too_many = [v for v in names if variation_by_name(v).files > len(design.files)]
        if too_many:
            raise UsageError(f"config variations.files: {too_many[0]} needs {variation_by_name(too_many[0]).files} "
                             f"files, the list has {len(design.files)}")
        return design


@dataclass(frozen=True)
class VariationCase:
    """One record set to diagnose: a variation, a replicate, what is hidden (None: nothing) and its size."""

    name: str
    variation: Variation
    replicate: int
    hidden: str | None
    steps: float | None
    seed: int


def variation_cases(design: VariationDesign) -> list[VariationCase]:
    """Every case of the design: per variation and replicate, the null, then each hidden effect at each size.

    A case's seed (hands, noise, base perturbation) depends only on its variation's place in VARIATIONS and its
    replicate, so the null and the hidden effects of one variation and replicate share their records' hand,
    noise and base parameters, and a smaller grid's records are the larger grid's.
    """
    order = [v.name for v in VARIATIONS]
    cases = []
    for replicate in range(design.replicates):
        for name in design.variations:
            variation = variation_by_name(name)
            seed = design.seed + 1000 * replicate + 10 * order.index(name)
            stem = f"{name}__r{replicate}"
            cases.append(VariationCase(f"{stem}__null", variation, replicate, None, None, seed))
            for effect in design.hidden_in(variation):
                for steps in design.steps:
                    label = f"{effect}_{steps:g}".replace(".", "p")
                    cases.append(VariationCase(f"{stem}__{label}", variation, replicate, effect, steps, seed))
    return cases


def case_names(design: VariationDesign) -> list[str]:
    return [c.name for c in variation_cases(design)]


def _case_files(case: VariationCase, design: VariationDesign):
    """(case, surface, hand, logger) of each file: file i's hand and noise seeded case.seed + i."""
    return [(load_case, surface, *case.variation.settings(case.seed + i))
            for i, (load_case, surface) in enumerate(design.files[:case.variation.files])]


def hidden_strength(params: Parameters, files, base: dict, effect: str, target: float,
                    signal: str = TORQUE, settings: DiagnosisSettings = DEFAULT_SETTINGS
                    ) -> tuple[str, float, float, float]:
    """(strength key, strength, RMS change of `signal` at it, the part of that change a calibration cannot absorb)
    of `effect` changing the clean `signal` (the torque, or the handwheel angle where the diagnosis fits it) by
    `target` RMS over `files` (prescribed racks), found by the benchmark's size search
    (:func:`parksteer.synthetic.size_search.strength_for_rms`) from a probe at a hundredth of the upper bound.

    The part a calibration cannot absorb (the observable change) is what is left of the change once it is
    projected off the directions the diagnosis calibrates (:func:`parksteer.diagnose.calibrate.calibrated_keys`:
    the finite-difference changes of the clean signal at the perturbed base, of the settings' relative step; with
    the angle, also one constant per file, the sensor's zero), in the linear least-squares sense. A king-pin
    friction on one load is nearly a rack friction (the steering arm's lever varies little over the cycle), so
    most of its change is absorbed by the calibrated rack friction force. It is a first-order measure: the diagnosis's fit is nonlinear and weighted
    and can absorb more (a king-pin friction keeping 0.42 steps here left a one-load record at 1.04 noise floors,
    while a column friction keeping 0.27 was named). The size is set on the whole change, as the targets state it:
    sized on the observable part, a king-pin or column friction would need several times its physical range.
    """
    from ..model.numeric.simulate import simulate
    from ..model.symbolic.components import discover_effects, resolve_effects, strength_parameter

    registry = discover_effects()
    if effect not in registry:
        raise UsageError(f"config variations.hidden: unknown effect {effect!r}")
    quantity = strength_parameter(registry[effect], params)
    key, upper = quantity.key, quantity.upper
    drives = [(load_case, surface, variation_rack(params, hand)) for load_case, surface, hand, _logger in files]

    def run(effects, overrides) -> list[np.ndarray]:
        return [np.asarray(simulate(load_case, effects=effects, overrides=overrides, surface=surface, rack_drive=drive,
                                    params=params, output_dt_s=SEARCH_DT_S).columns[signal], dtype=float)
                for load_case, surface, drive in drives]

    reference = run(None, base)
    logs, offsets = calibrated_keys(resolve_effects(None), signal == "handwheel_angle_rad", settings)
    step = settings.calibration_relative_step
    moved = [{**base, k: base.get(k, params[k]) * (1.0 + step)} for k in logs]
    moved += [{**base, k: base.get(k, params[k]) + offset_step} for k, _half_range, offset_step in offsets]
    columns = [np.concatenate(run(None, overrides)) - np.concatenate(reference) for overrides in moved]
    if signal == "handwheel_angle_rad" and settings.angle_offset_fitted:  # each file's sensor zero
        columns += [np.concatenate([np.full(len(r), float(j == i)) for j, r in enumerate(reference)])
                    for i in range(len(reference))]
    absorbed = pm.qr(np.column_stack(columns))[0]
    signals: dict[float, np.ndarray] = {0.0: np.concatenate(reference)}  # each strength simulated once

    def signal_of(strength: float) -> np.ndarray:
        if strength not in signals:
            signals[strength] = np.concatenate(run(f"+{effect}", {**base, key: strength}))
        return signals[strength]

    def observable_of(strength: float) -> np.ndarray:
        change = signal_of(strength) - signals[0.0]
        return change - pm.matmul(absorbed, pm.matmul(absorbed.T, change))

    strength = strength_for_rms(signal_of, target, upper * 1e-2, upper,
                                SizeSearch(iterations=SEARCH_STEPS, tolerance=SEARCH_TOLERANCE, max_lag_s=0.0))
    return (key, strength, rms_difference(signal_of(strength), signals[0.0]),
            rms_difference(observable_of(strength), 0.0))


def case_truth(params: Parameters, design: VariationDesign, case: VariationCase) -> tuple[list, dict]:
    """(the case's files as (case, surface, hand, logger), its truth): the perturbed base, and what is hidden at
    which strength, with its whole and its observable change in converter steps (:func:`hidden_strength`)."""
    files = _case_files(case, design)
    base = perturbed_base(params, case.seed, design.perturbation)
    logger = files[0][3]
    torque_step = quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
    # Where the angle is fitted, the hidden effect's size is its change of the angle in the angle converter's
    # steps: with the rack prescribed, what the angle makes observable (a lash) does not change the torque at all.
    signal, size_step = ("handwheel_angle_rad", quantisation_step(logger.angle_full_scale_rad, logger.angle_bits)) \
        if case.variation.uses_angle else (TORQUE, torque_step)
    key, strength, steps_actual, steps_observable = None, None, None, None
    if case.hidden is not None:
        key, strength, change, observable = hidden_strength(params, files, base, case.hidden,
                                                            case.steps * size_step, signal)
        steps_actual, steps_observable = change / size_step, observable / size_step
    return files, {
        "name": case.name, "variation": case.variation.name, "what": case.variation.what,
        "replicate": case.replicate, "seed": case.seed, "hidden": case.hidden, "steps_requested": case.steps,
        "steps": steps_actual, "steps_observable": steps_observable, "torque_step_Nm": torque_step,
        "size_signal": signal, "size_step": size_step, "strength_key": key, "strength": strength,
        "base_overrides": base, "files": [{"case": c, "surface": s} for c, s, _h, _l in files],
    }


def run_case(parameters_path, design: VariationDesign, name: str, folder, truth_path, diagnosis_path,
             settings: DiagnosisSettings = BENCHMARK_SETTINGS, on_diagnosis=None) -> dict:
    """Make variation case `name`'s records, write them into `folder`, diagnose them from the files with
    `settings` (and the angle and lag settings below); `on_diagnosis` as
    :func:`~parksteer.experiments.benchmark.diagnose_written` takes it."""
    params = load_parameters(parameters_path)
    start = time.perf_counter()
    truth, records, settings = case_records(params, design, name, settings)
    return diagnose_written(params, records, folder, truth, truth_path, diagnosis_path, start, settings,
                            on_diagnosis=on_diagnosis)


def case_records(params: Parameters, design: VariationDesign, name: str,
                 settings: DiagnosisSettings = BENCHMARK_SETTINGS) -> tuple[dict, list, DiagnosisSettings]:
    """(truth, records as (case, surface, measurement), the settings a user would diagnose them with) of
    variation case `name`."""
    cases = {c.name: c for c in variation_cases(design)}
    if name not in cases:
        raise UsageError(f"unknown variation case {name!r}")
    case = cases[name]
    files, truth = case_truth(params, design, case)
    overrides = dict(truth["base_overrides"])
    if case.hidden is not None:
        overrides[truth["strength_key"]] = truth["strength"]
    records = [(load_case, surface, variation_record(params, hand, logger, load_case, surface, overrides=overrides,
                                                      effects=f"+{case.hidden}" if case.hidden else None))
               for load_case, surface, hand, logger in files]
    # as a user would: the angle fitted where the logger has one, the torque lag searched for where the logger is
    # known to delay its torque channel (the lag itself is found by the diagnosis)
    settings = replace(settings, use_handwheel_angle=case.variation.uses_angle,
                       torque_lag_fitted=case.variation.logger.torque_lag_s > 0.0)
    return truth, records, settings


