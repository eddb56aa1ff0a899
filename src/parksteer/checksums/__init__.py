"""Stored checksums of every figure and its data, and a verification that tells a platform wobble from a change.

``figures/SHA256SUMS`` is in the format ``sha256sum -c`` reads, paths relative to the repository root.
``figures/reference/`` keeps each figure's data (CSV) and drawing (SVG, gzipped) as of the last refresh, and
``figures/PLATFORM.json`` the platform the sums were made on. Verification says for each file one of:

* identical: the sha256 matches;
* within tolerance: the bytes differ, but every number agrees with the reference within its figure family's
  tolerance (parksteer.checksums.tolerances) and everything else is identical; the line names the largest
  difference and the platform facts that differ from the recorded ones;
* changed: anything else (a larger difference, another column, row, text cell or SVG element), including a file
  that is missing, broken (truncated, unparsable) or without a stored sum.

Verification fails on "changed", and with ``strict`` on "within tolerance" too.
"""

from __future__ import annotations

import gzip
import hashlib
import io
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..tables import atomic_path, read_csv

if TYPE_CHECKING:
    from .compare import Comparison

SUMS_NAME = "SHA256SUMS"
REFERENCE_DIR = "reference"
IDENTICAL, WITHIN, CHANGED = "identical", "within tolerance", "changed"


def sha256_of(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def read_sums(sums_path: Path) -> dict[str, str]:
    """Map of relative path -> hex digest from a sha256sum-format file."""
    sums: dict[str, str] = {}
    for n, line in enumerate(Path(sums_path).read_text(encoding="utf-8").splitlines(), start=1):
        if not line.strip():
            continue
        digest, sep, rel = line.partition("  ")
        if not sep or len(digest) != 64:
            raise ValueError(f"{sums_path}:{n}: not a sha256sum line: {line!r}")
        sums[rel.strip()] = digest
    return sums


def integrity_problem(path: Path) -> str | None:
    """Why a built figure or data file cannot be what a rule wrote (truncated, unparsable), or None if it parses.

    A checksum mismatch of a file that parses is a change to explain; one of a file that does not is damage, which
    an ordinary rebuild repairs once the file is removed.
    """
    path = Path(path)
    if path.stat().st_size == 0:
        return "empty"
    if path.suffix == ".svg":
        import xml.etree.ElementTree as ElementTree

        try:
            root = ElementTree.parse(path).getroot()
        except ElementTree.ParseError as exc:
            return f"not well-formed SVG ({exc})"
        if not root.tag.endswith("svg"):
            return f"root element is {root.tag!r}, not svg"
        return None
    if path.suffix == ".csv":
        text = path.read_text(encoding="utf-8", errors="replace")
        if not text.endswith("\n"):
            return "does not end with a newline (truncated)"
        try:
            columns, _ = read_csv(path)
        except (ValueError, IndexError, KeyError, UnicodeDecodeError) as exc:
            return f"not a readable table ({type(exc).__name__}: {exc})"
        lengths = {len(v) for v in columns.values()}
        if len(lengths) > 1:
            return "columns of different lengths"
    return None


def _data_file_for(rel: str, files: list[str]) -> str | None:
    """The CSV that holds a figure's data: itself, or the CSV with the same stem."""
    if rel.endswith(".csv"):
        return rel
    stem = rel.rsplit(".", 1)[0]
    return f"{stem}.csv" if f"{stem}.csv" in files else None


def reference_path(reference: Path, rel: str) -> Path:
    """Where the reference copy of a figure file is kept: CSVs as they are, SVGs gzipped."""
    name = Path(rel).name
    return reference / (name + ".gz" if name.endswith(".svg") else name)


def _write_gzip(source: Path, target: Path) -> None:
    """Deterministic gzip (no name, no time) so a refresh of unchanged figures leaves the copy's bytes alone."""
    buffer = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buffer, mtime=0, compresslevel=9) as out:
        out.write(Path(source).read_bytes())
    with atomic_path(target) as tmp:
        tmp.write_bytes(buffer.getvalue())


@dataclass(frozen=True)
class FileCheck:
    """What verification found for one file: its outcome (IDENTICAL, WITHIN or CHANGED) and the explanation."""

    path: str
    outcome: str
    detail: str = ""

    @property
    def line(self) -> str:
        if self.outcome == CHANGED and self.detail.startswith(("broken:", "missing", "no stored checksum",
                                                                "has a stored checksum")):
            return f"{self.path}: {self.detail}"  # a flavour of "changed" with its own first word
        return f"{self.path}: {self.outcome}" + (f": {self.detail}" if self.detail else "")


