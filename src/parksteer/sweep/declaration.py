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
(``design.*``, see DESIGN_VARIABLES) that changes several of them together so that the
model stays consistent (statics of the wheel loads, the axis through the wheel centre).
Every problem is one line naming the file and the key (:class:`SweepError`).
"""

from __future__ import annotations

import gc
import hashlib
import itertools
import json
import math
import operator
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..errors import UsageError, cannot_read
from ..names import SURFACES
from ..parameters import Parameters, quantity, registry
from .design import SweepError, point_overrides

# Figures of merit a map can show (written by parksteer.sweep.merit for every point).
MAP_QUANTITIES = (
    "peak_torque_Nm",
    "plateau_torque_Nm",
    "lock_torque_Nm",
    "reversal_drop_Nm",
    "plateau_torque_braked_Nm",
    "peak_torque_braked_Nm",
)
TOP_LEVEL_KEYS = {"name", "description", "base_case", "effects", "surface", "axes", "full_axes", "points", "map",
                  "assistance", "braked"}
# How a point compares its wheels braked: not at all, the post-hoc rig-theory estimate, or (any other value) a
# second simulation with that effect added at the top of its brake_fraction range.
BRAKED_NONE, BRAKED_RIG_THEORY = "none", "rig_theory"
BRAKE_PARAMETER = "brake_fraction"
# Sections of the parameter file that the model reads (rig and spacers feed only the rig figures).
MODEL_SECTIONS = ("vehicle", "steering", "geometry", "tyre", "input")
# Grid values are rounded to this many significant digits so that linspace noise never changes a point id.
GRID_DIGITS = 12
ID_HEX_DIGITS = 10
# Points per batch job when the configuration names none (config/config.yaml, sweep_batch_size).
DEFAULT_BATCH_SIZE = 50
# The declaration the pipeline sweeps when the configuration names none (config/config.yaml, sweep).
DEFAULT_SWEEP_FILE = "config/sweeps/design.yaml"
# A batch is closed at the latest when it holds this many times the batch size.
BATCH_CAP_FACTOR = 3
# At most about this many batch jobs per sweep: beyond MAX_BATCHES x the batch size points the batch size doubles
# (see effective_batch_size). The scheduler's cost per job (about 1.5 ms of Snakemake's own work while the DAG is
# built, a submission on a cluster) then stays bounded, and a million points still make over 1,024 jobs for a
# cluster to run at once.
MAX_BATCHES = 4096


@dataclass(frozen=True)
class DesignVariable:
    """A design quantity that sets several model parameters together."""

    name: str
    unit: str
    minimum: float
    maximum: float
    description: str
    replaces: tuple[str, ...]  # the model parameters it sets (an axis may not name them as well)


DESIGN_VARIABLES: dict[str, DesignVariable] = {
    v.name: v
    for v in (
        DesignVariable(
            "front_axle_load", "N", 1000.0, 30000.0,
            "total static load on the front wheels; the chassis mass follows (W/g minus the unsprung mass), "
            "the chassis keeps its lateral mass-centre position and the left/right split follows from statics",
            ("case.chassis_mass", "case.load_left", "case.load_right"),
        ),
        DesignVariable(
            "extra_offset", "m", 0.0, 0.2,
            "wheel spacer thickness: each wheel centre moves outboard by it (the paper's spacers); the "
            "left/right loads are re-split by statics about the wider track",
            ("case.wheel_centre_y", "case.extra_offset", "case.load_left", "case.load_right"),
        ),
        DesignVariable(
            "steering_ratio", "1", 5.0, 60.0,
            "overall steering ratio G, handwheel angle per road-wheel angle: the handwheel-to-rack ratio "
            "becomes G times the road-wheel-to-rack ratio, and the handwheel lock angle scales with G so that "
            "the rack travel and the road-wheel lock stay those of the base car",
            ("steering.handwheel_to_rack_ratio", "input.handwheel_lock_angle"),
        ),
        DesignVariable(
            "castor_angle", "rad", -0.3, 0.3,
            "castor angle, with the mechanical trail (z2 - z1) tan(castor) that keeps the steer axis through "
            "the wheel centre in side view, as in the paper's model",
            ("geometry.castor_angle", "geometry.mechanical_trail"),
        ),
    )
}


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
class MapSpec:
    """Which two axes a torque map spans, one panel per value of `panels`, the other axes held."""

    x: str
    y: str
    panels: str | None
    hold: dict[str, float]
    quantity: str


@dataclass(frozen=True)
class AssistanceThreshold:
    """The handwheel torque above which a design is taken to need power assistance: rim force x rim radius."""

    rim_force_N: float
    rim_radius_m: float
    rim_force_source: str
    rim_radius_source: str

    @property
    def torque_Nm(self) -> float:
        return self.rim_force_N * self.rim_radius_m


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
        return _Grid(self.axes)[index]

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


# ---------------------------------------------------------------------------- parameter keys


def parameter_bounds(key: str) -> tuple[float, float, bool, str]:
    """(lower, upper, lower_inclusive, unit) of a sweepable key; raise KeyError for an unknown key.

    A model quantity's bounds are its registry's (:mod:`parksteer.parameters`); a design variable's are its own.
    """
    owner, _, name = key.partition(".")
    if not name:
        raise KeyError(key)
    if owner == "design":
        v = DESIGN_VARIABLES[name]
        return v.minimum, v.maximum, True, v.unit
    q = registry().get(key)
    if q is None or q.is_list:
        raise KeyError(key)
    return q.lower, q.upper, q.lower_inclusive, q.unit


def _check_key(where: str, key: Any) -> str:
    if not isinstance(key, str) or "." not in key:
        raise SweepError(f"{where}: {key!r} is not a parameter key (OWNER.NAME, e.g. tyre.tyre_pressure)")
    try:
        parameter_bounds(key)
    except KeyError:
        raise SweepError(
            f"{where}: unknown parameter {key!r} (a model parameter as for `parksteer simulate --set`, "
            f"or design.{{{', '.join(DESIGN_VARIABLES)}}})"
        ) from None
    return key


def _number(where: str, value: Any) -> float:
    if isinstance(value, str):  # YAML 1.1 reads 1.2e5 (no dot) as a string
        try:
            value = float(value)
        except ValueError:
            pass
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SweepError(f"{where}: {value!r} is not a number")
    value = float(value)
    if not math.isfinite(value):
        raise SweepError(f"{where}: {value} is not finite")
    return value


def _check_value(where: str, key: str, value: float) -> float:
    lower, upper, inclusive, unit = parameter_bounds(key)
    below = value < lower if inclusive else value <= lower
    if below or value > upper:
        bracket = "[" if inclusive else "("
        shown = f"{value:g}" if unit == "1" else f"{value:g} {unit}"
        raise SweepError(f"{where}: {shown} is out of bounds {bracket}{lower:g}, {upper:g}]")
    return value


def _round(value: float) -> float:
    return float(f"{value:.{GRID_DIGITS}g}")


def _axis_values(where: str, key: str, raw: Any) -> tuple[float, ...]:
    """A list of numbers, or a grid {start, stop, num} (num evenly spaced values, both ends included)."""
    if isinstance(raw, dict):
        unknown = sorted(set(raw) - {"start", "stop", "num"})
        if unknown:
            raise SweepError(f"{where}.{unknown[0]}: unknown grid field (use start, stop, num)")
        missing = [k for k in ("start", "stop", "num") if k not in raw]
        if missing:
            raise SweepError(f"{where}: grid needs {missing[0]}")
        start, stop = _number(f"{where}.start", raw["start"]), _number(f"{where}.stop", raw["stop"])
        num = raw["num"]
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            raise SweepError(f"{where}.num: {num!r} is not a positive integer")
        if num == 1 and start != stop:
            raise SweepError(f"{where}.num: 1 value cannot span {start:g} to {stop:g}")
        values = [_round(v) for v in np.linspace(start, stop, num)]
    elif isinstance(raw, list):
        if not raw:
            raise SweepError(f"{where}: empty axis")
        values = [_round(_number(f"{where}[{i}]", v)) for i, v in enumerate(raw)]
    elif raw is None:
        raise SweepError(f"{where}: empty axis")
    else:
        values = [_round(_number(where, raw))]
    if len(set(values)) != len(values):
        raise SweepError(f"{where}: repeated value")
    for i, v in enumerate(values):
        _check_value(f"{where}[{i}]", key, v)
    return tuple(values)


def _check_conflicts(where: str, keys: list[str]) -> None:
    for key in keys:
        owner, _, name = key.partition(".")
        if owner != "design":
            continue
        for other in DESIGN_VARIABLES[name].replaces:
            if other in keys:
                raise SweepError(f"{where}: {key} sets {other}; sweep one of them, not both")


# ---------------------------------------------------------------------------- ids and expansion


def point_id(case: str, effects: str | None, surface: str, values: dict[str, float]) -> str:
    """A hash of what the point simulates: the same on every run and machine, whatever the point's position."""
    canonical = json.dumps(
        {"case": case, "effects": effects, "surface": surface,
         "values": {k: format(v, f".{GRID_DIGITS}g") for k, v in values.items()}},
        sort_keys=True,
    )
    return hashlib.sha256(canonical.encode()).hexdigest()[:ID_HEX_DIGITS]


