"""What a diagnosis knows at each stage (:class:`DiagnosisState`), and what it found (:class:`Diagnosis`).

Both are frozen: a stage (:mod:`parksteer.diagnose.stages`) takes a state and returns a new one
(``dataclasses.replace``), so nothing a stage did can change what an earlier stage's state holds, and
nothing the caller passed in is changed (the files are copied into the state's problem, with what the
stages derive for them, before the first stage). The state owns the diagnosis's settings: a stage reads
them from the state, and the one that diagnoses again with other settings (the torque lags held) runs
the table on a new state that carries them.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
import numpy as np

from ..model.symbolic.components import Effect
from .fitting import Fit
from .candidates import Score, Signature
from .problem import Problem
from .statistics import fit_statistics
from ..frozen import FrozenDict as BaseFrozenDict
from .settings import DEFAULT_SETTINGS, DiagnosisSettings

VERDICTS = ("missing", "adequate", "unexplained")


class FrozenDict(BaseFrozenDict):
    """A diagnosis's read-only mapping (it pickles, so a result may cross a process fork)."""

    refusal = "a diagnosis's mapping is read-only: make a new one"


def frozen_mapping(items=()) -> FrozenDict:
    """A read-only copy of `items` (a mapping or pairs)."""
    return FrozenDict(items)


@dataclass(frozen=True)
class Candidate:
    """One candidate's signature, score and (for the best few) refit and BIC gain."""

    signature: Signature
    score: Score
    refit: Fit | None = None
    delta_bic: float | None = None

    @property
    def name(self) -> str:
        return self.signature.effect.name

    def rss_after(self, base_rss: float) -> float:
        return self.refit.rss if self.refit is not None else base_rss - self.score.removed_rss


@dataclass(frozen=True)
class Separation:
    """Where two fitted models differ most, among the conditions the data do not cover."""

    effect: str
    delta_bic: float
    case: str
    surface: str
    predicted_difference_rms_Nm: float
    over_noise_floor: float
    conditions: tuple[dict, ...]


def confounded_candidates(candidates, settings: DiagnosisSettings) -> tuple[Candidate, ...]:
    """The observable candidates whose signature is mostly a calibrated parameter's (identifiable fraction below
    the settings' confounded_fraction): these data cannot tell them from a change of that parameter."""
    return tuple(c for c in candidates
                 if c.signature.observable and c.score.identifiable_fraction < settings.confounded_fraction)


@dataclass(frozen=True)
class DiagnosisState:
    """The inputs of a diagnosis and what its stages have found so far (None: not yet).

    Inputs: `settings` (the one owner of the method's settings), `problem` (the caller's files, copied, with
    what the stages derived for them: replay uncertainty, torque lag, whether the angle is fitted), the model's
    `base` effects, the candidate `registry`, the calibrated `strengths` and `start` values, `progress` (prints
    a line unless quiet), `table` (the stages this state runs through) and the strengths `held` at a baseline's
    values (:mod:`parksteer.diagnose.baseline`).

    Found: one field per built-in stage; `outputs` holds what a stage added later keeps (by its name, read by
    the report's section for it), so that a new stage needs no field here.
    """

    settings: DiagnosisSettings
    problem: Problem
    base: tuple[Effect, ...]
    registry: Mapping[str, Effect]
    strengths: Mapping[str, float] | None = None
    start: Mapping[str, float] | None = None
    progress: Callable[[str], None] = field(default=lambda message: None, repr=False)
    table: tuple = ()
    held: Mapping[str, float] | None = None  # strengths held at a baseline's values, never fitted
    nominal: tuple[np.ndarray, ...] | None = None
    calibration: Fit | None = None
    candidates: tuple[Candidate, ...] = ()
    untestable: tuple[str, ...] = ()
    best: str | None = None  # the name of the candidate with the largest BIC gain
    n_eff: float | None = None
    rho: float | None = None
    verdict: str | None = None
    explained_fraction: float | None = None
    indistinguishable: tuple[Separation, ...] = ()
    identification: tuple[dict, ...] = ()
    confound_tests: Mapping[str, dict | None] = field(default_factory=frozen_mapping)
    outputs: Mapping[str, object] = field(default_factory=frozen_mapping)
    timings_s: Mapping[str, float] = field(default_factory=frozen_mapping)
    replays_by_stage: Mapping[str, int] = field(default_factory=frozen_mapping)  # replays run when each ended

    @property
    def files(self):
        return self.problem.files

    @property
    def start_values(self) -> dict[str, float]:
        return dict(self.start or {})

    @property
    def best_candidate(self) -> Candidate | None:
        return next((c for c in self.candidates if c.name == self.best), None) if self.best is not None else None

    def with_output(self, name: str, value) -> DiagnosisState:
        """This state with `value` kept under `name` (a stage added to the table keeps its result here)."""
        return replace(self, outputs=frozen_mapping({**self.outputs, name: value}))

    def with_timing(self, name: str, seconds: float) -> DiagnosisState:
        return replace(self, timings_s=frozen_mapping({**self.timings_s, name: seconds}))

    def with_cost(self, name: str, seconds: float, replays: int) -> DiagnosisState:
        """This state with stage `name`'s time and the `replays` run so far when it ended (the count, unlike the
        time, is the same on any machine)."""
        return replace(self.with_timing(name, seconds),
                       replays_by_stage=frozen_mapping({**self.replays_by_stage, name: replays}))

    def result(self, replays: int) -> Diagnosis:
        """What the diagnosis found, with the count of `replays` it ran (the replay engine's)."""
        return Diagnosis(self.problem, self.base, self.nominal, self.calibration, self.candidates, self.untestable,
                         self.verdict, self.best_candidate, self.indistinguishable, self.n_eff, self.rho,
                         self.explained_fraction, self.timings_s, self.settings, self.identification,
                         self.confound_tests, self.outputs, self.replays_by_stage, replays)


