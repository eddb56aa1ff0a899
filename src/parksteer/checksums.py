"""Stored checksums of every figure and its data, and a verification that explains mismatches.

``figures/SHA256SUMS`` is in the format ``sha256sum -c`` reads, paths relative to the
repository root. ``figures/reference/`` keeps a copy of each figure's data (CSV) as of
the last refresh, so a mismatch can be reported with the largest numeric difference in
the data: a user can then tell a real change (large difference) from a platform wobble
(a difference in the last printed digit, or none at all with only the SVG rendering
changed).
"""

from __future__ import annotations

import hashlib
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .tables import atomic_path, read_csv

SUMS_NAME = "SHA256SUMS"
REFERENCE_DIR = "reference"


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


@dataclass(frozen=True)
class DataDifference:
    """Largest absolute difference between a figure's data and its stored reference."""

    column: str
    row: int
    new: float
    old: float

    @property
    def abs_diff(self) -> float:
        return abs(self.new - self.old)

    @property
    def rel_diff(self) -> float:
        scale = max(abs(self.new), abs(self.old), 1e-300)
        return self.abs_diff / scale


def largest_difference(new_csv: Path, reference_csv: Path) -> DataDifference | str:
    """Compare two CSVs column by column; a string explains a structural difference."""
    new, _ = read_csv(new_csv)
    old, _ = read_csv(reference_csv)
    if list(new) != list(old):
        return f"columns differ: {list(old)} -> {list(new)}"
    worst: DataDifference | None = None
    for name in new:
        a, b = new[name], old[name]
        if a.shape != b.shape:
            return f"column {name} has {len(b)} rows in the reference and {len(a)} now"
        if a.dtype == object or b.dtype == object:
            diff_rows = [i for i, (x, y) in enumerate(zip(a, b)) if x != y]
            if diff_rows:
                return f"text column {name} differs from row {diff_rows[0] + 1}"
            continue
        d = np.abs(a - b)
        d = np.where(np.isnan(a) & np.isnan(b), 0.0, d)
        if d.size and (worst is None or np.nanmax(d) > worst.abs_diff):
            i = int(np.nanargmax(d))
            worst = DataDifference(name, i + 1, float(a[i]), float(b[i]))
    return worst if worst is not None else DataDifference("-", 0, 0.0, 0.0)


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


def verify(root: Path, sums_path: Path, expected_files: list[str]) -> list[str]:
    """Check every expected file against the stored sums; return one message per problem (empty if all pass)."""
    root = Path(root)
    sums = read_sums(sums_path)
    reference = Path(sums_path).parent / REFERENCE_DIR
    problems: list[str] = []
    for rel in sorted(set(expected_files) | set(sums)):
        path = root / rel
        if rel not in sums:
            problems.append(f"{rel}: no stored checksum (new figure? refresh the sums)")
            continue
        if rel not in expected_files:
            problems.append(f"{rel}: has a stored checksum but the pipeline no longer makes it")
            continue
        if not path.exists():
            problems.append(f"{rel}: missing (build it first)")
            continue
        if sha256_of(path) == sums[rel]:
            continue
        broken = integrity_problem(path)
        if broken is not None:
            problems.append(f"{rel}: broken: {broken}; delete it and rebuild (snakemake --cores 2 {rel})")
            continue
        data = _data_file_for(rel, expected_files)
        detail = "no data file to compare"
        if data is not None:
            ref = reference / Path(data).name
            if not ref.exists():
                detail = f"no reference copy {ref.relative_to(root) if ref.is_relative_to(root) else ref}"
            elif data != rel and integrity_problem(root / data) is not None:
                detail = f"its data {data} is broken: {integrity_problem(root / data)}"
            else:
                diff = largest_difference(root / data, ref)
                if isinstance(diff, str):
                    detail = f"data {data}: {diff}"
                elif diff.abs_diff == 0.0:
                    detail = f"data {data} identical to the reference: only the rendering differs"
                else:
                    detail = (
                        f"largest data difference in {data}: column {diff.column}, row {diff.row}: "
                        f"{diff.old:.7g} -> {diff.new:.7g} (abs {diff.abs_diff:.3g}, rel {diff.rel_diff:.3g})"
                    )
        problems.append(f"{rel}: checksum mismatch; {detail}")
    return problems


def refresh(root: Path, sums_path: Path, files: list[str]) -> None:
    """Write the sums of `files` and copy their CSV data to the reference folder."""
    root = Path(root)
    reference = Path(sums_path).parent / REFERENCE_DIR
    reference.mkdir(parents=True, exist_ok=True)
    lines = [f"{sha256_of(root / rel)}  {rel}" for rel in sorted(files)]
    keep = set()
    for rel in files:
        if rel.endswith(".csv"):
            shutil.copyfile(root / rel, reference / Path(rel).name)
            keep.add(Path(rel).name)
    for stale in reference.glob("*.csv"):
        if stale.name not in keep:
            stale.unlink()
    with atomic_path(sums_path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