def point_ids(case: str, effects: str | None, surface: str, values_list) -> list[str]:
    """point_id of every values dict of `values_list`, the same strings, in linear time with a small constant
    (:func:`point_id_maker`)."""
    make = point_id_maker(case, effects, surface)
    return [make(values) for values in values_list]


def point_id_maker(case: str, effects: str | None, surface: str):
    """A function giving point_id(case, effects, surface, values) of a values dict, the same string: the canonical
    text is assembled from pieces kept per key and value instead of being encoded again per point."""
    head = json.dumps({"case": case, "effects": effects, "surface": surface}, sort_keys=True)[:-1] + ', "values": {'
    fragments: dict[str, dict[float, str]] = {}
    orders: dict[tuple[str, ...], list[tuple[str, dict[float, str]]]] = {}
    sha256 = hashlib.sha256

    def make(values: dict[str, float]) -> str:
        keys = tuple(values)
        order = orders.get(keys)
        if order is None:  # json.dumps(sort_keys=True) sorts the same way
            order = orders[keys] = [(key, fragments.setdefault(key, {})) for key in sorted(keys)]
        parts = []
        for key, known in order:
            value = values[key]
            text = known.get(value) if value != 0.0 else None  # 0.0 and -0.0 are one dict key but print apart
            if text is None:
                text = f'{json.dumps(key)}: {json.dumps(format(value, f".{GRID_DIGITS}g"))}'
                if value != 0.0:
                    known[value] = text
            parts.append(text)
        return sha256(f'{head}{", ".join(parts)}}}}}'.encode()).hexdigest()[:ID_HEX_DIGITS]

    return make


