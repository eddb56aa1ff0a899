"""One row per benchmark case: how a diagnosis fared against the case's truth, typed.

Each benchmark scores its cases into rows of its own kind (:class:`BenchmarkRow` for the hidden-effect
benchmark, :mod:`parksteer.experiments.benchmark`; :class:`VariationRow` for the variation benchmark,
:mod:`parksteer.experiments.variations`; :class:`OutclassRow` for the out-of-class one,
:mod:`parksteer.experiments.outclass`); the summaries and the figures (:mod:`parksteer.figures.diagnose`) read
them by attribute. A row's fields, in order, are the columns of its benchmark's CSV (:func:`csv_columns`).

The error ratios share one spelling: ``<model>_over_floor`` is that model's weighted RMS error over the noise
floor (``calibrated_over_floor``: the calibrated base model; ``after_over_floor``: with the named effect;
``nearest_after_over_floor``: with the strongly evidenced nearest candidate); ``plain_after_over_floor`` is the
plain (unweighted) RMS error with the named effect over the same floor.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path

from ..errors import UsageError

# The file of a case's rows in its job's folder (<folder>/<case><ROW_SUFFIX>), as the batch jobs of the assisted
# benchmarks write them.
ROW_SUFFIX = ".row.json"


@dataclass(frozen=True)
class BenchmarkRow:
    """A hidden-effect benchmark case (:func:`parksteer.experiments.benchmark.outcome`)."""

    name: str
    kind: str  # candidate, null or outside
    hidden: str  # the hidden effect ("nothing" for a null)
    steps: float  # hidden size asked for, converter steps of torque RMS
    steps_actual: float  # the size reached
    said: str  # the named effect, or the verdict
    verdict: str
    indistinguishable: str  # the reported group, space-separated
    named_first: bool
    named_or_group: bool
    calibrated_over_floor: float
    after_over_floor: float  # nan without a named effect
    plain_after_over_floor: float
    replays: int
    wall_s: float


@dataclass(frozen=True)
class VariationRow:
    """A variation benchmark case (:func:`parksteer.experiments.variations.outcome`)."""

    name: str
    variation: str
    replicate: int
    hidden: str
    steps: float
    steps_actual: float
    steps_observable: float = 0.0  # the part of the hidden change the calibration cannot absorb, steps RMS
    verdict: str = "adequate"
    effect: str = ""
    indistinguishable: str = ""
    named: bool = False
    false_alarm: bool = False
    hidden_confounded_with: str = ""
    hidden_separated_by: str = ""  # case/surface where the confound tests say it would show
    torque_lag_s: float = 0.0  # the logger's true lag
    torque_lag_found_s: float = 0.0  # the diagnosis's, mean over the files
    calibrated_over_floor: float = 1.0
    after_over_floor: float | None = None
    covered: int = 0
    intervals: int = 0
    not_covered: str = ""
    wall_s: float | None = None


@dataclass(frozen=True)
class OutclassRow:
    """An out-of-class benchmark case (:func:`parksteer.experiments.outclass.outcome`)."""

    name: str
    kind: str  # rival or null
    hidden: str
    steps: float
    steps_actual: float
    closest: str
    said: str
    relation: str
    closest_in_group: bool
    indistinguishable: str
    bic_margin: float | None
    best_delta_bic: float | None
    explained_fraction: float | None
    calibrated_over_floor: float
    after_over_floor: float | None
    nearest: str
    nearest_after_over_floor: float | None
    confident_wrong: bool
    adequate_at_3_steps: bool
    target_met: bool
    wall_s: float | None


def as_dict(row) -> dict:
    """A row as a plain dict (for JSON)."""
    return dataclasses.asdict(row)


def csv_columns(rows, leave_out=frozenset(), none=None) -> dict[str, list]:
    """The rows as CSV columns, in field order, without the fields `leave_out` names; a None written as `none`
    where given."""
    if not rows:
        return {}
    names = [f.name for f in dataclasses.fields(rows[0]) if f.name not in leave_out]
    if none is None:
        return {name: [getattr(r, name) for r in rows] for name in names}
    return {name: [none if getattr(r, name) is None else getattr(r, name) for r in rows] for name in names}


def read_case_files(folders, names: list[str], benchmark: str) -> list:
    """The JSON of each case of `names` that the batch jobs wrote into `folders` (<case><ROW_SUFFIX>), in the order
    of `names`; a case with no file, or with files in two folders, is refused in one line naming the `benchmark`."""
    found: dict[str, Path] = {}
    for folder in map(Path, folders):
        for path in sorted(folder.glob(f"*{ROW_SUFFIX}")):
            name = path.name[:-len(ROW_SUFFIX)]
            if name in found:
                raise UsageError(f"{path}: case {name} has rows in {found[name].parent} as well")
            found[name] = path
    missing = [name for name in names if name not in found]
    if missing:
        raise UsageError(f"{benchmark}: no rows of case {missing[0]} in {', '.join(map(str, folders))}")
    return [json.loads(found[name].read_text(encoding="utf-8")) for name in names]
