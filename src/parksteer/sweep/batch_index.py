"""The batch index: which points each batch job of a sweep runs, written once where the workflow plans the sweep.

A batch job needs the values of its own points only. Expanding and checking the whole declaration in every job
would cost each of them the whole sweep (seconds at a million points), and handing each job its points' values
through the workflow would hold every point in the scheduler. So the sweep is expanded once, where the workflow
plans it, into a batch index: one line per batch, "<batch id> <point index> <point index> ...", the indices
being positions in the declaration's expansion. A job reads its line and decodes its points from the declaration
(an axis sweep's point i is the mixed-radix digits of i). The file is named after a hash of what it is computed
from (the declaration's text, full, the batch size, the code of the modules that read and expand it), so a stale
one is never read; a job that finds none expands the sweep itself and writes it.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from . import declaration, expansion, fields, keys
from .declaration import Sweep, compose_point_spec, load_sweep
from .design import SweepError
from .expansion import Grid, batch_id, point_ids
from .fields import read_axes, read_declaration, read_points

# The modules whose code decides a batch index's lines: this one, and those that read and expand the declaration.
INDEX_CODE = (__file__, declaration.__file__, expansion.__file__, fields.__file__, keys.__file__)


def batch_index_path(index_dir: str | Path, path: str | Path, full: bool, batch_size: int) -> Path:
    """Where the batch index of declaration `path` at `batch_size` is kept under `index_dir`."""
    digest = hashlib.sha256()
    code = [Path(module).read_bytes() for module in INDEX_CODE]
    for part in (Path(path).read_bytes(), repr((bool(full), int(batch_size))).encode(), *code):
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
    doc = read_declaration(path)
    if "points" in doc and "axes" not in doc:
        return read_points(path, doc["points"])
    field_name = "full_axes" if full else "axes"
    if field_name not in doc:
        raise SweepError(f"{path}: {field_name}: not declared")
    axes = read_axes(path, field_name, doc[field_name])
    return Grid(axes)


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