def effective_batch_size(n_points: int, batch_size: int) -> int:
    """The batch size a sweep of `n_points` points is cut at: `batch_size` x 2^k, the smallest k >= 0 with
    n_points <= MAX_BATCHES x batch_size x 2^k.

    Every sweep of at most MAX_BATCHES x `batch_size` points (204,800 at the default 50) is cut at `batch_size`
    itself, into the batches and batch ids it always had; a larger one into about MAX_BATCHES / 2 to MAX_BATCHES
    batches. The size doubles, so that a batch boundary at the larger size (an id that is a multiple of it) is one
    at the smaller size too: a sweep that grows past a threshold merges neighbouring batches rather than cutting
    new ones anywhere.
    """
    size = batch_size
    while n_points > MAX_BATCHES * size:
        size *= 2
    return size


def batch_points(ids, batch_size: int) -> dict[str, tuple[str, ...]]:
    """Group point ids into batches of about `batch_size` (grown with the sweep beyond MAX_BATCHES x `batch_size`
    points: :func:`effective_batch_size`), batch id -> its point ids (sorted).

    The ids are taken in sorted order and a batch ends after every id whose value is a multiple of
    `batch_size` (content-defined boundaries, as in rsync), or once it holds BATCH_CAP_FACTOR x `batch_size`
    points. A boundary depends only on the id before it, so a new point changes only the batch it falls in (which
    it joins, or splits in two when its own id is a boundary) and leaves every other batch, its id (a hash of its
    members) and its result as they were; a removed point changes only its batch (merged with the next when the
    point ended it). The cap can shift boundaries further only in a run of over BATCH_CAP_FACTOR x `batch_size`
    points without a natural boundary. Batch size 1 gives one batch per point.
    """
    if isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1:
        raise SweepError(f"sweep_batch_size: {batch_size!r} is not a positive integer")
    ids = sorted(ids)
    batch_size = effective_batch_size(len(ids), batch_size)
    batches: dict[str, tuple[str, ...]] = {}
    current: list[str] = []

    def close():
        members = tuple(current)
        batches[batch_id(members)] = members
        current.clear()

    for point in ids:
        current.append(point)
        if int(point, 16) % batch_size == 0 or len(current) >= BATCH_CAP_FACTOR * batch_size:
            close()
    if current:
        close()
    return batches


