"""Sweep declarations: a YAML file naming a base case, the effects and the design axes of a study.

A declaration (SI units throughout)::

    name: design                    # outputs: results/sweeps/design/, figures/sweep_design.*
    description: one paragraph
    base_case: unladen              # a Table B1 case of the parameter file
    effects: null                   # an effects spec as for `parksteer simulate` (null: the paper's five)
    surface: ground                 # or air_bearing
    axes:                           # the full factorial, first axis slowest
      tyre.tyre_pressure: [122500, 180000, 240000, 300000]
      design.front_axle_load: {start: 5000, stop: 9000, num: 3}
    full_axes: {...}                # optional: replaces `axes` when the pipeline asks for the full sweep
    points:                         # instead of axes: a declared list of points
      - {tyre.tyre_pressure: 200000, design.extra_offset: 0.02}
    map: {x: KEY, y: KEY, panels: KEY, hold: {KEY: VALUE}, quantity: peak_torque_Nm}
    braked: braked_wheels           # compare with the wheels braked: an effect with a brake_fraction
                                    # parameter (simulated at its maximum), rig_theory, or none (default)
    assistance:                     # the torque above which the car needs power assistance
      rim_force: {value: 150, unit: N, source: "..."}
      rim_radius: {value: 0.19, unit: m, source: "..."}

An axis key is any model parameter `simulate` accepts as an override (``tyre.tyre_pressure``,
``case.chassis_mass``, ``steering.rack_friction_force``, ...) or a design variable
(``design.*``, see :data:`.keys.DESIGN_VARIABLES`) that changes several of them together so that the
model stays consistent (statics of the wheel loads, the axis through the wheel centre).
Every problem is one line naming the file and the key (:class:`SweepError`).
"""

from __future__ import annotations

import gc
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..names import SURFACES
from ..parameters import Parameters
from .design import SweepError
from .expansion import DEFAULT_BATCH_SIZE, Grid, batch_points, expand_grid, point_id_maker, point_ids
from .fields import (
    BRAKED_NONE,
    AssistanceThreshold,
    MapSpec,
    check_effects,
    read_axes,
    read_braked,
    read_declaration,
    read_map,
    read_points,
    read_threshold,
)
from .model_check import check_model_consistency, grid_check_points

TOP_LEVEL_KEYS = {"name", "description", "base_case", "effects", "surface", "axes", "full_axes", "points", "map",
                  "assistance", "braked"}
# The declaration the pipeline sweeps when the configuration names none (config/config.yaml, sweep).
DEFAULT_SWEEP_FILE = "config/sweeps/design.yaml"


@dataclass(frozen=True, slots=True)
class SweepPoint:
    """One point of a sweep: its position in the expansion, its id and its axis values (SI).

    The id hashes only what the point simulates (case, effects, surface, values), not its position, so that
    extending an axis or reordering the declaration leaves every existing point's id, and its result, valid.
    """

    index: int
    id: str
    values: dict[str, float]


