"""A sweep's points: their ids, the expansion of a grid, and their batches (the jobs the workflow runs)."""

from __future__ import annotations

import hashlib
import itertools
import json

from .design import SweepError
from .keys import GRID_DIGITS


ID_HEX_DIGITS = 10


# Points per batch job when the configuration names none (config/config.yaml, sweep_batch_size).
DEFAULT_BATCH_SIZE = 50


# A batch is closed at the latest when it holds this many times the batch size.
BATCH_CAP_FACTOR = 3


# At most about this many batch jobs per sweep: beyond MAX_BATCHES x the batch size points the batch size doubles
# (see effective_batch_size). The scheduler's cost per job (about 1.5 ms of Snakemake's own work while the DAG is
# built, a submission on a cluster) then stays bounded, and a million points still make over 1,024 jobs for a
# cluster to run at once.
MAX_BATCHES = 4096


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


class Grid:
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


def expand_grid(axes: dict[str, tuple[float, ...]]) -> list[dict[str, float]]:
    keys = list(axes)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(axes[k] for k in keys))]