def batch_id(members) -> str:
    """A batch's id: a hash of its point ids (sorted)."""
    return hashlib.sha256(" ".join(members).encode()).hexdigest()[:ID_HEX_DIGITS]


# ---------------------------------------------------------------------------- the batch index
# A batch job needs the values of its own points only. Expanding and checking the whole declaration in every job
# would cost each of them the whole sweep (seconds at a million points), and handing each job its points' values
# through the workflow would hold every point in the scheduler. So the sweep is expanded once, where the workflow
# plans it, into a batch index: one line per batch, "<batch id> <point index> <point index> ...", the indices
# being positions in the declaration's expansion. A job reads its line and decodes its points from the declaration
# (an axis sweep's point i is the mixed-radix digits of i). The file is named after a hash of what it is computed
# from (the declaration's text, full, the batch size, this module's code), so a stale one is never read; a job
# that finds none expands the sweep itself and writes it.


def batch_index_path(index_dir: str | Path, path: str | Path, full: bool, batch_size: int) -> Path:
    """Where the batch index of declaration `path` at `batch_size` is kept under `index_dir`."""
    digest = hashlib.sha256()
    for part in (Path(path).read_bytes(), repr((bool(full), int(batch_size))).encode(), Path(__file__).read_bytes()):
        digest.update(hashlib.sha256(part).digest())
    return Path(index_dir) / f"{Path(path).stem}-{digest.hexdigest()[:16]}.txt"


def write_batch_index(sweep: Sweep, batch_size: int, index_dir: str | Path) -> Path:
    """Write the batch index of `sweep` (unless already there) and return its path."""
    from ..tables import atomic_path

    target = batch_index_path(index_dir, sweep.path, sweep.full, batch_size)
    if target.is_file():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(target) as scratch, open(scratch, "w", encoding="utf-8") as out:
        by_id = sweep._by_id
        for batch, members in sorted(sweep.batches(batch_size).items()):
            out.write(f"{batch} {' '.join([str(by_id[m].index) for m in members])}\n")
    return target


def _declared_values(path: Path, full: bool):
    """The declaration's values, point i at [i], without expanding or checking every point (load_sweep does)."""
    doc = _read(path)
    if "points" in doc and "axes" not in doc:
        return _points(path, doc["points"])
    field_name = "full_axes" if full else "axes"
    if field_name not in doc:
        raise SweepError(f"{path}: {field_name}: not declared")
    axes = _axes(path, field_name, doc[field_name])
    return _Grid(axes)


class _Grid:
    """The points of a full factorial without its expansion: point i's values are the mixed-radix digits of i."""

    def __init__(self, axes: dict[str, tuple[float, ...]]):
        self.axes = axes
        self.keys, self.sizes = list(axes), [len(v) for v in axes.values()]

    def __getitem__(self, index: int) -> dict[str, float]:
        digits = []
        for size in reversed(self.sizes):  # the first axis slowest, as itertools.product
            index, digit = divmod(index, size)
            digits.append(digit)
        return {k: self.axes[k][d] for k, d in zip(self.keys, reversed(digits))}