@dataclass(frozen=True)
class Sweep:
    """A validated, expanded sweep declaration."""

    path: Path
    name: str
    description: str
    base_case: str
    effects: str | None
    surface: str
    axes: dict[str, tuple[float, ...]]  # empty for a declared list of points
    points: tuple[SweepPoint, ...]
    map: MapSpec | None
    assistance: AssistanceThreshold | None
    full: bool
    braked: str = BRAKED_NONE
    braked_effects: tuple[str, ...] | None = None  # the effect set of the braked run (an effect method only)
    # False: a grid read without its expansion (load_sweep(expand=False)); `points` is empty, a point's values
    # are decoded from its index (values_at) and a record's index from its values (locate)
    expanded: bool = True
    _by_id: dict[str, SweepPoint] = field(default_factory=dict, repr=False, compare=False)
    _batches: dict[int, dict[str, tuple[str, ...]]] = field(default_factory=dict, repr=False, compare=False)
    _grid: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        self._by_id.update({p.id: p for p in self.points})

    @property
    def n_points(self) -> int:
        return len(self.points) if self.expanded else math.prod(len(v) for v in self.axes.values())

    def _unexpanded(self, what: str):
        if not self.expanded:
            raise SweepError(f"{self.path}: {what} needs the sweep expanded (load_sweep with expand=True)")

    def values_at(self, index: int) -> dict[str, float]:
        """The values of point `index` (of the expansion's order; a grid's first axis slowest)."""
        if self.expanded:
            return dict(self.points[index].values)
        return Grid(self.axes)[index]

    def id_at(self, index: int) -> str:
        """The id of point `index`."""
        if self.expanded:
            return self.points[index].id
        return self._id_maker()(self.values_at(index))

    def _id_maker(self):
        if "id" not in self._grid:
            self._grid["id"] = point_id_maker(self.base_case, self.effects, self.surface)
        return self._grid["id"]

    def locate(self, point_id: str, values: dict[str, float]) -> int:
        """The index of the sweep's point of id `point_id`, whose values are `values`, or -1 if it has none.

        An expanded sweep looks the id up. A grid without its expansion finds the index from the values (each
        value's position on its axis, the digits of the index, the first axis slowest) and checks that the point
        there has that id (the id hashes what the point simulates, so a record of another case, effect set or
        surface is no point of this sweep): no point is held, about 2 us a record."""
        if self.expanded:
            point = self._by_id.get(point_id)
            return point.index if point is not None else -1
        if "positions" not in self._grid:
            stride, strides = 1, {}
            for key in reversed(list(self.axes)):
                strides[key] = stride
                stride *= len(self.axes[key])
            self._grid["positions"] = [(key, {v: i * strides[key] for i, v in enumerate(self.axes[key])})
                                       for key in self.axes]
        positions = self._grid["positions"]
        if len(values) != len(positions):
            return -1
        index = 0
        for key, offsets in positions:
            offset = offsets.get(values.get(key))
            if offset is None:
                return -1
            index += offset
        return index if self._id_maker()(values) == point_id else -1

    @property
    def model_sets(self) -> dict[str, Any]:
        """The effect sets whose compiled models the points need: "free" (as declared) and "braked" if simulated."""
        sets: dict[str, Any] = {"free": self.effects}
        if self.braked_effects is not None:
            sets["braked"] = list(self.braked_effects)
        return sets

    @property
    def point_ids(self) -> list[str]:
        self._unexpanded("point_ids")
        return [p.id for p in self.points]

    @property
    def keys(self) -> list[str]:
        """Every parameter key that varies, in declaration order."""
        if self.axes:
            return list(self.axes)
        seen: dict[str, None] = {}
        for p in self.points:
            seen.update(dict.fromkeys(p.values))
        return list(seen)

    def batches(self, batch_size: int = DEFAULT_BATCH_SIZE) -> dict[str, tuple[str, ...]]:
        """The points in batches of about `batch_size`, batch id -> point ids (see :func:`batch_points`); formed
        once per batch size and kept, so that asking for every batch's spec sorts and hashes the points once."""
        if batch_size not in self._batches:
            self._batches[batch_size] = batch_points(self.point_ids, batch_size)
        return self._batches[batch_size]

    def batch_spec(self, batch_id: str, batch_size: int = DEFAULT_BATCH_SIZE) -> dict[str, Any]:
        """Everything a batch job needs: the spec of each of its points, in id order."""
        batches = self.batches(batch_size)
        if batch_id not in batches:
            raise SweepError(f"{self.path}: no batch {batch_id!r} in sweep {self.name} at batch size {batch_size}")
        return {"sweep": self.name, "batch": batch_id, "points": [self.point_spec(i) for i in batches[batch_id]]}

    @property
    def shared_spec(self) -> dict[str, Any]:
        """What every point spec of this sweep holds besides its id and values (see :meth:`point_spec`)."""
        return {
            "sweep": self.name,
            "case": self.base_case,
            "effects": self.effects,
            "surface": self.surface,
            "braked": self.braked,
            "braked_effects": list(self.braked_effects) if self.braked_effects is not None else None,
        }

    def find(self, point_id: str) -> SweepPoint | None:
        """The point of id `point_id`, or None if the sweep has none."""
        self._unexpanded("find")
        return self._by_id.get(point_id)

    def point(self, point_id: str) -> SweepPoint:
        self._unexpanded("point")
        try:
            return self._by_id[point_id]
        except KeyError:
            raise SweepError(f"{self.path}: no point {point_id!r} in sweep {self.name}") from None

    def point_spec(self, point_id: str) -> dict[str, Any]:
        """Everything a point job needs, as plain data (Snakemake passes it as a rule parameter).

        It holds nothing that depends on the point's position in the sweep, so a job reruns only when what it
        simulates changes.
        """
        point = self.point(point_id)
        return compose_point_spec(self.shared_spec, point.id, point.values)


def compose_point_spec(shared: dict[str, Any], point: str, values: dict[str, float]) -> dict[str, Any]:
    """A point spec from the sweep's shared part (Sweep.shared_spec), the point's id and its values."""
    return {"sweep": shared["sweep"], "point": point, "case": shared["case"], "effects": shared["effects"],
            "surface": shared["surface"], "braked": shared["braked"],
            "braked_effects": list(shared["braked_effects"]) if shared["braked_effects"] is not None else None,
            "values": dict(values)}


