"""That a sweep's points make a consistent model: effect parameters of an effect in the model, derived values
within their bounds; each combination of the values the check reads checked once."""

from __future__ import annotations

import itertools
import math
import operator
from pathlib import Path
from typing import Any

from ..model.symbolic.components import quantity_of
from ..parameters import Parameters
from .design import SweepError, point_overrides
from .expansion import Grid


# Sections of the parameter file that the model reads (rig and spacers feed only the rig figures).
MODEL_SECTIONS = ("vehicle", "steering", "geometry", "tyre", "input")


def check_model_consistency(path: Path, params: Parameters, case: str, effects: str | None,
                             values_list: list[dict[str, float]], numbers: list[int] | None = None,
                             what: str = "point") -> None:
    """Effect parameters belong to an effect of the sweep's model; derived case values are physical. A problem
    names the point by its position in `values_list`, or by `numbers` at that position (:func:`grid_check_points`)."""
    owners = {k.partition(".")[0] for k in set().union(*values_list)}
    effect_owners = owners - set(MODEL_SECTIONS) - {"case", "design"}
    if effect_owners:
        from ..model.symbolic.components import resolve_effects

        chosen = {e.name for e in resolve_effects(effects)}
        for owner in sorted(effect_owners):
            if owner not in chosen:
                raise SweepError(f"{path}: {owner}: effect is not in this sweep's model "
                                 f"(effects: {effects or 'default'})")
    # A point's derived values depend only on its design values and the direct values point_overrides reads
    # (gravity, unsprung mass, ...), not on those it passes through (tyre.tyre_pressure): points that agree on
    # those share one check, so that a million-point grid checks each combination of its design axes once. Which
    # keys it reads depends only on which keys a point has (its branches test presence), so one traced call per
    # key set tells them.
    relevant_values: dict[tuple[str, ...], Any] = {}  # key set -> the function giving a point's relevant values
    checked: set[tuple] = set()
    for i, values in enumerate(values_list):
        keys = tuple(values)
        relevant = relevant_values.get(keys)
        if relevant is None:
            traced = _KeysRead(values)
            try:
                point_overrides(params, case, traced)
            except SweepError:
                pass  # reported below with the point's number
            read = [k for k in keys if k.startswith("design.") or k in traced.read]
            relevant = relevant_values[keys] = operator.itemgetter(*read) if read else (lambda _: ())
        signature = (keys, relevant(values))
        if signature in checked:
            continue
        try:
            derived = point_overrides(params, case, values)
        except SweepError as exc:
            raise SweepError(f"{path}: {what} {i if numbers is None else numbers[i]}: {exc}") from None
        for key, value in derived.items():
            if key in values:
                continue  # checked with its axis
            q = quantity_of(key)
            if not q.within(value):
                raise SweepError(f"{path}: {what} {i if numbers is None else numbers[i]}: derived {key} = "
                                 f"{value:g} {q.unit} is out of bounds "
                                 f"{q.bounds_text()}")
        checked.add(signature)


def grid_check_points(params: Parameters, case: str, axes: dict[str, tuple[float, ...]]
                ) -> tuple[list[dict[str, float]], list[int]]:
    """The points of the grid `axes` that check_model_consistency tells apart, and their indices: one per
    combination of the values of the keys the check reads (those point_overrides reads of the first point, and
    the design axes), the other keys at their first value; in the grid's order, so the first that fails is the
    grid's first point that fails (of the points sharing a combination, the one with the other digits 0: the
    smallest index), and the check of the whole grid costs those combinations, not its points."""
    keys = list(axes)
    first = {key: values[0] for key, values in axes.items()}
    traced = _KeysRead(first)
    try:
        point_overrides(params, case, traced)
    except SweepError:
        pass  # reported by the check with the point's number
    read = [k for k in keys if k.startswith("design.") or k in traced.read]
    grid = Grid(axes)
    strides = {k: math.prod(grid.sizes[j + 1:]) for j, k in enumerate(keys)}
    values_list, numbers = [], []
    for digits in itertools.product(*(range(len(axes[k])) for k in read)):
        values_list.append({**first, **{k: axes[k][d] for k, d in zip(read, digits)}})
        numbers.append(sum(strides[k] * d for k, d in zip(read, digits)))
    return values_list, numbers


class _KeysRead(dict):
    """A point's values that note which keys are looked up (by [], get or in)."""

    def __init__(self, values: dict[str, float]):
        super().__init__(values)
        self.read: set[str] = set()

    def __getitem__(self, key):
        self.read.add(key)
        return super().__getitem__(key)

    def get(self, key, default=None):
        self.read.add(key)
        return super().get(key, default)

    def __contains__(self, key):
        self.read.add(key)
        return super().__contains__(key)
