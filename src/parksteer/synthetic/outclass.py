"""The out-of-class benchmark's records: a rival effect that is no diagnosis candidate, hidden and logged.

They (:func:`make_outclass_dataset`, design :class:`OutclassDesign`, section
``outclass``) are made otherwise: a rival effect that is no diagnosis candidate is hidden, the model runs at a
tighter tolerance, and the clean columns pass a whole logger chain (:func:`chain_logged`: anti-alias filter,
channel lag, sampling, noise, an 8-bit torque and a finer rack converter). The hand is the data sets' irregular hand
(:func:`parksteer.synthetic.datasets.hand`):
the smooth hand of :mod:`parksteer.synthetic.variations` is sampled too finely to be a handwheel input of the
compiled model (24 pieces at most), and driving the rack instead would be the diagnosis's own drive.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .. import portable as pm
from ..measure.converter import quantisation_step
from ..measure.io import Measurement
from ..model.numeric.simulate import simulate
from ..model.symbolic.components import discover_effects, strength_parameter
from ..model.symbolic.rivals import chosen_rivals, rival_effects
from ..parameters import Parameters
from .datasets import (
    RANGE_HEADROOM,
    RANGE_STEP_FRACTION,
    BenchmarkDesign,
    Dataset,
    DatasetSpec,
    file_pairs,
    hand,
    perturbed_base,
)
from .hand import HandProfile
from .size_search import SizeSearch, rms_difference, strength_for_rms
from ..names import TORQUE



OUTCLASS_CLEAN_DT_S = 0.001  # the truth's output spacing: the anti-alias filter runs on a signal this fine


def _fine_run(params, case, surface, hand_profile, effects, overrides, rtol) -> dict[str, np.ndarray]:
    result = simulate(case, effects=effects, overrides=overrides, surface=surface, params=params,
                      handwheel=hand_profile.handwheel_profile(), output_dt_s=OUTCLASS_CLEAN_DT_S, rtol=rtol)
    return {name: np.asarray(result.columns[name]) for name in ("time_s", "rack_m", TORQUE)}


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
        return cls(rivals, tuple(float(s) for s in grid["steps"]), int(grid["nulls"]), file_pairs(section["files"]),
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

    made: dict[tuple, list] = {}  # each effect set and values run once: the record is the search's last run

    def runs(effects, overrides):
        key = (effects, tuple(sorted(overrides.items())))
        if key not in made:
            made[key] = [_fine_run(params, case, surface, h, effects, overrides, design.rtol)
                         for (case, surface), h in zip(spec.files, hands)]
        return made[key]

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
