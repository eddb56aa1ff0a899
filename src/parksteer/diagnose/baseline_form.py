"""The parts of a car's baseline (:mod:`parksteer.diagnose.baseline`): the form held in later records
(:class:`HeldForm`), the threshold of "as the baseline" (:class:`Threshold`) and the car's fingerprint."""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field

from ..errors import UsageError
from ..model.symbolic.components import Effect, discover_effects
from ..model.symbolic.shapes import shape_effect
from ..parameters import Parameters
from .settings import DiagnosisSettings

FORMAT = "parksteer baseline 1"
# The headline rule against a baseline (Threshold.settings_for): the held strengths are uncertain, and a change the
# data do not hold apart from 0 is within what the healthy car already does.
HEADLINE = "no candidate named whose fitted strength is 0 or whose 95 % interval holds 0"


def vehicle_fingerprint(params: Parameters) -> str:
    """A short hash of the car's values (every section and case of its parameter or vehicle file): a baseline is
    the car's, and a record of another car is refused against it."""
    text = json.dumps({"sections": params.sections, "cases": params.cases}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


@dataclass(frozen=True)
class HeldForm:
    """What the healthy car has that the model lacks, held at the baseline's values in later diagnoses.

    `source`: ``candidate`` (a library effect the absolute diagnosis named) or ``signature`` (the form its residual's
    signature points to, :func:`parksteer.model.symbolic.shapes.shape_effect`: `shape_class` with `knots` knots or
    column `orders`, the knots' places and width in `places`). `strengths`: key -> {value, ci95, standard_error}."""

    source: str
    effect: str
    strengths: dict
    places: dict = field(default_factory=dict)
    shape_class: str | None = None
    knots: int = 0
    orders: tuple[int, ...] = ()
    signature: str | None = None

    def model_effect(self, registry: dict[str, Effect] | None = None) -> Effect:
        if self.source == "signature":
            return shape_effect(self.shape_class, self.knots, tuple(self.orders))
        registry = registry if registry is not None else discover_effects()
        if self.effect not in registry:
            raise UsageError(f"baseline: effect {self.effect!r} is not a registered effect")
        return registry[self.effect]

    @property
    def values(self) -> dict[str, float]:
        """The held values: the strengths and the form's places."""
        return {**{k: float(v["value"]) for k, v in self.strengths.items()}, **self.places}


@dataclass(frozen=True)
class Threshold:
    """What "as the baseline" allows: `over_floor`, the weighted RMS error in noise floors, `bic_per_sample`, the
    best candidate's BIC gain per sample, and `lead_per_sample`, the best candidate's lead in BIC gain over the
    second best per sample, that one more healthy part stays under (95 % prediction bounds over the healthy parts
    with the form held); `method` says how the parts were made; `parts` lists each. A baseline file written before
    the lead was learnt reads with a lead of 0: the settings' band alone."""

    over_floor: float
    bic_per_sample: float
    method: str
    parts: tuple[dict, ...] = ()
    lead_per_sample: float = 0.0

    def settings_for(self, settings: DiagnosisSettings, samples: int) -> DiagnosisSettings:
        """`settings` with the thresholds of "as the baseline" for a later record of `samples` samples: the adequate
        factor at least the healthy spread, the ceiling on a named effect's error raised in proportion, and the BIC
        gain a candidate needs at least what healthy parts reached at the same length; the band within which two
        candidates are indistinguishable (a name within it is not confident) at least the lead over the second best
        that healthy parts reached at the same length: there the best candidate's gain is the car's own misfit taken
        up, and a candidate's lead of that size is what the misfit makes of two candidates that fit alike, not a
        change told apart from its rival; no candidate named whose
        95 % interval holds 0 (``headline_interval_clear_of_zero``): against a baseline the held strengths are
        uncertain, and a strength the data do not hold apart from 0 is within what the healthy car already does; and
        nothing calibrated again (the car's calibrated values are the baseline's, :meth:`Baseline.parameters`): a
        change that a calibrated value can carry (a column friction through the rack friction) is otherwise taken up
        by it and never named."""
        adequate = max(settings.adequate_rms_factor, self.over_floor)
        ceiling = max(settings.missing_rms_ceiling, adequate * settings.missing_rms_ceiling
                      / settings.adequate_rms_factor)
        bic = max(settings.bic_missing_threshold, self.bic_per_sample * samples)
        band = max(settings.bic_indistinguishable, self.lead_per_sample * samples)
        return dataclasses.replace(settings, adequate_rms_factor=adequate, missing_rms_ceiling=ceiling,
                                   bic_missing_threshold=bic, bic_indistinguishable=band,
                                   headline_interval_clear_of_zero=True, calibrated_parameters=(),
                                   calibrated_with_angle=(), calibrated_with_angle_offsets=())

    def as_dict(self) -> dict:
        return {"over_floor": self.over_floor, "bic_per_sample": self.bic_per_sample,
                "lead_per_sample": self.lead_per_sample, "method": self.method,
                "parts": [dict(p) for p in self.parts]}
