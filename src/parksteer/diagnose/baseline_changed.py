"""A calibrated value that changed since the baseline: each value a baseline holds, freed as a candidate of its own.

Against a baseline the car's calibrated values are held at the baseline's (:meth:`parksteer.diagnose.baseline_form.
Threshold.settings_for`): calibrated again, a value takes up any change it can carry (a column friction through the
rack friction). But the value itself may be what changed (a rack whose friction grew), and held it could only show
as the library candidate nearest to it. So each held value is a candidate, ``changed:<key>`` (:class:`ChangedValues`,
a stage after the library's refits): the value freed alone (in its logarithm within ``calibration_range_factor`` of
the baseline's; an angle as it stands within its half range), everything else held, one parameter as a library
candidate's strength is one. Its BIC gain enters the same selection (:mod:`parksteer.diagnose.stages.select`)
against the same thresholds of "as the baseline". It may be named only where its 95 % interval leaves out the
baseline's value (a change the data do not hold apart from none is no change); otherwise it is listed, not
refitted. Named, the verdict is ``missing`` with ``effect`` ``changed:<key>``: a change found, never a library
effect. Where it and a library candidate explain a record alike, both are refitted within the BIC band of each
other, and the margin says so. Why: docs/diagnosis.md, "Against a car's baseline".
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .. import portable as pm
from ..model.symbolic.components import Effect
from ..model.symbolic.system import CORE_PARAMETERS
from .calibrate import log_parameter, offset_parameter
from .candidates import Score, Signature
from .engine import ReplayEngine
from .fitting import Fit, least_squares
from .settings import DiagnosisSettings
from .stages.base import Stage
from .state import Candidate, DiagnosisState
from .statistics import fit_statistics

PREFIX = "changed:"


class ChangedValue(Effect):
    """The name a freed calibrated value goes by among the candidates (``changed:<key>``): no mechanism of its own,
    its model is the car's, and never a library effect (no registry lists it)."""

    diagnosis_candidate = False

    def __init__(self, key: str):
        self.key = key
        self.name = PREFIX + key
        self.description = f"the calibrated value {key} changed since the baseline"


def changed_key(name: str | None) -> str | None:
    """The calibrated key a candidate's name frees (``changed:<key>``), or None for a library candidate."""
    return name[len(PREFIX):] if name is not None and name.startswith(PREFIX) else None


class ChangedValues(Stage):
    """Each held calibrated value a candidate of its own (module docstring). `keys`: the baseline's calibrated
    values; `offsets`: {key: (half range, step)} of those fitted as they stand (an angle), the others in their
    logarithm."""

    name = "changed_values"

    def __init__(self, keys: tuple[str, ...], offsets: dict[str, tuple[float, float]]):
        self.keys = tuple(keys)
        self.offsets = dict(offsets)

    def message(self, state: DiagnosisState) -> str | None:
        return "freeing the baseline's calibrated values: " + ", ".join(self.keys) if self.keys else None

    def _parameter(self, engine: ReplayEngine, state: DiagnosisState, model: list[Effect], key: str):
        if key in self.offsets:
            half, step = self.offsets[key]
            return offset_parameter(engine, state.problem, model, key, half, step)
        return log_parameter(engine, state.problem, model, key, state.settings)

    def run(self, state: DiagnosisState, engine: ReplayEngine) -> DiagnosisState:
        problem, calibration, settings = state.problem, state.calibration, state.settings
        model = list(calibration.effects)
        used = {k for e in model for k in e.uses} | set(CORE_PARAMETERS)
        keys = [k for k in self.keys if k in used and k not in calibration.values]
        freed = [self._parameter(engine, state, model, k) for k in keys]

        # one fit a value, spread over the workers as the library's refits are; each travels back without its effects
        def fitted(parameter) -> Fit:
            fit = least_squares(engine, problem, model, [*calibration.parameters, parameter],
                                np.concatenate([calibration.theta, [parameter.theta(parameter.reference)]]),
                                calibration.fixed, max_iterations=settings.refit_max_iterations, settings=settings)
            return replace(fit, effects=None)

        fits = [replace(f, effects=model) for f in engine.in_workers(problem, fitted, freed, False)]
        floor = fit_statistics(problem, calibration.predictions)["noise_floor_Nm"]
        added = tuple(_candidate(problem, calibration, model, p, fit, floor, settings) for p, fit in zip(freed, fits))
        return replace(state, candidates=state.candidates + added)


def _candidate(problem, calibration: Fit, model: list[Effect], parameter, fit: Fit, floor_Nm: float,
               settings: DiagnosisSettings) -> Candidate:
    """The freed value as a candidate: its signature the fitted change (per unit of the value's fitted variable,
    from the fit's last Jacobian), its score the sum of squares the fit removes, its refit kept only where the 95 %
    interval leaves out the baseline's value (module docstring)."""
    key, baseline_value = parameter.key, parameter.reference
    value = fit.values[key]
    weighted = fit.jacobian[:, -1]
    difference = np.concatenate([p - z for p, z in zip(fit.predictions, calibration.predictions)])
    rms_change = float(np.sqrt(np.mean(difference**2)))
    signature = Signature(ChangedValue(key), key, value, list(calibration.predictions), list(fit.predictions),
                          weighted, rms_change, model, rms_change >= settings.unobservable_noise_floors * floor_Nm)
    removed = max(calibration.rss - fit.rss, 0.0)
    variance = calibration.rss / max(calibration.weighted.size, 1)
    J = calibration.jacobian
    fraction = 1.0
    if J.shape[1] and pm.norm(weighted) > 0.0:
        projected = weighted - pm.matmul(J, pm.lstsq(J, weighted))
        fraction = min(float(pm.norm(projected) / pm.norm(weighted)), 1.0)
    score = Score(signature.effect.name, removed / variance if variance > 0 else 0.0, value, removed, fraction, None)
    low, high = fit.intervals(problem, settings.interval_block_s)[key]["ci95"]
    clear = not (low <= baseline_value <= high)
    return Candidate(signature, score, refit=fit if clear and removed > 0.0 else None)


def with_changed_values(stages: tuple, keys, settings: DiagnosisSettings) -> tuple:
    """`stages` with :class:`ChangedValues` for `keys` after the library's refits (stage ``refits``), so that the
    selection compares both; unchanged where the table has no refits."""
    names = [s.name for s in stages]
    if "refits" not in names or not keys:
        return tuple(stages)
    offsets = {k: (half, step) for k, half, step in settings.calibrated_with_angle_offsets}
    at = names.index("refits") + 1
    return (*stages[:at], ChangedValues(tuple(keys), offsets), *stages[at:])