def batch_spec_from_index(path: str | Path, parameters_path: str | Path, full: bool, batch_size: int, batch: str,
                          shared: dict[str, Any], index_dir: str | Path) -> dict[str, Any]:
    """The spec of batch `batch` (as Sweep.batch_spec gives it) from the sweep's batch index, written first if
    missing; `shared` is the sweep's Sweep.shared_spec. Its points' ids are computed again and must hash to
    `batch`."""
    path = Path(path)
    index = batch_index_path(index_dir, path, full, batch_size)
    if not index.is_file():
        from ..parameters import load_parameters

        index = write_batch_index(load_sweep(path, load_parameters(parameters_path), full=full), batch_size,
                                  index_dir)
    text = index.read_text(encoding="utf-8")
    start = 0 if text.startswith(f"{batch} ") else text.find(f"\n{batch} ") + 1
    if start == 0 and not text.startswith(f"{batch} "):
        raise SweepError(f"{path}: no batch {batch!r} in sweep {shared['sweep']} at batch size {batch_size}")
    line = text[start:text.find("\n", start)]
    declared = _declared_values(path, full)
    values = [declared[int(i)] for i in line.split()[1:]]
    ids = point_ids(shared["case"], shared["effects"], shared["surface"], values)
    if batch_id(ids) != batch:
        raise SweepError(f"{path}: batch {batch} of {index} does not match the declaration; delete that file")
    return {"sweep": shared["sweep"], "batch": batch,
            "points": [compose_point_spec(shared, i, v) for i, v in zip(ids, values)]}


def _expand(axes: dict[str, tuple[float, ...]]) -> list[dict[str, float]]:
    keys = list(axes)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(axes[k] for k in keys))]


# ---------------------------------------------------------------------------- loading


def _read(path: Path) -> dict:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SweepError(cannot_read(path, exc)) from None
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0] if str(exc) else "syntax error"
        raise SweepError(f"{path}: not valid YAML ({first})") from None
    if not isinstance(doc, dict):
        raise SweepError(f"{path}: expected a mapping of sweep fields")
    return doc


def _axes(path: Path, field_name: str, raw: Any) -> dict[str, tuple[float, ...]]:
    where = f"{path}: {field_name}"
    if not isinstance(raw, dict) or not raw:
        raise SweepError(f"{where}: expected a mapping of parameter keys to values")
    axes = {}
    for key, values in raw.items():
        _check_key(where, key)
        axes[key] = _axis_values(f"{where}.{key}", key, values)
    _check_conflicts(where, list(axes))
    return axes


def _points(path: Path, raw: Any) -> list[dict[str, float]]:
    where = f"{path}: points"
    if not isinstance(raw, list) or not raw:
        raise SweepError(f"{where}: expected a non-empty list of points")
    out = []
    for i, entry in enumerate(raw):
        if not isinstance(entry, dict) or not entry:
            raise SweepError(f"{where}[{i}]: expected a mapping of parameter keys to values")
        values = {}
        for key, value in entry.items():
            _check_key(f"{where}[{i}]", key)
            values[key] = _check_value(f"{where}[{i}].{key}", key, _round(_number(f"{where}[{i}].{key}", value)))
        _check_conflicts(f"{where}[{i}]", list(values))
        out.append(values)
    seen = set()
    for i, values in enumerate(out):
        frozen = tuple(sorted(values.items()))
        if frozen in seen:
            raise SweepError(f"{where}[{i}]: repeated point")
        seen.add(frozen)
    return out


def _threshold(path: Path, raw: Any) -> AssistanceThreshold:
    where = f"{path}: assistance"
    if not isinstance(raw, dict):
        raise SweepError(f"{where}: expected rim_force and rim_radius")
    unknown = sorted(set(raw) - {"rim_force", "rim_radius"})
    if unknown:
        raise SweepError(f"{where}.{unknown[0]}: unknown field (use rim_force, rim_radius)")
    out = {}
    for name, unit in (("rim_force", "N"), ("rim_radius", "m")):
        entry = raw.get(name)
        if not isinstance(entry, dict) or set(entry) != {"value", "unit", "source"}:
            raise SweepError(f"{where}.{name}: expected {{value, unit, source}}")
        if entry["unit"] != unit:
            raise SweepError(f"{where}.{name}: unit {entry['unit']!r} where {unit!r} is required")
        if not isinstance(entry["source"], str) or not entry["source"].strip():
            raise SweepError(f"{where}.{name}: source must be a non-empty string")
        value = _number(f"{where}.{name}.value", entry["value"])
        if value <= 0:
            raise SweepError(f"{where}.{name}.value: {value:g} {unit} must be positive")
        out[name] = (value, entry["source"].strip())
    return AssistanceThreshold(out["rim_force"][0], out["rim_radius"][0], out["rim_force"][1], out["rim_radius"][1])


