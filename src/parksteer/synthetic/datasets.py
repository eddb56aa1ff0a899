"""Synthetic measurements with something hidden in them: the car data set and the benchmark's data sets.

Every file is made the way a car test would be: the driver's hand turns the wheel through
the paper's cycle with an irregular speed (:func:`parksteer.synthetic.logger.irregular_hand_profile`);
the model is driven by that handwheel angle (:func:`parksteer.model.numeric.simulate.simulate` with
``handwheel``: the column twists, the rack follows), so the data come from the other drive
mode than the rack replay that analyses them; the logger then samples, adds noise and
quantises every channel (:func:`parksteer.synthetic.logger.synthetic_measurement`, the
settings of the parameter file's ``[synthetic]`` section). What is hidden is one of:

- a candidate effect of the library at a strength that changes the torque by a given number
  of converter steps RMS (found by secant steps on the strength, :func:`strength_for_rms`);
- nothing (a null);
- a disturbance no candidate models (:class:`Disturbance`): a drift of the torque sensor's
  zero, a ripple from a damaged pinion tooth, a lag of the torque channel behind the rack,
  or an effect from outside the library (the example's out-of-balance column).

The base parameters of every data set are perturbed within stated ranges, so that a
diagnosis must calibrate them first. What is hidden is recorded in a separate truth
dictionary, never in the files: their metadata say only ``synthetic: true`` and the
logger's and the hand's settings.

The experiment design (what is hidden in the car data set, the benchmark's strengths, files,
perturbations and seeds) is the pipeline's configuration (``config/config.yaml``, sections
``car`` and ``benchmark``), given here as :class:`CarDesign` and :class:`BenchmarkDesign`.

The out-of-class benchmark's records (:func:`make_outclass_dataset`, design :class:`OutclassDesign`, section
``outclass``) are made otherwise: a rival effect that is no diagnosis candidate is hidden, the model runs at a
tighter tolerance, and the clean columns pass a whole logger chain (:func:`chain_logged`: anti-alias filter,
channel lag, sampling, noise, an 8-bit torque and a finer rack converter). The hand is the irregular hand above:
the smooth hand of :mod:`parksteer.synthetic.variations` is sampled too finely to be a handwheel input of the
compiled model (24 pieces at most), and driving the rack instead would be the diagnosis's own drive.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from .hand import HandProfile, irregular_hand_profile
from ..measure.converter import quantisation_step
from .logger import synthetic_measurement
from .example import example_hand, example_logger
from ..measure.io import OPTIONAL_COLUMNS, REQUIRED_COLUMNS, Measurement
from ..model.symbolic.components import chosen_rivals, discover_effects, load_effect_module, rival_effects
from ..model.numeric.simulate import simulate
from ..parameters import Parameters
from ..resources import example_effect
from ..model.symbolic.components import strength_parameter
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


def rms_difference(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


@dataclass(frozen=True)
class SizeSearch:
    """How the size of a hidden thing is found: evaluations of the search beyond its probe (the setting keeps its
    historical name, bisection_iterations, in the configuration), accepted relative error of the RMS change, and
    the largest lag of the torque channel searched (s)."""

    iterations: int
    tolerance: float
    max_lag_s: float


def strength_for_rms(torque_of, target_Nm: float, start: float, upper: float, search: SizeSearch) -> float:
    """The size s (from 0 up) at which RMS(torque_of(s) - torque_of(0)) = target: secant steps in log-log.

    The RMS change of a small effect grows as a power of its size (linearly for most; faster for
    one with a threshold), so a straight line through two points in log(size), log(change) lands
    close to the target at once: from the probe `start`, a linearised estimate (change
    proportional to size), then secant steps through the last two points, each kept inside the
    bracket known so far (a step outside it, or a change that does not grow with the size, falls
    back to halving the bracket in the logarithm). Stops when the RMS change is within
    ``search.tolerance`` of the target, after at most ``search.iterations`` evaluations beyond the probe.
    If even `upper` changes the torque by less than the target, `upper` is returned (the caller
    records the change it actually makes).
    """
    reference = torque_of(0.0)

    def change(s: float) -> float:
        return rms_difference(torque_of(s), reference)

    def close(value: float) -> bool:
        return abs(value - target_Nm) <= search.tolerance * target_Nm

    low, high = 0.0, float(upper)  # sizes known to give less / more than the target
    bounded = False  # whether `high` has been evaluated (or upper tried)
    points = [(float(min(start, upper)), change(float(min(start, upper))))]
    for _ in range(search.iterations):
        s, value = points[-1]
        if close(value):
            return s
        if value < target_Nm:
            low = max(low, s)
            if s >= upper:
                return upper
        else:
            high = min(high, s)
        if len(points) == 1 or value <= 0.0:
            guess = s * target_Nm / value if value > 0.0 else s * 4.0  # linearised: change proportional to size
        else:
            (s0, v0), (s1, v1) = points[-2], points[-1]
            slope = pm.log(v1 / v0) / pm.log(s1 / s0) if v0 > 0.0 and s0 != s1 and v1 != v0 else 0.0
            guess = s1 * pm.power(target_Nm / v1, 1.0 / slope) if slope > 0.0 else -1.0
        if not low < guess < high:  # outside the bracket
            if guess >= high and not bounded:
                guess = upper  # nothing above has reached the target yet: try the largest size itself
            elif low > 0.0:
                guess = math.sqrt(low * high)  # halve the bracket in the logarithm
            else:
                guess = high / 4.0
        bounded = bounded or guess >= upper or value >= target_Nm
        points.append((guess, change(guess)))
    return points[-1][0]


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
    is): strengths in converter steps, the files of each data set, the base perturbation (fractions by key), the
    number of nulls, the seed of data set 0, the disturbances' sizes, and the size search."""

    steps: tuple[float, ...]
    files: tuple[tuple[str, str], ...]
    perturbation: dict[str, float]
    nulls: int
    seed: int
    disturbance_steps: tuple[float, ...]
    search: SizeSearch

    @classmethod
    def from_config(cls, section: dict) -> BenchmarkDesign:
        return cls(tuple(float(s) for s in section["steps"]), _files(section["files"]),
                   {str(k): float(v) for k, v in section["perturbation"].items()}, int(section["nulls"]),
                   int(section["seed"]), tuple(float(s) for s in section["disturbance_steps"]),
                   SizeSearch(int(section["bisection_iterations"]), float(section["bisection_tolerance"]),
                              float(section["max_lag_s"])))


