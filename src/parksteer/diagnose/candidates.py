"""Candidate effects: which ones can be tested, their signatures, and the score test that ranks them.

A candidate is any registered effect (:mod:`parksteer.model.symbolic.components`) that is not in the model and has
a strength: the parameter named ``strength``, else the only one whose default is zero and whose range starts at
zero; one without it is listed as not testable. Its signature is the change of the replayed torque (and, with
:attr:`parksteer.diagnose.settings.DiagnosisSettings.use_handwheel_angle`, of the angle, counted in torque floors
per angle floor: :meth:`parksteer.diagnose.problem.Problem.in_torque_floors`) per unit strength, from a probe
scaled to a few noise floors RMS; one that moves the torque by less than a tenth of a floor at its largest strength
is unobservable and scores zero. The score test (Rao) projects the calibrated parameters' sensitivities out of the
signature and gives the linear strength, the weighted sum of squares it removes and a chi-square statistic of one
degree of freedom; a negative strength scores zero, and a signature that barely survives the projection is reported
confounded with the calibrated parameters. The test's formulas: docs/diagnosis.md, "Candidates and the score test".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import portable as pm
from ..model.symbolic.components import (Effect, discover_effects, power_assist_of, resolve_effects,
                                         strength_parameter, with_effect_quantities)
from .settings import DEFAULT_SETTINGS, DiagnosisSettings
from .fitting import Fit
from .engine import ReplayEngine
from .problem import Problem

def candidate_effects(model_effects: list[Effect], registry: dict[str, Effect] | None = None
                      ) -> tuple[list[Effect], list[str]]:
    """(testable candidates, names of registered effects outside the model that have no strength)."""
    registry = registry if registry is not None else discover_effects()
    in_model = {e.name for e in model_effects}
    # An electrically assisted car's own candidates (motor friction, torsion-bar offset, gain error) join only its
    # diagnosis; a candidate whose slot an assist fills (the rack lash) cannot join an assisted car's model.
    assisted = power_assist_of(model_effects) is not None
    electric = any(e.power_assist == "electric" for e in model_effects)
    testable, untestable = [], []
    for name in sorted(registry):
        wanted = registry[name].diagnosis_candidate or (electric and registry[name].assist_candidate)
        if name in in_model or not wanted:
            continue
        slot = registry[name].replaces
        if assisted and slot is not None and any(e.replaces == slot for e in model_effects):
            untestable.append(name)  # its slot is the assist's (a rack lash shapes the column as the torsion bar)
            continue
        (testable if strength_parameter(registry[name]) is not None else untestable).append(name)
    return [registry[n] for n in testable], untestable


def shares_diagnosis_model(effect: Effect, base_effects: list[Effect], params=None) -> bool:
    """Whether candidate `effect` can be replayed in the diagnosis model (:func:`diagnosis_model`) instead of a model
    of its own: it adds no coordinate or body (:meth:`Effect.configure`, :meth:`Effect.bodies`: a state changes the
    integrator's error norm and so its steps at any strength, a body the mass matrix), needs only effects of the
    base model, fills no slot the base model fills, and its strength is 0 in `params` (by default the shipped
    file's), so that it is absent there. Its loads are then a product with its strength (the effect files' promise
    that 0 means absent), exactly zero at strength 0; a slot filler's law at strength 0 is the slot's own law to
    rounding (ackermann's atan2(sin r, cos r) is r, rack_lash's dead band of width 0 the identity), so the others at
    strength 0 leave a candidate's replays its own model's to rounding (tests/diagnose/test_diagnosis_model.py)."""
    spec = strength_parameter(effect, params)
    kind = type(effect)
    filled = {e.replaces for e in base_effects} - {None}
    slot_ok = effect.replaces is None or effect.replaces not in filled
    return (spec is not None and slot_ok and kind.configure is Effect.configure
            and kind.bodies is Effect.bodies and set(effect.requires) <= {e.name for e in base_effects}
            and (params is None or float(with_effect_quantities(params, [effect])[spec.key]) == 0.0))


def diagnosis_model(base_effects: list[Effect], candidates: list[Effect], params=None) -> list[Effect]:
    """The one model that replays every candidate sharing it (:func:`shares_diagnosis_model`): the base effects and
    those candidates, by name, one filler per slot (the first by name; another keeps a model of its own). A
    candidate's replays run in it with the others' strengths at 0 (their value in `params`), so its signature and
    refit cost no model of its own; the base model's replays stay on the base model."""
    shared, slots = [], set()
    for candidate in sorted(candidates, key=lambda e: e.name):
        if shares_diagnosis_model(candidate, base_effects, params) and candidate.replaces not in slots:
            shared.append(candidate)
            slots.add(candidate.replaces)
            slots.discard(None)
    return sorted([*base_effects, *shared], key=lambda e: e.name)


def replay_models(base_effects: list[Effect], candidates: list[Effect], params=None
                  ) -> dict[tuple[str, ...], list[Effect]]:
    """{names of the base effects with one candidate: the effects of the compiled model that replays them}, for the
    candidates that share the diagnosis model (:func:`diagnosis_model`); a candidate not listed has its own."""
    host = diagnosis_model(base_effects, candidates, params)
    hosted = {e.name for e in host} - {e.name for e in base_effects}
    return {tuple(sorted([*(e.name for e in base_effects), name])): host for name in sorted(hosted)} \
        if len(hosted) > 1 else {}


def models_to_build(base_effects: list[Effect], candidates: list[Effect], params=None) -> list[list[Effect]]:
    """The compiled models a diagnosis of `base_effects` against `candidates` replays: the base model, the
    diagnosis model, and the base model with each candidate that has a model of its own."""
    hosts = replay_models(base_effects, candidates, params)
    out = [list(base_effects)]
    for candidate in candidates:
        names = tuple(sorted([*(e.name for e in base_effects), candidate.name]))
        model = hosts.get(names, sorted([*base_effects, candidate], key=lambda e: e.name))
        if all([e.name for e in model] != [e.name for e in m] for m in out):
            out.append(model)
    return out


def assisted_models(params) -> list[list[Effect]]:
    """The compiled models of the car of `params` with its assist ([] without one): those a diagnosis with its assist
    (``--with-assist``) replays (:func:`models_to_build` over its candidates), then the car with each assisted
    candidate (what a benchmark hides one in), each set once."""
    from ..model.numeric.assist import effects_with_assist

    spec = effects_with_assist(None, params)
    if spec is None:
        return []
    base = resolve_effects(spec)
    candidates = candidate_effects(base)[0]
    out = models_to_build(base, candidates, params)
    for candidate in (c for c in candidates if c.assist_candidate):
        effects = resolve_effects([*base, candidate])
        if all([e.name for e in effects] != [e.name for e in m] for m in out):
            out.append(effects)
    return out


def default_diagnosis_models(params=None) -> list[list[Effect]]:
    """The compiled models a diagnosis of a car with the default effects builds (:func:`models_to_build`): the ones
    the package ships pre-derived (``parksteer derive --prebuilt``). The same for every vehicle file that leaves the
    candidates absent, the package's three and the parameter file's car alike."""
    base = resolve_effects(None)
    return models_to_build(base, candidate_effects(base)[0], params)


@dataclass(frozen=True)
class Signature:
    """A candidate's sensitivity at the calibrated base model."""

    effect: Effect
    key: str  # "effect.strength"
    probe: float  # strength at which it was taken
    zero: list[np.ndarray]  # torque with the candidate at strength zero, per file
    probed: list[np.ndarray]  # torque at the probe strength, per file
    weighted: np.ndarray  # d(model / sigma) / d(strength)
    rms_change_Nm: float  # plain RMS torque change at the probe
    model: list[Effect]  # the base effects with the candidate
    observable: bool = True  # False: even its largest strength barely moves the replayed torque


def _rms_change(problem: Problem, a: list[np.ndarray], b: list[np.ndarray]) -> float:
    """RMS change of the fitted signals in N m, an angle's change counted in torque floors per angle floor."""
    if not problem.uses_angle:
        diff = np.concatenate([x - y for x, y in zip(a, b)])
    else:
        diff = problem.in_torque_floors([x - y for x, y in zip(a, b)])
    return float(np.sqrt(np.mean(diff**2)))


def probe_signature(engine: ReplayEngine, problem: Problem, base_effects: list[Effect], candidate: Effect,
                    overrides: dict[str, float], target_Nm: float, settings: DiagnosisSettings = DEFAULT_SETTINGS
                    ) -> Signature:
    """The candidate's signature at a probe strength that changes the torque by about `target_Nm` RMS."""
    spec = strength_parameter(candidate)
    key = f"{candidate.name}.{spec.name}"
    effects = sorted([*base_effects, candidate], key=lambda e: e.name)
    zero = engine.predict(problem, effects, {**overrides, key: 0.0})
    strength = max(spec.upper * settings.probe_start_fraction, 1e-12)
    probed, change = None, 0.0
    for attempt in range(settings.probe_max_tries):
        probed = engine.predict(problem, effects, {**overrides, key: strength})
        change = _rms_change(problem, probed, zero)
        if change > 0.0 and 0.5 <= change / target_Nm <= 2.0:
            break
        factor = target_Nm / change if change > 0.0 else 100.0
        new_strength = min(spec.upper, strength * factor)
        if new_strength == strength or attempt + 1 == settings.probe_max_tries:
            break  # the signature is the last probe's, at the strength it was made with
        strength = new_strength
    weighted = problem.scale([p - z for p, z in zip(probed, zero)]) / strength
    observable = change >= settings.unobservable_noise_floors * target_Nm / settings.probe_effect_noise_floors
    return Signature(candidate, key, strength, zero, probed, weighted, change, effects, observable)


@dataclass(frozen=True)
class Score:
    """The score test of one candidate at the calibrated base model (module docstring)."""

    effect: str
    statistic: float  # chi-square(1) under the candidate's absence; 0 if it asks for a negative strength
    linear_strength: float  # u / |w~|^2
    removed_rss: float  # u^2 / |w~|^2 (0 if the strength would be negative)
    identifiable_fraction: float  # |w~| / |w|
    confounded_with: str | None  # the calibrated parameter whose sensitivity is closest to the signature
    # (J^T J)^-1 J^T w: the change of the calibrated parameters (theta) that best makes the signature per unit
    # strength, the part projected out; None for an unobservable candidate
    calibrated_equivalent: np.ndarray | None = None


# What the least-squares projection leaves of a signature the calibrated parameters make exactly is rounding, about
# 1e-16 of it times the Jacobian's condition; below this share the signature counts as made by them entirely (the
# smallest identifiable share in the benchmarks is about 0.03).
PROJECTION_ROUNDOFF = 1e-10


def score(signature: Signature, calibration: Fit) -> Score:
    if not signature.observable:
        return Score(signature.effect.name, 0.0, 0.0, 0.0, 0.0, None)
    w = signature.weighted
    r = calibration.weighted
    J = calibration.jacobian
    if J.shape[1]:
        equivalent = pm.lstsq(J, w)
        projected = w - pm.matmul(J, equivalent)
        cosines = [abs(pm.dot(w, J[:, i])) / (pm.norm(w) * pm.norm(J[:, i]) + 1e-300)
                   for i in range(J.shape[1])]
        closest = calibration.parameters[int(np.argmax(cosines))].key
    else:
        projected, closest, equivalent = w, None, np.zeros(0)
    norm2 = pm.dot(projected, projected)
    full = pm.norm(w)
    fraction = min(math.sqrt(norm2) / full, 1.0) if full > 0 else 0.0
    u = pm.dot(projected, r)
    if norm2 <= (PROJECTION_ROUNDOFF * full) ** 2:
        return Score(signature.effect.name, 0.0, 0.0, 0.0, fraction, closest, equivalent)
    variance = pm.dot(r, r) / r.size
    allowed_negative = strength_parameter(signature.effect).lower < 0.0
    removed = u * u / norm2 if (u > 0 or allowed_negative) else 0.0
    return Score(signature.effect.name, removed / variance, u / norm2, removed, fraction, closest, equivalent)


def candidate_models(effects: str | None = None, extra: tuple[str, ...] = ()) -> dict[str, str | None]:
    """Every effect set a diagnosis of the model `effects` replays, or a truth generator hides a candidate in, by
    name, as effects specs: ``base``, ``diagnosis`` (the diagnosis model of the registry's candidates,
    :func:`diagnosis_model`, with the shipped parameters) and ``with_<candidate>`` for each testable candidate (the
    model a diagnosis replays a candidate in when it does not share the diagnosis model, and the one the
    benchmarks' records are made with).

    `extra` names effect modules outside the registry (files or dotted names) to include as candidates (a
    ``with_<candidate>`` set each; a diagnosis whose registry holds them has a diagnosis model of its own). The
    pipeline derives each set once (:func:`parksteer.model.codegen.cache.ensure`, one job per set) before any
    diagnosis runs, which spares the parallel diagnoses from deriving the same model side by side.
    """
    from ..model.symbolic.components import load_effect_module, resolve_effects

    base = resolve_effects(effects)
    registry = discover_effects()
    shared = sorted({e.name for e in diagnosis_model(base, candidate_effects(base, registry)[0])}
                    - {e.name for e in base})
    refs = {name: name for name in registry}
    for ref in extra:
        effect = load_effect_module(ref)
        registry[effect.name] = effect
        refs[effect.name] = str(ref)
    testable, _ = candidate_effects(base, registry)
    sets: dict[str, str | None] = {"base": effects}
    if len(shared) > 1:
        sets["diagnosis"] = ",".join(filter(None, [effects, *(f"+{refs[name]}" for name in shared)]))
    for candidate in testable:
        sets[f"with_{candidate.name}"] = ",".join(filter(None, [effects, f"+{refs[candidate.name]}"]))
    return sets