@dataclass(frozen=True)
class Diagnosis:
    """Everything :func:`parksteer.diagnose.select.diagnose` found (its JSON form, :mod:`parksteer.reporting.report`,
    is documented by the schema ``parksteer/data/diagnosis.schema.json``)."""

    problem: Problem
    base_effects: tuple[Effect, ...]
    nominal_predictions: tuple[np.ndarray, ...]
    calibration: Fit
    candidates: tuple[Candidate, ...]
    untestable: tuple[str, ...]
    verdict: str
    best: Candidate | None
    indistinguishable: tuple[Separation, ...]
    n_eff: float
    rho: float
    explained_fraction: float | None
    timings_s: Mapping[str, float] = field(default_factory=frozen_mapping)
    settings: DiagnosisSettings = DEFAULT_SETTINGS
    identification: tuple[dict, ...] = ()  # what these data fix (stages/identify.py)
    # where each confounded candidate would show, by name (stages/confound.py; empty where the settings say not)
    confound_tests: Mapping[str, dict | None] = field(default_factory=frozen_mapping)
    outputs: Mapping[str, object] = field(default_factory=frozen_mapping)  # what added stages keep, by name
    replays_by_stage: Mapping[str, int] = field(default_factory=frozen_mapping)  # replays run when each stage ended
    replays: int = 0  # every replay the diagnosis ran

    @property
    def effect(self) -> str | None:
        return self.best.name if self.verdict == "missing" and self.best is not None else None

    @property
    def effects(self) -> list[Effect]:
        """Every effect the diagnosis replayed: the model's, the calibrated fit's, each candidate's and its refit's."""
        refits = [e for c in self.candidates if c.refit is not None for e in c.refit.effects]
        return [*self.base_effects, *self.calibration.effects, *(c.signature.effect for c in self.candidates), *refits]

    @property
    def ranked(self) -> list[Candidate]:
        refitted = sorted((c for c in self.candidates if c.refit is not None), key=lambda c: -(c.delta_bic or 0.0))
        others = sorted((c for c in self.candidates if c.refit is None), key=lambda c: -c.score.statistic)
        return refitted + others

    @property
    def confounded(self) -> tuple[Candidate, ...]:
        return confounded_candidates(self.candidates, self.settings)

    @property
    def unobservable(self) -> list[str]:
        return [c.name for c in self.candidates if not c.signature.observable]

    def statistics(self, predictions) -> dict:
        return fit_statistics(self.problem, predictions)