def load_sweep(path: str | Path, params: Parameters, full: bool = False, expand: bool = True) -> Sweep:
    """Read, validate and expand a sweep declaration against the parameter file `params`.

    full: use `full_axes` (the large version of the study) instead of `axes`.
    expand: False leaves a grid's points unexpanded (Sweep.expanded; the gathering of a million points needs
    their number, each one's index from its values and the id there, not the 0.45 kB a point the expansion
    holds). Every point is checked as with the expansion, each combination of the values the check reads once
    (:func:`grid_check_points`). A declared list of points is expanded either way (the file holds it).

    Python's cyclic garbage collector is paused meanwhile: the expansion allocates a few objects per point, none
    of them in a cycle, and each collection it triggers walks every object made so far (a million points: about
    2 s of 7).
    """
    from ..model.symbolic.components import with_effect_quantities

    params = with_effect_quantities(params)  # an axis may be an installed effect's quantity
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _load_sweep(Path(path), params, full, expand)
    finally:
        if enabled:
            gc.enable()


def _load_sweep(path: Path, params: Parameters, full: bool, expand: bool = True) -> Sweep:
    """load_sweep with the garbage collector paused."""
    doc = read_declaration(path)
    unknown = sorted(set(doc) - TOP_LEVEL_KEYS)
    if unknown:
        raise SweepError(f"{path}: {unknown[0]}: unknown field (known: {', '.join(sorted(TOP_LEVEL_KEYS))})")
    name = doc.get("name")
    if not isinstance(name, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        raise SweepError(f"{path}: name: {name!r} must be lower-case letters, digits and _ (it names files)")
    base_case = doc.get("base_case")
    if base_case not in params.cases:
        raise SweepError(f"{path}: base_case: {base_case!r} is not a case of {params.path} "
                         f"(known: {', '.join(params.case_names)})")
    effects = doc.get("effects")
    if effects is not None and not isinstance(effects, str):
        raise SweepError(f"{path}: effects: expected an effects spec string or null")
    check_effects(path, effects)
    surface = doc.get("surface", "ground")
    if surface not in SURFACES:
        raise SweepError(f"{path}: surface: {surface!r} is not one of {', '.join(SURFACES)}")
    description = doc.get("description") or ""
    if not isinstance(description, str):
        raise SweepError(f"{path}: description: expected text")

    if ("axes" in doc) == ("points" in doc):
        raise SweepError(f"{path}: declare either axes (a full factorial) or points (a list), not both or neither")
    if "points" in doc:
        if full:
            raise SweepError(f"{path}: full_axes: the full sweep needs axes; this sweep declares points")
        axes: dict[str, tuple[float, ...]] = {}
        values_list = read_points(path, doc["points"])
    else:
        field_name = "full_axes" if full else "axes"
        if full and "full_axes" not in doc:
            raise SweepError(f"{path}: full_axes: the full sweep was asked for but is not declared")
        axes = read_axes(path, field_name, doc[field_name])
        values_list = expand_grid(axes) if expand else None
    if "full_axes" in doc and not full:  # validate the other half of the file as well, every point of it
        other = read_axes(path, "full_axes", doc["full_axes"])
        if expand:
            check_model_consistency(path, params, base_case, effects, expand_grid(other),
                                     what="full_axes point")
        else:
            check_model_consistency(path, params, base_case, effects, *grid_check_points(params, base_case, other),
                                     what="full_axes point")

    if values_list is None:
        check_model_consistency(path, params, base_case, effects, *grid_check_points(params, base_case, axes))
        points: tuple[SweepPoint, ...] = ()
    else:
        check_model_consistency(path, params, base_case, effects, values_list)
        ids = point_ids(base_case, effects, surface, values_list)
        points = tuple(SweepPoint(i, pid, v) for i, (pid, v) in enumerate(zip(ids, values_list)))
    keys = list(axes) if axes else list(dict.fromkeys(k for v in values_list for k in v))
    spec_map = read_map(path, doc["map"], keys, axes, values_list) if doc.get("map") is not None else None
    threshold = read_threshold(path, doc["assistance"]) if doc.get("assistance") is not None else None
    braked, braked_effects = read_braked(path, doc.get("braked", BRAKED_NONE), effects, surface)
    return Sweep(path, name, description.strip(), base_case, effects, surface, axes, points, spec_map, threshold,
                 full, braked, braked_effects, expanded=values_list is not None)