@dataclass(frozen=True)
class CarDesign:
    """The synthetic car data set's design (config/config.yaml, section ``car``): the one hidden effect and its
    strength, the files (case, surface) in order, the seed, and the base perturbation (the benchmark's)."""

    hidden_effect: str
    hidden_strength: float
    files: tuple[tuple[str, str], ...]
    seed: int
    perturbation: dict[str, float]

    @classmethod
    def from_config(cls, section: dict, perturbation: dict) -> CarDesign:
        return cls(str(section["hidden_effect"]), float(section["hidden_strength"]), _files(section["files"]),
                   int(section["seed"]), {str(k): float(v) for k, v in perturbation.items()})


def _files(pairs) -> tuple[tuple[str, str], ...]:
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

    def torques(effects, overrides, disturbance=None):
        out = []
        for (case, surface), hand_profile in zip(spec.files, hands):
            columns = clean_run(params, case, surface, hand_profile, effects, overrides)
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
        columns = clean_run(params, case, surface, hand_profile, effects, overrides)
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


# ------------------------------------------------------------------------------ the out-of-class benchmark
def outclass_rivals(registry=None) -> dict[str, dict]:
    """Each rival effect's closest library candidate (or None), the others that share its physics ("related") and
    why, as each rival declares them (:class:`parksteer.model.symbolic.components.Rival`). A diagnosis that names
    the closest or a related candidate, or says `unexplained`, has answered honestly; one that names any other
    candidate beyond the indistinguishable band has given a confident wrong answer."""
    return {name: {"closest": e.rival.closest, "related": tuple(e.rival.related), "reason": e.rival.why}
            for name, e in rival_effects(registry).items()}


@dataclass(frozen=True)
class ChainLogger:
    """The whole logger chain of the out-of-class records, in the order a signal passes it.

    A causal Butterworth low-pass of ``anti_alias_order`` at ``anti_alias_hz`` on every channel (the analogue
    anti-alias filter, run from rest on the fine clean signal), a delay of the torque channel behind the rack of
    ``torque_lag_s`` (a multiplexed converter), sampling at ``sample_rate_hz``, analog noise (the parameter
    file's ``[synthetic]`` RMS values), and a converter per channel: the torque on ``torque_bits`` over the
    parameter file's full scale, the rack on ``rack_bits``.
    """

    sample_rate_hz: float
    anti_alias_hz: float
    anti_alias_order: int
    torque_lag_s: float
    torque_bits: int
    rack_bits: int

    @classmethod
    def from_config(cls, section: dict) -> ChainLogger:
        return cls(float(section["sample_rate_hz"]), float(section["anti_alias_hz"]), int(section["anti_alias_order"]),
                   float(section["torque_lag_s"]), int(section["torque_bits"]), int(section["rack_bits"]))