def _map(path: Path, raw: Any, keys: list[str], axes: dict[str, tuple[float, ...]], points) -> MapSpec:
    where = f"{path}: map"
    if not isinstance(raw, dict):
        raise SweepError(f"{where}: expected a mapping with x, y and quantity")
    unknown = sorted(set(raw) - {"x", "y", "panels", "hold", "quantity"})
    if unknown:
        raise SweepError(f"{where}.{unknown[0]}: unknown field (use x, y, panels, hold, quantity)")
    for name in ("x", "y", "quantity"):
        if name not in raw:
            raise SweepError(f"{where}: needs {name}")
    for name in ("x", "y", "panels"):
        key = raw.get(name)
        if key is not None and key not in keys:
            raise SweepError(f"{where}.{name}: {key!r} is not a key of this sweep")
    used = [raw["x"], raw["y"]] + ([raw["panels"]] if raw.get("panels") else [])
    if len(set(used)) != len(used):
        raise SweepError(f"{where}: x, y and panels must be different keys")
    if raw["quantity"] not in MAP_QUANTITIES:
        raise SweepError(f"{where}.quantity: {raw['quantity']!r} is not one of {', '.join(MAP_QUANTITIES)}")
    hold_raw = raw.get("hold") or {}
    if not isinstance(hold_raw, dict):
        raise SweepError(f"{where}.hold: expected a mapping of keys to values")
    hold = {}
    for key, value in hold_raw.items():
        if key not in keys or key in used:
            raise SweepError(f"{where}.hold.{key}: not a key of this sweep outside x, y and panels")
        value = _round(_number(f"{where}.hold.{key}", value))
        available = axes[key] if axes else sorted({p[key] for p in points if key in p})
        if value not in available:
            raise SweepError(f"{where}.hold.{key}: {value:g} is not a value of this sweep")
        hold[key] = value
    return MapSpec(raw["x"], raw["y"], raw.get("panels"), hold, raw["quantity"])


def _check_effects(path: Path, effects: str | None) -> None:
    """The effects spec names effects that exist (resolved as `parksteer simulate --effects` would); null, the
    paper's five, needs no check and so does not import the symbolic model (sympy)."""
    if effects is None:
        return
    from ..model.symbolic.components import resolve_effects

    try:
        resolve_effects(effects)
    except UsageError as exc:
        raise SweepError(f"{path}: effects: {exc}") from None


def _check_model_consistency(path: Path, params: Parameters, case: str, effects: str | None,
                             values_list: list[dict[str, float]], numbers: list[int] | None = None,
                             what: str = "point") -> None:
    """Effect parameters belong to an effect of the sweep's model; derived case values are physical. A problem
    names the point by its position in `values_list`, or by `numbers` at that position (:func:`_grid_check`)."""
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
            q = quantity(key)
            if not q.within(value):
                raise SweepError(f"{path}: {what} {i if numbers is None else numbers[i]}: derived {key} = "
                                 f"{value:g} {q.unit} is out of bounds "
                                 f"{q.bounds_text()}")
        checked.add(signature)


