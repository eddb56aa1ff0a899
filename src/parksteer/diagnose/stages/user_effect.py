"""What a user's effect in the model does to the error: the ladder without it and with it, its fitted strengths, the
residual by phase before and after, and the error as its strengths grow from 0 to their fitted values.

A user's effect (``--effects=+FILE.py``) declares the strengths a diagnosis fits (``Quantity.free``), which the
calibration fits with the base model's uncertain parameters (:func:`parksteer.diagnose.calibrate.free_strengths`).
This stage, in the table only when the model has free strengths (:func:`with_user_effect_stage`), gives:

- the ladder: the model without those effects at the parameter file's values, the same calibrated, then the model
  with them;
- each free strength with its 95 % interval and unit, or why these data give it none (:func:`why_not_fixed`);
- the calibrated parameters' intervals with the strengths held at their fit (:func:`conditioned_on_strengths`),
  and the share of each one's signature the strengths do not also make (:func:`not_made_by_strengths`);
- the residual's RMS in each phase of each file, without the effects and with them;
- a sweep: every free strength whose 0 means absent moved together from 0 to its fitted value in
  :data:`SWEEP_POINTS` steps, the other parameters held at the fit, the weighted error at each.

The worked example: docs/signature.md, "Adding an effect".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ... import portable as pm
from ...measure.phases import PHASES
from ..calibrate import calibrate, free_strengths
from ..fitting import Fit
from ..engine import ReplayEngine
from ..statistics import block_sandwich
from ..state import DiagnosisState
from ..statistics import fit_statistics
from .base import Stage

NAME = "user_effect"
SWEEP_POINTS = 6  # 0, 1/5, ..., 1 of the way to the fitted strengths


@dataclass(frozen=True)
class UserEffect:
    """What :class:`UserEffectLadder` found (module docstring); the predictions are kept for the figures."""

    effects: tuple[str, ...]
    rungs: tuple[dict, ...]
    strengths: dict
    phases: tuple[dict, ...]
    sweep: dict
    nominal: tuple[np.ndarray, ...]
    without: Fit
    noise_floor_Nm: float
    not_made_by_strengths: dict

    def as_dict(self) -> dict:
        return {"effects": list(self.effects), "rungs": list(self.rungs), "strengths": self.strengths,
                "phases": list(self.phases), "sweep": self.sweep, "noise_floor_Nm": self.noise_floor_Nm,
                "not_made_by_strengths": self.not_made_by_strengths}


def _others(fit: Fit, free_keys) -> list[int]:
    return [i for i, p in enumerate(fit.parameters) if p.key not in set(free_keys)]


def conditioned_on_strengths(fit: Fit, problem, free_keys, block_s: float) -> dict[str, dict]:
    """The intervals (:meth:`Fit.intervals`) of `fit`'s parameters other than `free_keys`, with those held at their
    fitted values: what these data fix of the car given the user's effect as fitted. Unconditioned, a user's shape
    of many strengths takes the car's parameters' intervals with it wherever the strengths together can make the
    same torque (a sum of bumps along the rack is a uniform rack friction), and the block sandwich needs more
    blocks than parameters."""
    keep = _others(fit, free_keys)
    sub = replace(fit, parameters=[fit.parameters[i] for i in keep], theta=np.asarray(fit.theta)[keep],
                  jacobian=fit.jacobian[:, keep])
    return sub.intervals(problem, block_s)


def not_made_by_strengths(fit: Fit, free_keys) -> dict[str, float]:
    """For each parameter of `fit` other than `free_keys`: the share (0 to 1, of its Jacobian column's norm) of its
    signature that no combination of the free strengths' signatures makes (the least-squares residual)."""
    keep, free = _others(fit, free_keys), [i for i in range(len(fit.parameters)) if i not in _others(fit, free_keys)]
    strengths = fit.jacobian[:, free]
    out = {}
    for i in keep:
        column = fit.jacobian[:, i]
        norm = float(pm.norm(column))
        if norm == 0.0 or not free:
            out[fit.parameters[i].key] = 1.0 if norm > 0.0 else 0.0
            continue
        coefficients = pm.lstsq(strengths, column)
        out[fit.parameters[i].key] = float(pm.norm(column - pm.matmul(strengths, coefficients)) / norm)
    return out


def why_not_fixed(fit: Fit, problem, block_s: float) -> str:
    """Why a free strength has no 95 % interval: the block sandwich's degrees of freedom (blocks less parameters),
    which the interval needs, counted; or, with blocks to spare, that these data leave it free."""
    try:
        blocks = block_sandwich(fit.jacobian, fit.weighted, problem, block_s)[1]
    except np.linalg.LinAlgError:
        blocks = None
    k = len(fit.parameters)
    if blocks is not None and blocks <= k:
        return (f"the records hold {blocks} blocks of {block_s:g} s and the fit {k} parameters: an interval needs "
                f"more blocks than parameters (records {(k + 1) * block_s:g} s long or more in all, or fewer "
                "strengths)")
    return "these data leave it free: other strengths make the same torque"


def user_effects(effects) -> list:
    """The effects of the model that declare free strengths."""
    return [e for e in effects if any(q.free for q in e.quantities)]


def with_user_effect_stage(table: tuple, effects) -> tuple:
    """`table` with this stage last, when the model has effects with free strengths (else `table` as it is: a
    diagnosis of the package's effects runs exactly its table)."""
    if not user_effects(effects) or any(isinstance(s, UserEffectLadder) for s in table):
        return table
    return (*table, UserEffectLadder())


def _rung(label: str, effects, statistics: dict) -> dict:
    return {"label": label, "effects": [e.name for e in effects], "rms_Nm": statistics["rms_Nm"],
            "weighted_rms_Nm": statistics["weighted_rms_Nm"], "peak_Nm": statistics["peak_Nm"],
            "over_floor": statistics["weighted_rms_Nm"] / statistics["noise_floor_Nm"]}


def phase_rows(problem, before, after) -> list[dict]:
    """The residual's RMS in each phase of each file, of the `before` and `after` predictions."""
    rows = []
    for f, b, a in zip(problem.files, before, after):
        r_before, r_after = f.torque_Nm - f.torque_part(b), f.torque_Nm - f.torque_part(a)
        for phase in PHASES:
            mask = f.phases.mask(phase)
            if mask.any():
                rows.append({"file": f.label, "phase": phase, "samples": int(mask.sum()),
                             "without_rms_Nm": float(np.sqrt(np.mean(r_before[mask] ** 2))),
                             "with_rms_Nm": float(np.sqrt(np.mean(r_after[mask] ** 2))),
                             "noise_floor_Nm": float(f.noise.total_rms)})
    return rows


class UserEffectLadder(Stage):
    name = NAME

    def message(self, state: DiagnosisState) -> str | None:
        return "the error without " + ", ".join(e.name for e in user_effects(state.base)) + " and with it"

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        problem, fit = state.problem, state.calibration
        mine = user_effects(state.base)
        without = [e for e in state.base if e not in mine]
        used = {k for e in without for k in e.uses}
        strengths = {k: v for k, v in (state.strengths or {}).items() if k in used} or None
        nominal = engine.predict(problem, without, {})
        calibrated = calibrate(engine, problem, without, strengths=strengths, settings=state.settings)
        stats = [fit_statistics(problem, p) for p in (nominal, calibrated.predictions, fit.predictions)]
        floor = stats[1]["noise_floor_Nm"]
        names = ", ".join(e.name for e in mine)
        rungs = (_rung("paper's model", without, stats[0]), _rung("calibrated", without, stats[1]),
                 _rung(f"+ {names}", state.base, stats[2]))
        free = free_strengths(mine)
        block_s = state.settings.interval_block_s
        intervals = fit.intervals(problem, block_s)
        table = {}
        for q in free:
            entry = {**intervals[q.key], "unit": q.unit, "bounds": [q.lower, q.upper], "why_not_fixed": None}
            if not all(math.isfinite(c) for c in entry["ci95"]):
                entry = {**entry, "ci95": None, "standard_error": None,
                         "why_not_fixed": why_not_fixed(fit, problem, block_s)}
            table[q.key] = entry
        # the strengths whose 0 means absent are swept (a width or a phase is held at its fit); when none has, every
        # free strength from just inside its lower bound
        swept = [q for q in free if q.within(0.0)] or free
        fitted = {q.key: intervals[q.key]["value"] for q in swept}
        origin = {q.key: 0.0 if q.within(0.0) else math.nextafter(q.lower, math.inf) for q in swept}
        fractions = np.linspace(0.0, 1.0, SWEEP_POINTS)
        errors = []
        for t in fractions:
            values = {k: origin[k] + float(t) * (fitted[k] - origin[k]) for k in fitted}
            errors.append(fit_statistics(problem, engine.predict(problem, state.base, {**fit.overrides, **values})))
        sweep = {"keys": list(fitted), "fractions": [float(t) for t in fractions],
                 "values": {k: [origin[k] + float(t) * (fitted[k] - origin[k]) for t in fractions] for k in fitted},
                 "weighted_rms_Nm": [e["weighted_rms_Nm"] for e in errors],
                 "over_floor": [e["weighted_rms_Nm"] / floor for e in errors]}
        found = UserEffect(tuple(e.name for e in mine), rungs, table,
                           tuple(phase_rows(problem, calibrated.predictions, fit.predictions)), sweep,
                           tuple(nominal), replace(calibrated, effects=without), floor,
                           not_made_by_strengths(fit, [q.key for q in free]))
        return state.with_output(NAME, found)
