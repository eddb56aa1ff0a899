"""Synthetic measurements with something hidden in them: the car data set and the benchmark's data sets.

Every file is made the way a car test would be: the hand turns the wheel through the paper's cycle at an irregular
speed (:func:`parksteer.synthetic.logger.irregular_hand_profile`), the model is driven by that handwheel angle
(:func:`parksteer.model.numeric.simulate.simulate` with ``handwheel``: the other drive mode than the rack replay
that analyses the data), and the logger samples, adds noise and quantises every channel
(:func:`parksteer.synthetic.logger.synthetic_measurement`, the parameter file's ``[synthetic]``). What is hidden is a
library candidate at a strength that changes the torque by a given number of converter steps RMS
(:func:`strength_for_rms`), nothing (a null), or a disturbance no candidate models (:class:`Disturbance`: a sensor
zero drift, a damaged pinion tooth's ripple, a torque channel lag, or an effect from outside the library). The base
parameters are perturbed within stated ranges (:data:`BASE_PERTURBATION`, the same for every benchmark), so that a
diagnosis must calibrate them first. The truth is recorded apart, never in the files, whose metadata say only
``synthetic: true`` and the logger's and hand's settings. The design is the pipeline's configuration
(``config/config.yaml``, ``car`` and ``benchmark``), given here as :class:`CarDesign` and :class:`BenchmarkDesign`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from .hand import HandProfile, irregular_hand_profile
from ..measure.converter import quantisation_step
from .logger import synthetic_measurement
from .example import example_hand, example_logger
from ..measure.io import OPTIONAL_COLUMNS, REQUIRED_COLUMNS, Measurement
from ..model.symbolic.components import discover_effects, load_effect_module
from ..model.numeric.simulate import simulate
from ..parameters import Parameters
from ..resources import example_effect
from ..model.symbolic.components import strength_parameter
from .size_search import SizeSearch, rms_difference, strength_for_rms
from ..names import TORQUE

RECORDED = [name for name in REQUIRED_COLUMNS + OPTIONAL_COLUMNS if name != "time_s"]
CLEAN_OUTPUT_DT_S = 0.005
USER_EFFECT_PATH = example_effect("column_imbalance")
DISTURBANCES = ("torque_drift", "gear_tooth", "channel_lag", "column_imbalance")
RANGE_HEADROOM = 0.1  # a logger range leaves at least this fraction of headroom over the signal's peak
RANGE_STEP_FRACTION = 0.2  # ranges go up in steps of this fraction of the parameter file's range


def torque_step_Nm(params: Parameters) -> float:
    """The torque channel's converter step of the synthetic logger."""
    logger = example_logger(params)
    return quantisation_step(logger.full_scale[TORQUE], logger.bits)


def hand(params: Parameters, seed: int) -> HandProfile:
    """The irregular hand of the synthetic measurements, with its own seed."""
    variation = dataclasses.replace(example_hand(params), seed=int(seed))
    return irregular_hand_profile(params, variation, output_dt_s=0.01)


def clean_run(params: Parameters, case: str, surface: str, hand_profile: HandProfile, effects=None,
              overrides: dict[str, float] | None = None) -> dict[str, np.ndarray]:
    """The model's clean columns (time_s and every recorded channel) for a hand-driven cycle."""
    result = simulate(case, effects=effects, overrides=overrides, surface=surface, params=params,
                      handwheel=hand_profile.handwheel_profile(), output_dt_s=CLEAN_OUTPUT_DT_S)
    columns = {"time_s": np.asarray(result.columns["time_s"])}
    columns.update({name: np.asarray(result.columns[name]) for name in RECORDED})
    return columns