def _grid_check(params: Parameters, case: str, axes: dict[str, tuple[float, ...]]
                ) -> tuple[list[dict[str, float]], list[int]]:
    """The points of the grid `axes` that _check_model_consistency tells apart, and their indices: one per
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
    grid = _Grid(axes)
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


def _braked(path: Path, raw: Any, effects: str | None, surface: str) -> tuple[str, tuple[str, ...] | None]:
    """The braked-wheel comparison: none, rig_theory, or an effect with a brake_fraction parameter."""
    where = f"{path}: braked"
    if not isinstance(raw, str) or not raw:
        raise SweepError(f"{where}: expected {BRAKED_NONE}, {BRAKED_RIG_THEORY} or an effect name")
    if raw == BRAKED_NONE:
        return raw, None
    if surface != "ground":
        raise SweepError(f"{where}: braked wheels are compared on the ground only (surface is {surface})")
    from ..model.symbolic.components import discover_effects, resolve_effects

    chosen = [e.name for e in resolve_effects(effects)]
    if "tyre_friction" not in chosen:
        raise SweepError(f"{where}: needs tyre_friction in the model, or there is no patch to drag")
    if raw == BRAKED_RIG_THEORY:
        return raw, None
    found = discover_effects()
    if raw not in found:
        raise SweepError(f"{where}: {raw!r} is neither {BRAKED_NONE}, {BRAKED_RIG_THEORY} nor an effect "
                         f"(known: {', '.join(sorted(found))})")
    if raw in chosen:
        raise SweepError(f"{where}: effect {raw} is already in the free-rolling model")
    if f"{raw}.{BRAKE_PARAMETER}" not in found[raw].uses:
        raise SweepError(f"{where}: effect {raw} has no {BRAKE_PARAMETER} parameter")
    return raw, tuple(sorted(chosen + [raw]))


def load_sweep(path: str | Path, params: Parameters, full: bool = False, expand: bool = True) -> Sweep:
    """Read, validate and expand a sweep declaration against the parameter file `params`.

    full: use `full_axes` (the large version of the study) instead of `axes`.
    expand: False leaves a grid's points unexpanded (Sweep.expanded; the gathering of a million points needs
    their number, each one's index from its values and the id there, not the 0.45 kB a point the expansion
    holds). Every point is checked as with the expansion, each combination of the values the check reads once
    (:func:`_grid_check`). A declared list of points is expanded either way (the file holds it).

    Python's cyclic garbage collector is paused meanwhile: the expansion allocates a few objects per point, none
    of them in a cycle, and each collection it triggers walks every object made so far (a million points: about
    2 s of 7).
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _load_sweep(Path(path), params, full, expand)
    finally:
        if enabled:
            gc.enable()


def _load_sweep(path: Path, params: Parameters, full: bool, expand: bool = True) -> Sweep:
    """load_sweep with the garbage collector paused."""
    doc = _read(path)
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
    _check_effects(path, effects)
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
        values_list = _points(path, doc["points"])
    else:
        field_name = "full_axes" if full else "axes"
        if full and "full_axes" not in doc:
            raise SweepError(f"{path}: full_axes: the full sweep was asked for but is not declared")
        axes = _axes(path, field_name, doc[field_name])
        values_list = _expand(axes) if expand else None
    if "full_axes" in doc and not full:  # validate the other half of the file as well, every point of it
        other = _axes(path, "full_axes", doc["full_axes"])
        if expand:
            _check_model_consistency(path, params, base_case, effects, _expand(other),
                                     what="full_axes point")
        else:
            _check_model_consistency(path, params, base_case, effects, *_grid_check(params, base_case, other),
                                     what="full_axes point")

    if values_list is None:
        _check_model_consistency(path, params, base_case, effects, *_grid_check(params, base_case, axes))
        points: tuple[SweepPoint, ...] = ()
    else:
        _check_model_consistency(path, params, base_case, effects, values_list)
        ids = point_ids(base_case, effects, surface, values_list)
        points = tuple(SweepPoint(i, pid, v) for i, (pid, v) in enumerate(zip(ids, values_list)))
    keys = list(axes) if axes else list(dict.fromkeys(k for v in values_list for k in v))
    spec_map = _map(path, doc["map"], keys, axes, values_list) if doc.get("map") is not None else None
    threshold = _threshold(path, doc["assistance"]) if doc.get("assistance") is not None else None
    braked, braked_effects = _braked(path, doc.get("braked", BRAKED_NONE), effects, surface)
    return Sweep(path, name, description.strip(), base_case, effects, surface, axes, points, spec_map, threshold,
                 full, braked, braked_effects, expanded=values_list is not None)