@dataclass(frozen=True)
class OutclassDesign:
    """The out-of-class benchmark's design (config/config.yaml, section ``outclass``, where each value's reason
    is): rival effects (a selection of the effects that declare ``rival``, in the order of the data sets; every
    one in name order when the section names none), their sizes in converter steps (the small grid, or the full one when ``full_grid``), the
    nulls, the files, the truth integrator's relative tolerance, the logger chain and the seed. The base
    perturbation and the size search are the in-class benchmark's."""

    rivals: tuple[str, ...]
    steps: tuple[float, ...]
    nulls: int
    files: tuple[tuple[str, str], ...]
    rtol: float
    logger: ChainLogger
    seed: int
    perturbation: dict[str, float]
    search: SizeSearch

    @classmethod
    def from_config(cls, section: dict, benchmark: dict) -> OutclassDesign:
        grid = section["full"] if section["full_grid"] else section["small"]
        bench = BenchmarkDesign.from_config(benchmark)
        rivals = chosen_rivals(section.get("rivals"), "config outclass.rivals")
        return cls(rivals, tuple(float(s) for s in grid["steps"]), int(grid["nulls"]), _files(section["files"]),
                   float(section["rtol"]), ChainLogger.from_config(section["logger"]), int(section["seed"]), bench.perturbation, bench.search)


def outclass_specs(params: Parameters, design: OutclassDesign, registry=None) -> list[DatasetSpec]:
    """Every data set of the out-of-class benchmark: each rival at each size, then the nulls.

    A rival must be an effect that declares itself one (``rival``: never a diagnosis candidate, so the truth is
    never one of the forms the diagnosis fits, and with its closest candidate, so its answer can be judged).
    """
    registry = registry if registry is not None else discover_effects()
    chosen_rivals(design.rivals, "config outclass.rivals", registry)
    specs: list[DatasetSpec] = []

    def add(kind, hidden, steps):
        index = len(specs)
        seed = design.seed + index
        label = "null" if kind == "null" else f"{hidden}_{steps:g}".replace(".", "p")
        specs.append(DatasetSpec(f"o{index:02d}_{label}", seed, design.files, kind, hidden, steps,
                                 perturbed_base(params, seed, design.perturbation), search=design.search))

    for rival in design.rivals:
        for steps in design.steps:
            add("rival", rival, steps)
    for _ in range(design.nulls):
        add("null", None, None)
    return specs


def chain_logged(params: Parameters, columns: dict[str, np.ndarray], chain: ChainLogger, case: str, surface: str,
                 seed: int, hand_profile: HandProfile) -> Measurement:
    """Pass clean columns (time_s, rack_m, handwheel_torque_Nm on a fine even grid) through the logger chain."""
    from ..measure.io import metadata_text
    from ..measure.converter import add_noise, quantise
    from .logger import resample

    t = np.asarray(columns["time_s"], dtype=float)
    filtered = anti_alias_and_lag(t, columns, chain.anti_alias_hz, chain.anti_alias_order, chain.torque_lag_s)
    time_s, sampled = resample(t, filtered, chain.sample_rate_hz)
    s = params.sections["synthetic"]
    rng = np.random.default_rng(seed)
    rack_scale, torque_scale = float(s["full_scale_rack"]), float(s["full_scale_torque"])
    peak = float(np.max(np.abs(sampled[TORQUE])))
    if peak > (1.0 - RANGE_HEADROOM) * torque_scale:  # the engineer's next range up, as _logged does
        unit = RANGE_STEP_FRACTION * torque_scale
        torque_scale = unit * math.ceil(peak / (1.0 - RANGE_HEADROOM) / unit)
    rack = quantise(add_noise(sampled["rack_m"], float(s["noise_rack"]), rng), rack_scale, chain.rack_bits)
    torque = quantise(add_noise(sampled[TORQUE], float(s["noise_torque"]), rng), torque_scale,
                      chain.torque_bits)
    # a file states one converter (the torque's); the rack's noise is estimated from the data
    metadata = {"case": case, "surface": surface, "source": "synthetic: parksteer.synthetic.datasets (out of class)",
                "synthetic": True, "bits": chain.torque_bits, "sample_rate_hz": chain.sample_rate_hz,
                "full_scale_handwheel_torque_Nm": torque_scale, "rack_bits": chain.rack_bits,
                "anti_alias_hz": chain.anti_alias_hz, "torque_lag_s": chain.torque_lag_s, "noise_seed": int(seed)}
    metadata.update(hand_profile.metadata)
    return Measurement(path=None, columns={"time_s": time_s, "rack_m": rack, TORQUE: torque},
                       metadata={k: metadata_text(v) for k, v in metadata.items()})