@dataclass(frozen=True)
class Disturbance:
    """Something outside the candidate library, added to a clean run before it is logged.

    kind ``torque_drift``: the torque sensor's zero drifts linearly from 0 to ``size`` N m
    over the record (a thermal drift after zeroing at the start).
    kind ``gear_tooth``: a damaged pinion tooth gives a transmission error that repeats once
    per pinion turn, x_rack = x + A sin(G x + phase), with G the handwheel-to-rack ratio (one
    turn every 2 pi / G of rack, 34 mm); by virtual work the handwheel torque is scaled by
    dx_rack/dx = 1 + A G cos(G x + phase). ``size`` is A in m. Both the logged rack and the torque
    carry it.
    kind ``channel_lag``: the torque channel lags the rack by ``size`` s (a filter or a
    multiplexer in the logger).
    kind ``column_imbalance``: the out-of-balance column of examples/user_effect (an effect
    the library does not have), ``size`` its strength in N m; applied in the model itself.
    """

    kind: str
    size: float
    phase: float = 0.0

    def __post_init__(self):
        if self.kind not in DISTURBANCES:
            raise UsageError(f"unknown disturbance {self.kind!r} (known: {', '.join(DISTURBANCES)})")

    def effects_and_overrides(self) -> tuple[str | None, dict[str, float]]:
        if self.kind == "column_imbalance":
            return f"+{USER_EFFECT_PATH}", {"column_imbalance.strength": self.size, "column_imbalance.phase": self.phase}
        return None, {}

    def apply(self, params: Parameters, columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        out = dict(columns)
        t, torque = columns["time_s"], columns[TORQUE]
        if self.kind == "torque_drift":
            out[TORQUE] = torque + self.size * (t - t[0]) / (t[-1] - t[0])
        elif self.kind == "gear_tooth":
            ratio = params["steering.handwheel_to_rack_ratio"]
            angle = ratio * columns["rack_m"] + self.phase
            out["rack_m"] = columns["rack_m"] + self.size * pm.sin(angle)
            out[TORQUE] = torque * (1.0 + self.size * ratio * pm.cos(angle))
        elif self.kind == "channel_lag":
            out[TORQUE] = np.interp(t - self.size, t, torque)
        return out

    def with_size(self, size: float) -> Disturbance:
        return dataclasses.replace(self, size=float(size))


@dataclass
class DatasetSpec:
    """One synthetic data set: its files, what is hidden, at what size, and the base perturbation."""

    name: str
    seed: int
    files: tuple[tuple[str, str], ...]
    kind: str  # "candidate", "null" or "outside" (the out-of-class benchmark: "rival" or "null")
    hidden: str | None = None  # a candidate's name, or a disturbance's kind
    steps: float | None = None  # hidden size as converter steps of torque RMS (on the first file)
    base_overrides: dict[str, float] = field(default_factory=dict)
    phase: float | None = None  # of a disturbance (rad); None draws it from the seed
    strength: float | None = None  # a hidden candidate's strength as it stands (instead of `steps`)
    search: SizeSearch | None = None  # how a size given in `steps` is found (needed when `steps` is)


@dataclass(frozen=True)
class BenchmarkDesign:
    """The hidden-effect benchmark's design (config/config.yaml, section ``benchmark``, where each value's reason
    is): strengths in converter steps, the files of each data set, the base perturbation (fractions by key:
    :data:`BASE_PERTURBATION`), the number of nulls, the seed of data set 0, the disturbances' sizes, and the size
    search."""

    steps: tuple[float, ...]
    files: tuple[tuple[str, str], ...]
    perturbation: dict[str, float]
    nulls: int
    seed: int
    disturbance_steps: tuple[float, ...]
    search: SizeSearch

    @classmethod
    def from_config(cls, section: dict) -> BenchmarkDesign:
        return cls(tuple(float(s) for s in section["steps"]), file_pairs(section["files"]),
                   dict(BASE_PERTURBATION), int(section["nulls"]),
                   int(section["seed"]), tuple(float(s) for s in section["disturbance_steps"]),
                   SizeSearch(int(section["bisection_iterations"]), float(section["bisection_tolerance"]),
                              float(section["max_lag_s"])))


@dataclass(frozen=True)
class CarDesign:
    """The synthetic car data set's design (config/config.yaml, section ``car``): the one hidden effect and its
    strength, the files (case, surface) in order, the seed, and the base perturbation (:data:`BASE_PERTURBATION`)."""

    hidden_effect: str
    hidden_strength: float
    files: tuple[tuple[str, str], ...]
    seed: int
    perturbation: dict[str, float]

    @classmethod
    def from_config(cls, section: dict) -> CarDesign:
        return cls(str(section["hidden_effect"]), float(section["hidden_strength"]), file_pairs(section["files"]),
                   int(section["seed"]), dict(BASE_PERTURBATION))


# The base perturbation of every synthetic benchmark record (the in-class, out-of-class, variation, assisted and
# baseline benchmarks, the synthetic car data sets and the docs' samples): each key's value is its parameter file's
# times 1 + U(-p, p), drawn by :func:`perturbed_base` in key order. An experiment-design choice, not a measured
# spread: the three parameters the diagnosis calibrates are moved so that no record starts the calibration at its
# truth. The paper quotes them from the benchmark's results (settings.perturbation).
BASE_PERTURBATION = MappingProxyType({"tyre.friction_coefficient": 0.10, "steering.rack_friction_force": 0.15,
                                      "tyre.carcass_torsional_stiffness": 0.20})


def file_pairs(pairs) -> tuple[tuple[str, str], ...]:
    return tuple((str(case), str(surface)) for case, surface in pairs)


def perturbed_base(params: Parameters, seed: int, perturbation: dict[str, float]) -> dict[str, float]:
    """Base-parameter overrides, each its default times 1 + U(-p, p) (`perturbation`: p by key), seeded."""
    rng = np.random.default_rng(seed)
    out = {}
    for key, fraction in sorted(perturbation.items()):
        out[key] = float(params[key]) * (1.0 + rng.uniform(-fraction, fraction))
    return out


@dataclass
class Dataset:
    """The measurements of one data set and the truth about them (kept apart from the files)."""

    spec: DatasetSpec
    measurements: list[Measurement]
    truth: dict


def _logged(params: Parameters, columns: dict[str, np.ndarray], case: str, surface: str, seed: int,
            hand_profile: HandProfile) -> Measurement:
    """Log a clean run with the synthetic logger; a channel whose peak needs more range gets the next range up.

    As an engineer would set the logger: the range stays the parameter file's unless the signal
    comes within 10 % of it; then it is raised to the next multiple of RANGE_STEP_FRACTION of it
    that leaves 10 % headroom (the converter step grows with it, and the file's metadata say so).
    """
    logger = dataclasses.replace(example_logger(params), seed=int(seed))
    full_scale = dict(logger.full_scale)
    for name, scale in logger.full_scale.items():
        peak = float(np.max(np.abs(columns[name]))) if name in columns else 0.0
        if peak > (1.0 - RANGE_HEADROOM) * scale:
            unit = RANGE_STEP_FRACTION * scale
            full_scale[name] = unit * math.ceil(peak / (1.0 - RANGE_HEADROOM) / unit)
    logger = dataclasses.replace(logger, full_scale=full_scale)
    return synthetic_measurement(columns["time_s"], {k: v for k, v in columns.items() if k != "time_s"}, logger,
                                 case=case, surface=surface, source="synthetic: parksteer.synthetic.datasets",
                                 extra_metadata=dict(hand_profile.metadata))


def make_dataset(params: Parameters, spec: DatasetSpec) -> Dataset:
    """Simulate, hide, and log every file of `spec`; the truth names what is hidden and its size.

    The size is set so that the hidden thing changes the clean torque by ``spec.steps``
    converter steps RMS over all the data set's files together (a candidate whose largest
    strength changes it by less is hidden at that strength), or is ``spec.strength`` as it
    stands; the truth records the steps it actually makes.
    """
    step = torque_step_Nm(params)
    target = None if spec.steps is None else spec.steps * step
    if target is not None and spec.search is None:
        raise UsageError(f"data set {spec.name}: a size in converter steps needs a size search (DatasetSpec.search)")
    hands = [hand(params, spec.seed * 100 + i) for i in range(len(spec.files))]
    base = dict(spec.base_overrides)
    # each file's clean run of each effect set and values, simulated once: the size search ends on the run at the
    # strength it returns, which the truth's size and the record then take again (read-only: logging copies)
    runs: dict[tuple, dict[str, np.ndarray]] = {}

    def clean(i: int, effects, overrides) -> dict[str, np.ndarray]:
        key = (i, effects, tuple(sorted(overrides.items())))
        if key not in runs:
            runs[key] = clean_run(params, *spec.files[i], hands[i], effects, overrides)
        return runs[key]

    def torques(effects, overrides, disturbance=None):
        out = []
        for i in range(len(spec.files)):
            columns = clean(i, effects, overrides)
            if disturbance is not None:
                columns = disturbance.apply(params, columns)
            out.append(columns[TORQUE])
        return np.concatenate(out)

    effects, overrides, disturbance, strength_key, strength = None, dict(base), None, None, None
    if spec.kind == "candidate":
        effect = discover_effects()[spec.hidden]
        strength_key = strength_parameter(effect, params).key
        effects = f"+{effect.name}"
        upper = strength_parameter(effect, params).upper
        if spec.strength is not None:
            strength = float(spec.strength)
        else:
            strength = strength_for_rms(lambda s: torques(effects, {**base, strength_key: s}), target, upper * 1e-3,
                                        upper, spec.search)
        overrides[strength_key] = strength
    elif spec.kind == "outside":
        phase = spec.phase if spec.phase is not None else float(np.random.default_rng(spec.seed).uniform(-np.pi, np.pi))
        disturbance = Disturbance(spec.hidden, 0.0, phase=phase)
        strength = _disturbance_size(params, disturbance, target, torques, base, spec.search)
        disturbance = disturbance.with_size(strength)
        effects, extra = disturbance.effects_and_overrides()
        overrides.update(extra)
        strength_key = f"{spec.hidden}.size"
    steps = None
    if spec.kind != "null":
        hidden = torques(effects, overrides, disturbance)
        steps = rms_difference(hidden, torques(None, base)) / step
    measurements = []
    for i, ((case, surface), hand_profile) in enumerate(zip(spec.files, hands)):
        columns = clean(i, effects, overrides)
        if disturbance is not None:
            columns = disturbance.apply(params, columns)
        measurements.append(_logged(params, columns, case, surface, spec.seed * 100 + 50 + i, hand_profile))
    truth = {
        "name": spec.name,
        "kind": spec.kind,
        "hidden": spec.hidden,
        "steps_requested": spec.steps,
        "steps": steps,
        "torque_step_Nm": step,
        "strength_key": strength_key,
        "strength": strength,
        "phase": None if disturbance is None else disturbance.phase,
        "base_overrides": spec.base_overrides,
        "files": [{"case": c, "surface": s} for c, s in spec.files],
        "seed": spec.seed,
    }
    return Dataset(spec, measurements, truth)


def _disturbance_size(params: Parameters, disturbance: Disturbance, target: float, torques,
                      base: dict[str, float], search: SizeSearch) -> float:
    """The size of a disturbance that changes the data set's torque by `target` N m RMS (all files together)."""
    if disturbance.kind == "column_imbalance":
        effects = f"+{USER_EFFECT_PATH}"
        upper = strength_parameter(load_effect_module(str(USER_EFFECT_PATH)), params).upper
        return strength_for_rms(
            lambda s: torques(effects, {**base, "column_imbalance.strength": s, "column_imbalance.phase": disturbance.phase}),
            target, upper * 1e-3, upper, search)
    if disturbance.kind == "torque_drift":
        # RMS of a ramp from 0 to a over each record: a / sqrt(3)
        return target * math.sqrt(3.0)
    if disturbance.kind == "gear_tooth":
        # the torque change is A * (T G cos(G x + phase)): linear in A
        unit = torques(None, base, disturbance.with_size(1e-6)) - torques(None, base)
        return 1e-6 * target / float(np.sqrt(np.mean(unit**2)))
    return strength_for_rms(lambda s: torques(None, base, disturbance.with_size(s)), target, 0.001,
                            search.max_lag_s, search)


# ----------------------------------------------------------------------------- the benchmark's data sets
def benchmark_specs(params: Parameters, design: BenchmarkDesign, registry=None) -> list[DatasetSpec]:
    """Every data set of the benchmark: each candidate at each strength, nulls, disturbances outside the library."""
    registry = registry if registry is not None else discover_effects()
    candidates = sorted(name for name, e in registry.items()
                        if not e.in_default_set and e.diagnosis_candidate and strength_parameter(e, params) is not None)
    specs: list[DatasetSpec] = []

    def add(kind, hidden, steps):
        index = len(specs)
        seed = design.seed + index
        label = "null" if kind == "null" else f"{hidden}_{steps:g}".replace(".", "p")
        name = f"b{index:02d}_{label}"
        specs.append(DatasetSpec(name, seed, design.files, kind, hidden, steps,
                                 perturbed_base(params, seed, design.perturbation), search=design.search))

    for name in candidates:
        for steps in design.steps:
            add("candidate", name, steps)
    for _ in range(design.nulls):
        add("null", None, None)
    for kind in DISTURBANCES:
        for steps in design.disturbance_steps:
            add("outside", kind, steps)
    return specs


# ------------------------------------------------------------------------------------ the car data set
def car_dataset(params: Parameters, design: CarDesign) -> Dataset:
    """The stand-in for the paper's car tests: every case on the ground and on air bearings, ONE effect hidden."""
    spec = DatasetSpec("car", design.seed, design.files, "candidate", design.hidden_effect, None,
                       perturbed_base(params, design.seed, design.perturbation), strength=design.hidden_strength)
    return make_dataset(params, spec)


def file_name(case: str, surface: str) -> str:
    return f"{case}__{surface}.csv"


def write_car_dataset(parameters_path: str | Path, design: CarDesign, paths: list[str | Path],
                      truth_path: str | Path) -> None:
    """Write the car data set's files (named case__surface.csv, in the design's order) and, apart, its truth."""
    from ..measure.io import write_measurement
    from ..parameters import load_parameters
    from ..tables import write_json

    params = load_parameters(parameters_path)
    dataset = car_dataset(params, design)
    expected = [file_name(c, s) for c, s in design.files]
    if [Path(p).name for p in paths] != expected:
        raise UsageError(f"car data set: output files must be named {', '.join(expected)}")
    for path, measurement in zip(paths, dataset.measurements):
        write_measurement(path, measurement, params)
    write_json(truth_path, dataset.truth)
