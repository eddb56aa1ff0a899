"""A car's baseline: what its healthy records fix, and later records judged against it.

No model of a real car reaches a 12-bit sensor's noise floor: every record of it, its healthy ones included, carries
something the model lacks. The question its owner asks after a repair or a thousand kilometres is what changed.
:func:`learn_baseline` learns from the healthy records everything they fix:

- the car's calibrated parameters, each with its 95 % interval (:meth:`parksteer.diagnose.calibrate.Fit.intervals`);
- what the healthy car has that the model lacks (:class:`HeldForm`): the absolute diagnosis's verdict and, where it
  is not ``adequate``, the car's own form: the named library candidate at its fitted strength, or the form the
  residual's signature points to (:func:`parksteer.diagnose.suggest.suggest`) with its fitted strengths;
- how far apart healthy data are (:class:`Threshold`): each healthy record is judged against the form fitted again
  on the others (leave one out), with the sensor's thresholds; with one record, each half of it (cut between its
  reversals) under the form and calibration fitted on the whole record (a half replayed alone would start
  mid-stroke from rest, a start the car never had, so its error is read off the whole record's fit: in-sample, and
  said so). Of each part, the weighted RMS error in noise floors with the form held and the best candidate's BIC
  gain per sample; what "as the baseline" allows is the one-sided 95 % prediction bound for one more healthy part
  (Student's t over the parts: two parts fix it poorly, and the bound is wide; more healthy records tighten it).

A later record is then diagnosed (``diagnose(..., baseline=...)``, :mod:`parksteer.diagnose.select`) on the model
with the form's strengths HELD at the baseline's values (a change cannot be absorbed by fitting the quirk again),
starting from the baseline's calibrated values, and with the threshold above in place of the sensor floor's:
``adequate`` is "as the baseline", ``missing`` "changed: X", ``unexplained`` "changed, outside the library". The
uncertainty of the held strengths reaches the verdict through that threshold: a left-out part is judged against
strengths fitted without it, so their estimation error is inside the spread it measures. Where the records fix
the form poorly, the spread, and so the threshold, is wide. The diagnosis's JSON names the baseline
(``relative_to``: its file and content hash, the threshold and how it was found).

The file (:meth:`Baseline.write`, :mod:`parksteer.diagnose.baseline_file`) is TOML a person reads: every value with
its interval and source.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field

from ..errors import UsageError
from ..model.symbolic.components import Effect, discover_effects, resolve_effects
from ..model.symbolic.shapes import shape_effect
from ..parameters import Parameters
from .settings import DEFAULT_SETTINGS, DiagnosisSettings

FORMAT = "parksteer baseline 1"


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
    """What "as the baseline" allows: `over_floor`, the weighted RMS error in noise floors, and `bic_per_sample`, the
    best candidate's BIC gain per sample, that one more healthy part stays under (95 % prediction bounds over the
    healthy parts with the form held); `method` says how the parts were made; `parts` lists each."""

    over_floor: float
    bic_per_sample: float
    method: str
    parts: tuple[dict, ...] = ()

    def settings_for(self, settings: DiagnosisSettings, samples: int) -> DiagnosisSettings:
        """`settings` with the thresholds of "as the baseline" for a later record of `samples` samples: the adequate
        factor at least the healthy spread, the ceiling on a named effect's error raised in proportion, and the BIC
        gain a candidate needs at least what healthy parts reached at the same length."""
        adequate = max(settings.adequate_rms_factor, self.over_floor)
        ceiling = max(settings.missing_rms_ceiling, adequate * settings.missing_rms_ceiling
                      / settings.adequate_rms_factor)
        bic = max(settings.bic_missing_threshold, self.bic_per_sample * samples)
        return dataclasses.replace(settings, adequate_rms_factor=adequate, missing_rms_ceiling=ceiling,
                                   bic_missing_threshold=bic)

    def as_dict(self) -> dict:
        return {"over_floor": self.over_floor, "bic_per_sample": self.bic_per_sample, "method": self.method,
                "parts": [dict(p) for p in self.parts]}


@dataclass(frozen=True)
class Baseline:
    """What a car's healthy records fix (module docstring). `vehicle`: the car's file as given; `fingerprint`: its
    values' hash (:func:`vehicle_fingerprint`); `effects`: the model's; `calibrated`: key -> {value, ci95,
    standard_error}; `verdict`, `over_floor`: the absolute diagnosis of the healthy records; `form`: what they have
    that the model lacks (None when it is adequate); `identified_vehicle`: for an assisted car whose file gave only
    its gear's data, the vehicle file as ``parksteer assist identify`` writes it from these records."""

    vehicle: str | None
    fingerprint: str
    records: tuple[str, ...]
    effects: tuple[str, ...]
    calibrated: dict
    verdict: str
    over_floor: float
    form: HeldForm | None
    threshold: Threshold
    identified_vehicle: str | None = None
    path: str | None = None
    content_hash: str | None = None

    def write(self, path) -> Baseline:
        """Write the baseline as TOML to `path`; returns it with its path and content hash."""
        from .baseline_file import write_baseline

        return write_baseline(self, path)

    @classmethod
    def read(cls, path) -> Baseline:
        """The baseline written to `path` (a corrupt or foreign file: one line naming it and the key, exit 2)."""
        from .baseline_file import read_baseline

        return read_baseline(path)

    def relative_to(self) -> dict:
        """What a diagnosis against this baseline names it by (JSON ``relative_to``)."""
        return {"baseline": self.path, "content_hash": self.content_hash, "records": list(self.records),
                "verdict": self.verdict, "form": None if self.form is None else self.form.effect,
                "threshold": self.threshold.as_dict()}

    def check_vehicle(self, params: Parameters) -> None:
        if vehicle_fingerprint(params) != self.fingerprint:
            where = self.path or "baseline"
            raise UsageError(f"{where}: key 'vehicle.fingerprint': the baseline is of another car "
                             f"({self.vehicle}); give the vehicle file it was learnt with")

    def parameters(self, params: Parameters) -> Parameters:
        """The car's parameters a later record is diagnosed with: the identified vehicle file's where the baseline
        identified the assist, with the held form's values."""
        if self.identified_vehicle is not None:
            from .baseline_file import identified_parameters

            params = identified_parameters(self.identified_vehicle)
        if self.form is None:
            return params
        self.form.model_effect()  # a signature's form registers its quantities
        return params.with_overrides(self.form.values)

    def model(self, effects, registry: dict[str, Effect] | None = None) -> list[Effect]:
        """The model's `effects` with the held form added."""
        base = effects if isinstance(effects, list) and all(isinstance(e, Effect) for e in effects) \
            else resolve_effects(effects)
        if self.form is None or any(e.name == self.form.effect for e in base):
            return list(base)
        return sorted([*base, self.form.model_effect(registry)], key=lambda e: e.name)

    @property
    def held(self) -> dict[str, float]:
        """The strengths a later diagnosis holds (not fitted)."""
        return {} if self.form is None else {k: float(v["value"]) for k, v in self.form.strengths.items()}

    @property
    def start(self) -> dict[str, float]:
        """The calibrated values, where a later calibration starts."""
        return {k: float(v["value"]) for k, v in self.calibrated.items()}


def learn_baseline(files, params: Parameters, effects=None, settings: DiagnosisSettings = DEFAULT_SETTINGS, *,
                   vehicle=None, progress=None, registry: dict[str, Effect] | None = None,
                   workers: int = 1) -> Baseline:
    """Learn a car's baseline from its healthy records (module docstring).

    `files`, `params`, `effects`, `registry`, `settings`, `workers`: as :func:`parksteer.diagnose.select.diagnose`
    takes them (the records loaded by :func:`parksteer.diagnose.problem.load_files`). `vehicle`: the vehicle file's
    path (named in the baseline; for an assisted car whose file gives only its gear's data, its assist is first
    identified from these records, :mod:`parksteer.diagnose.assist_identify`). `progress`: None (quiet) or a
    callable given one line at each step."""
    from .baseline_learn import learn

    return learn(files, params, effects, settings, vehicle=vehicle, progress=progress, registry=registry,
                 workers=workers)