def anti_alias_and_lag(time_s: np.ndarray, columns: dict[str, np.ndarray], anti_alias_hz: float, order: int,
                       torque_lag_s: float) -> dict[str, np.ndarray]:
    """The analogue front of a logger on clean columns sampled on a fine even grid `time_s`: a causal Butterworth
    low-pass of `order` at `anti_alias_hz` on the rack and the torque (run from rest at the first value; none when
    `anti_alias_hz` is 0), then the torque channel delayed `torque_lag_s` behind the rack (linear interpolation)."""
    from scipy.signal import sosfilt

    t = np.asarray(time_s, dtype=float)
    filtered = {}
    if anti_alias_hz > 0.0:
        sos = pm.butterworth_lowpass_sos(order, anti_alias_hz, 1.0 / float(t[1] - t[0]))
    for name in ("rack_m", TORQUE):
        x = np.asarray(columns[name], dtype=float)
        filtered[name] = sosfilt(sos, x, zi=pm.sos_steady_state(sos) * x[0])[0] if anti_alias_hz > 0.0 else x.copy()
    if torque_lag_s:
        filtered[TORQUE] = np.interp(t - torque_lag_s, t, filtered[TORQUE])
    return filtered


def chain_torque_step_Nm(params: Parameters, chain: ChainLogger) -> float:
    """The converter step of the chain's torque channel at the parameter file's full scale."""
    return quantisation_step(float(params.sections["synthetic"]["full_scale_torque"]), chain.torque_bits)


def make_outclass_dataset(params: Parameters, spec: DatasetSpec, design: OutclassDesign) -> Dataset:
    """Simulate a rival hidden in the base model, handwheel-driven at ``design.rtol``, and log it through the chain.

    The rival's strength makes the clean torque change by ``spec.steps`` converter steps RMS over all files (the
    chain's torque step; its largest strength if that falls short, the truth records the steps it makes).
    """
    step = chain_torque_step_Nm(params, design.logger)
    hands = [hand(params, spec.seed * 100 + i) for i in range(len(spec.files))]
    base = dict(spec.base_overrides)

    def runs(effects, overrides):
        return [_fine_run(params, case, surface, h, effects, overrides, design.rtol)
                for (case, surface), h in zip(spec.files, hands)]

    def torque(effects, overrides):
        return np.concatenate([r[TORQUE] for r in runs(effects, overrides)])

    effects, overrides, strength_key, strength, steps = None, dict(base), None, None, None
    if spec.kind == "rival":
        effect = discover_effects()[spec.hidden]
        quantity = strength_parameter(effect, params)
        strength_key, effects = quantity.key, f"+{effect.name}"
        strength = strength_for_rms(lambda s: torque(effects, {**base, strength_key: s}), spec.steps * step,
                                    quantity.upper * 1e-3, quantity.upper, spec.search)
        overrides[strength_key] = strength
    clean = runs(effects, overrides)
    if spec.kind == "rival":
        steps = rms_difference(np.concatenate([r[TORQUE] for r in clean]), torque(None, base)) / step
    measurements = [chain_logged(params, columns, design.logger, case, surface, spec.seed * 100 + 50 + i, h)
                    for i, (columns, (case, surface), h) in enumerate(zip(clean, spec.files, hands))]
    rival = outclass_rivals().get(spec.hidden, {})
    truth = {
        "name": spec.name, "kind": spec.kind, "hidden": spec.hidden, "steps_requested": spec.steps, "steps": steps,
        "torque_step_Nm": step, "strength_key": strength_key, "strength": strength,
        "closest": rival.get("closest"), "related": list(rival.get("related", ())), "reason": rival.get("reason"),
        "rtol": design.rtol, "logger": dataclasses.asdict(design.logger),
        "base_overrides": spec.base_overrides, "files": [{"case": c, "surface": s} for c, s in spec.files],
        "seed": spec.seed,
    }
    return Dataset(spec, measurements, truth)


def _fine_run(params, case, surface, hand_profile, effects, overrides, rtol) -> dict[str, np.ndarray]:
    result = simulate(case, effects=effects, overrides=overrides, surface=surface, params=params,
                      handwheel=hand_profile.handwheel_profile(), output_dt_s=OUTCLASS_CLEAN_DT_S, rtol=rtol)
    return {name: np.asarray(result.columns[name]) for name in ("time_s", "rack_m", TORQUE)}


OUTCLASS_CLEAN_DT_S = 0.001  # the truth's output spacing: the anti-alias filter runs on a signal this fine
