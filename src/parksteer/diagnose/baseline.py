"""A car's baseline: what its healthy records fix, and later records judged against it.

:func:`learn_baseline` learns from a car's healthy records its calibrated parameters with their 95 % intervals
(:meth:`parksteer.diagnose.fitting.Fit.intervals`), what the healthy car has that the model lacks
(:class:`HeldForm`: the named library candidate at its fitted strength, or the form the residual's signature
points to, :func:`parksteer.diagnose.suggest.suggest`, its strengths fitted only where no calibrated value can carry
them, :mod:`parksteer.diagnose.baseline_share`), and how far apart healthy data are (:class:`Threshold`,
out of sample: leave one record out, or with one record each of its 2 s blocks left out; the one-sided 95 %
prediction bound, in noise floors, for one more healthy record). A later record is diagnosed
(``diagnose(..., baseline=...)``) with the form's strengths and the car's calibrated values held at the baseline's
(nothing calibrated again), and with that threshold where it is above the sensor's, a name confident only beyond
the lead over the second best that healthy parts reach (:meth:`Threshold.settings_for`): ``adequate`` reads "as the
baseline", ``missing`` "changed: X", ``unexplained`` "changed, outside the library"; against a baseline no
candidate whose 95 % interval holds 0 is named. The diagnosis's JSON names the baseline (``relative_to``).
The file (:meth:`Baseline.write`, :mod:`parksteer.diagnose.baseline_file`) is TOML a person reads, every value with its
interval and source. Why and how: docs/diagnosis.md, "Against a car's baseline".
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..errors import UsageError
from ..model.symbolic.components import Effect, resolve_effects, with_effect_quantities
from ..parameters import Parameters
from .baseline_changed import with_changed_values
from .baseline_file import baseline_text, content_hash, identified_parameters, parse_baseline, read_bytes
from .baseline_form import FORMAT, HEADLINE, HeldForm, Threshold, vehicle_fingerprint
from .baseline_learn import learn
from .settings import DEFAULT_SETTINGS, DiagnosisSettings

__all__ = ["FORMAT", "Baseline", "HeldForm", "Threshold", "learn_baseline", "vehicle_fingerprint"]


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
        """Write the baseline as TOML to `path` (its text read back first: nothing is written that would not read);
        returns it with its path and content hash."""
        import tomllib
        from pathlib import Path

        text = baseline_text(self)
        Baseline(**parse_baseline(tomllib.loads(text), str(path)))
        data = text.encode("utf-8")
        Path(path).write_bytes(data)
        return dataclasses.replace(self, path=str(path), content_hash=content_hash(data))

    @classmethod
    def read(cls, path) -> Baseline:
        """The baseline written to `path`, with its path and content hash (a damaged or foreign file: one line
        naming it and the key, exit 2)."""
        data, parsed = read_bytes(path)
        return cls(**parse_baseline(parsed, str(path)), path=str(path), content_hash=content_hash(data))

    def relative_to(self) -> dict:
        """What a diagnosis against this baseline names it by (JSON ``relative_to``)."""
        return {"baseline": self.path, "content_hash": self.content_hash, "records": list(self.records),
                "verdict": self.verdict, "form": None if self.form is None else self.form.effect,
                "threshold": self.threshold.as_dict(), "headline": HEADLINE,
                "calibrated": {k: {"value": float(v["value"]),
                                   "ci95": [float(c) for c in v["ci95"]] if "ci95" in v else None}
                               for k, v in self.calibrated.items()}}

    def check(self, params: Parameters, effects=None) -> None:
        """Refuse, in one line naming the file and the key, records of another car (its values' hash) or a model of
        other effects than the baseline's (`effects`, before the form is added)."""
        where = self.path or "baseline"
        if vehicle_fingerprint(params) != self.fingerprint:
            raise UsageError(f"{where}: key 'vehicle.fingerprint': the baseline is of another car "
                             f"({self.vehicle}); give the vehicle file it was learnt with")
        if effects is not None:
            names = tuple(sorted(e.name for e in effects))
            if names != tuple(sorted(self.effects)):
                raise UsageError(f"{where}: key 'records.model': the baseline's model is {', '.join(self.effects)}; "
                                 f"these records are diagnosed with {', '.join(names)} (the same --effects and "
                                 "--with-assist as the baseline)")

    def parameters(self, params: Parameters) -> Parameters:
        """The car's parameters a later record is diagnosed with: the identified vehicle file's where the baseline
        identified the assist, with the calibrated values and the held form's values."""
        if self.identified_vehicle is not None:
            params = identified_parameters(self.identified_vehicle)
        if self.form is None:
            return params.with_overrides(self.start)
        return with_effect_quantities(params, [self.form.model_effect()]).with_overrides(
            {**self.start, **self.form.values})

    def model(self, effects, registry: dict[str, Effect] | None = None) -> list[Effect]:
        """The model's `effects` with the held form added."""
        base = effects if isinstance(effects, list) and all(isinstance(e, Effect) for e in effects) \
            else resolve_effects(effects)
        if self.form is None or any(e.name == self.form.effect for e in base):
            return list(base)
        return sorted([*base, self.form.model_effect(registry)], key=lambda e: e.name)

    def table(self, stages, settings: DiagnosisSettings) -> tuple:
        """The stages a later record is diagnosed with: `stages` with each calibrated value the baseline holds a
        candidate of its own, ``changed:<key>`` (:mod:`parksteer.diagnose.baseline_changed`; `settings` say which
        are fitted as angles)."""
        return with_changed_values(tuple(stages), tuple(self.calibrated), settings)

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
    identified from these records, :mod:`parksteer.diagnose.identify.assist_identify`). `progress`: None (quiet) or a
    callable given one line at each step."""
    return learn(Baseline, files, params, effects, settings, vehicle=vehicle, progress=progress, registry=registry,
                 workers=workers)