def _compare_with_reference(root: Path, rel: str, data: str | None, reference: Path) -> Comparison | str:
    """The Comparison of a mismatching file (and its data) with the reference copies, or a string saying why there
    is nothing to compare."""
    from .compare import Comparison, compare_drawings, compare_tables
    from .tolerances import family_of

    stem = Path(rel).stem
    family = family_of(stem)
    if family is None:
        return f"no tolerance declared for figure {stem} (parksteer.checksums.tolerances); bytes differ"
    if data is None:
        return "no data file to compare"
    data_reference = reference_path(reference, data)
    if not data_reference.exists():
        return f"no reference copy {data_reference.name} (refresh the sums)"
    if data != rel and integrity_problem(root / data) is not None:
        return f"its data {data} is broken: {integrity_problem(root / data)}"
    table = compare_tables(root / data, data_reference, family)
    if rel == data or not table.within:
        return table if rel == data else Comparison(f"data {data}: {table.describe()}")
    drawing_reference = reference_path(reference, rel)
    if not drawing_reference.exists():
        return f"data {data} {table.describe()}, but no reference copy {drawing_reference.name} of the drawing"
    return compare_drawings(root / rel, gzip.decompress(drawing_reference.read_bytes()).decode("utf-8"),
                            family.drawing)


def verify(root: Path, sums_path: Path, expected_files: list[str],
           platform_now: dict[str, str] | None = None, complete: bool = True) -> list[FileCheck]:
    """Check every expected file (and, with `complete`, every stored one) against the stored sums and reference
    copies. `complete`: the files given are all the pipeline makes, so a stored sum with no file is a change;
    without it only the files given are checked (a user's subset).

    `platform_now`: the running platform's facts (gathered when a file is within tolerance and not given)."""
    from .platform_facts import PLATFORM_NAME, differences, gather, read

    root = Path(root)
    sums = read_sums(sums_path)
    reference = Path(sums_path).parent / REFERENCE_DIR
    platform_note: str | None = None
    checks: list[FileCheck] = []
    for rel in sorted(set(expected_files) | (set(sums) if complete else set())):
        path = root / rel
        if rel not in sums:
            checks.append(FileCheck(rel, CHANGED, "no stored checksum (new figure? refresh the sums)"))
            continue
        if rel not in expected_files:
            checks.append(FileCheck(rel, CHANGED, "has a stored checksum but the pipeline no longer makes it"))
            continue
        if not path.exists():
            checks.append(FileCheck(rel, CHANGED, "missing (build it first)"))
            continue
        if sha256_of(path) == sums[rel]:
            checks.append(FileCheck(rel, IDENTICAL))
            continue
        broken = integrity_problem(path)
        if broken is not None:
            checks.append(FileCheck(rel, CHANGED, f"broken: {broken}; delete it and rebuild (snakemake --cores 2 {rel})"))
            continue
        try:
            comparison = _compare_with_reference(root, rel, _data_file_for(rel, expected_files), reference)
        except (ValueError, UnicodeDecodeError, OSError) as exc:
            comparison = f"cannot compare with the reference ({type(exc).__name__}: {exc})"
        if isinstance(comparison, str):
            checks.append(FileCheck(rel, CHANGED, f"checksum mismatch; {comparison}"))
        elif not comparison.within:
            checks.append(FileCheck(rel, CHANGED, f"checksum mismatch; {comparison.describe()}"))
        else:
            if platform_note is None:
                running = platform_now if platform_now is not None else gather()
                differ = differences(read(Path(sums_path).parent / PLATFORM_NAME), running)
                platform_note = ("platform differs from the sums': " + "; ".join(differ)) if differ else \
                    "platform facts as recorded (the difference has another cause)"
            checks.append(FileCheck(rel, WITHIN, f"{comparison.describe()}; {platform_note}"))
    return checks


def failures(checks: list[FileCheck], strict: bool = False) -> list[FileCheck]:
    """The checks that fail verification: every "changed", and with `strict` every "within tolerance" too."""
    failing = {CHANGED, WITHIN} if strict else {CHANGED}
    return [c for c in checks if c.outcome in failing]


def summary(checks: list[FileCheck]) -> str:
    counts = {outcome: sum(c.outcome == outcome for c in checks) for outcome in (IDENTICAL, WITHIN, CHANGED)}
    return ", ".join(f"{n} {outcome}" for outcome, n in counts.items())


def refresh(root: Path, sums_path: Path, files: list[str], platform_now: dict[str, str] | None = None) -> None:
    """Write the sums of `files`, copy their data (CSV) and drawings (SVG, gzipped) to the reference folder, and
    record the platform they were made on beside the sums."""
    from .platform_facts import PLATFORM_NAME, gather, write

    root = Path(root)
    reference = Path(sums_path).parent / REFERENCE_DIR
    reference.mkdir(parents=True, exist_ok=True)
    lines = [f"{sha256_of(root / rel)}  {rel}" for rel in sorted(files)]
    keep = set()
    for rel in files:
        target = reference_path(reference, rel)
        if rel.endswith(".csv"):
            shutil.copyfile(root / rel, target)
        elif rel.endswith(".svg"):
            _write_gzip(root / rel, target)
        else:
            continue
        keep.add(target.name)
    for stale in [*reference.glob("*.csv"), *reference.glob("*.svg.gz")]:
        if stale.name not in keep:
            stale.unlink()
    write(Path(sums_path).parent / PLATFORM_NAME, platform_now if platform_now is not None else gather())
    with atomic_path(sums_path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
