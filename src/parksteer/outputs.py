"""Repair what earlier pipeline runs left behind: ``parksteer repair``, run before Snakemake.

Snakemake compares timestamps only, so a truncated output newer than its inputs would be trusted on every run.
:func:`repair` removes, in the working directory:
- every empty, truncated or unparsable CSV, SVG, JSON, notebook or PDF a rule wrote (results/, figures/*.svg,
  figures/*.csv, paper/*.pdf; figures/reference/ is source and never touched), read with the integrity checks of
  parksteer.checksums;
- a model manifest results/model/<set>.json whose cache key is not the one its effects have now (their sources,
  the sympy in use), or whose cache entry is missing or fails its SHA-256 check: a manifest is trusted only if
  what it points at is sound and current;
- temporary files of writers that were killed (:func:`parksteer.tables.remove_stale_temporaries`) and scratch
  directories of killed model builds (:func:`parksteer.model.codegen.scratch.clean_stale_scratch`);
- Snakemake's lock (.snakemake/locks) when no Snakemake process runs in the folder any more. A run started from
  another host on a shared file system cannot be seen from here: do not run one folder from two hosts at once.
The next Snakemake run treats what was removed as any missing file: a missing target is built, a missing
intermediate as soon as a job that reads it runs. Nothing here runs while Snakemake reads the workflow; reading
the 420 files (21 MB) of a full build takes about 0.5 s.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

from .checksums import integrity_problem
from .model.codegen.cache import cache_root, entry_is_sound
from .model.codegen.scratch import clean_stale_scratch
from .tables import ROWS_KEY, remove_stale_temporaries

CHECKED_SUFFIXES = (".csv", ".svg", ".json", ".ipynb", ".pdf")
PROC = Path("/proc")


def content_problem(path: Path) -> str | None:
    """Why the output `path` cannot be what a rule wrote (empty, truncated, unparsable), or None."""
    path = Path(path)
    if path.suffix == ".svg":
        return integrity_problem(path)
    if path.stat().st_size == 0:
        return "empty"
    if path.suffix == ".csv":  # the shape only: parsing every number would double the repair's time
        data = path.read_bytes()
        if not data.endswith(b"\n"):
            return "does not end with a newline (truncated)"
        lines = data.split(b"\n")
        rows = [line for line in lines if line.strip() and not line.startswith(b"#")]
        if not rows:
            return "no header row"
        stated = [line.split(b":", 1)[1].strip() for line in lines if line.startswith(b"# " + ROWS_KEY.encode() + b":")]
        if stated and stated[-1] != str(len(rows) - 1).encode():
            return f"{len(rows) - 1} data rows where its header says {stated[-1].decode(errors='replace')} (truncated)"
        cells = rows[0].count(b",")
        for number, row in enumerate(rows[1:], start=1):
            if row.count(b",") != cells:
                return f"data row {number} has {row.count(b',') + 1} cells, the header {cells + 1}"
        return None
    if path.suffix == ".pdf":
        with path.open("rb") as f:
            head = f.read(5)
            f.seek(max(0, path.stat().st_size - 1024))
            tail = f.read()
        return None if head == b"%PDF-" and b"%%EOF" in tail else "not a complete PDF (truncated)"
    try:
        json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        return f"not readable JSON ({exc})"
    return None


def manifest_problem(path: Path, expected: str | None = None) -> str | None:
    """Why the model manifest `path` cannot be trusted, or None: not a manifest, its cache entry missing or failing
    its SHA-256 check, or (when `expected` is given) naming another cache key than `expected`, the key its effect
    set has now (parksteer.model.codegen.cache.model_key)."""
    try:
        key = json.loads(Path(path).read_text(encoding="utf-8"))["key"]
    except (ValueError, UnicodeDecodeError, KeyError, TypeError) as exc:
        return f"not a model manifest ({type(exc).__name__}: {exc})"
    if expected is not None and key != expected:
        return f"names cache entry {key}, but the model's sources now key it {expected}"
    if not entry_is_sound(cache_root() / key):
        return f"names cache entry {key}, which is missing or fails its SHA-256 check ({cache_root() / key})"
    return None


def current_model_key(manifest: Path) -> str | None:
    """The cache key the effects the model manifest `manifest` names have now (their sources and the sympy in
    use: parksteer.model.codegen.cache.model_key), or None when they cannot be resolved by name (an effect from a
    file outside the package, or no readable list of effects)."""
    from .model.codegen.cache import model_key
    from .model.symbolic.components import resolve_effects

    try:
        names = json.loads(Path(manifest).read_text(encoding="utf-8"))["effects"]
        return model_key(resolve_effects([str(name) for name in names]))
    except (OSError, ValueError, KeyError, TypeError):  # a UsageError is a ValueError
        return None


def _parent_pid(pid: int) -> int | None:
    try:
        return int((PROC / str(pid) / "stat").read_text().rpartition(")")[2].split()[1])
    except (OSError, ValueError, IndexError):
        return None


def other_snakemake_running(folder: str | Path = ".") -> bool:
    """True if a Snakemake process other than this one and its ancestors runs in `folder`, or if that cannot be
    told (no /proc, or a Snakemake process whose folder cannot be read)."""
    if not (PROC / "self" / "cwd").exists():
        return True
    mine: set[int] = set()
    pid: int | None = os.getpid()
    while pid is not None and pid > 1 and pid not in mine:
        mine.add(pid)
        pid = _parent_pid(pid)
    here = os.path.realpath(folder)
    for entry in PROC.iterdir():
        if not entry.name.isdigit() or int(entry.name) in mine:
            continue
        try:
            argv = (entry / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if "snakemake" not in (os.path.basename(a.decode(errors="replace")) for a in argv[:3]):
            continue
        try:
            if os.path.realpath(entry / "cwd") != here:
                continue
        except OSError:
            return True
        return True
    return False


def written_files(root: Path) -> Iterator[Path]:
    """The files rules write under `root` that repair reads: results/ (but the model cache's entries, checked
    through their manifests, Snakemake's benchmark records and the directory outputs results/vehicles/*/synthetic),
    figures/*.svg and *.csv, paper/*.pdf."""
    results = root / "results"
    for folder, subfolders, names in os.walk(results):
        here = Path(folder)
        if here == results:
            subfolders[:] = [d for d in subfolders if d != "benchmarks"]
        if here == results / "model":
            subfolders.clear()
        if here.parent == results / "vehicles":  # its synthetic/ is a directory output: a removed file in it would
            subfolders[:] = [d for d in subfolders if d != "synthetic"]  # not make Snakemake rebuild it
        subfolders.sort()
        for name in sorted(names):
            path = here / name
            if path.suffix in CHECKED_SUFFIXES and not name.startswith("."):
                yield path
    yield from sorted(p for p in (root / "figures").glob("*") if p.suffix in (".svg", ".csv") and p.is_file())
    yield from sorted(p for p in (root / "paper").glob("*.pdf") if p.is_file())


def repair(root: str | Path = ".") -> tuple[list[str], int]:
    """Remove what earlier runs left damaged or half-done under `root` (see the module's description). Return one
    line for each removal, naming the file and why, and the number of outputs read."""
    root = Path(root)
    lines = []
    locks = root / ".snakemake" / "locks"
    if locks.is_dir() and any(locks.iterdir()) and not other_snakemake_running(root):
        shutil.rmtree(locks, ignore_errors=True)
        lines.append("removed the lock of a Snakemake run that is no longer running")
    for path in remove_stale_temporaries(*(root / name for name in ("results", "figures", "paper"))):
        lines.append(f"removed {path.relative_to(root)}: a temporary file of a killed writer")
    for path in clean_stale_scratch(cache_root()):
        lines.append(f"removed {path}: a scratch directory of a killed model build")
    manifests = root / "results" / "model"
    checked = 0
    for path in written_files(root):
        checked += 1
        why = content_problem(path)
        if why is None and path.parent == manifests and path.suffix == ".json":
            why = manifest_problem(path, current_model_key(path))
        if why is not None:
            path.unlink(missing_ok=True)
            lines.append(f"removed {path.relative_to(root)}: {why}; the next run rebuilds it")
    return lines, checked
