"""Whether a figure's data (CSV) and drawing (SVG) agree with their reference copies within tolerance.

A comparison gives the worst number (the one nearest to or furthest over its allowance) or, for anything that is
not a number within tolerance (a column renamed or reordered, a row more or less, a text cell, a header line, the
SVG's text around its numbers), a structural difference, which makes the file "changed" whatever its numbers.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from ..tables import SIGNIFICANT_DIGITS
from .tolerances import Family, Tolerance, tolerance_for, unit_of

# A number as write_csv, the header lines and matplotlib's SVG writer print it.
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?|\bnan\b|[-+]?\binf\b")
_SIGNIFICANT = re.compile(r"[1-9]\d*")


@dataclass(frozen=True)
class NumberDifference:
    """One number of a file against its reference: where, the two values and what was allowed."""

    where: str  # "column torque_Nm, row 4", "header noise_floor_Nm", "drawing number 1234 (line 56)"
    old: float
    new: float
    allowed: float
    unit: str = ""

    @property
    def abs_diff(self) -> float:
        if math.isnan(self.old) and math.isnan(self.new):
            return 0.0
        if self.old == self.new:  # equal infinities
            return 0.0
        return abs(self.new - self.old)

    @property
    def within(self) -> bool:
        return self.abs_diff <= self.allowed  # a NaN on one side only is never within

    @property
    def severity(self) -> float:
        """How much of its allowance the difference uses (over 1: beyond it)."""
        d = self.abs_diff
        if math.isnan(d):
            return math.inf
        return d / self.allowed if self.allowed > 0 else (math.inf if d > 0 else 0.0)

    def describe(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        return (f"{self.where}: {self.old:.7g} -> {self.new:.7g} "
                f"(abs {self.abs_diff:.3g}{unit}, allowed {self.allowed:.3g}{unit})")


@dataclass(frozen=True)
class Comparison:
    """Result of comparing a file with its reference: a structural difference, or the worst number (None: equal)."""

    structure: str | None = None
    worst: NumberDifference | None = None

    @property
    def within(self) -> bool:
        return self.structure is None and (self.worst is None or self.worst.within)

    def describe(self) -> str:
        if self.structure is not None:
            return self.structure
        if self.worst is None or self.worst.abs_diff == 0.0:
            return "numbers identical to the reference"
        return ("largest difference " if self.worst.within else "") + self.worst.describe()


def printing_unit(text: str) -> float:
    """One unit of the last printed digit if `text` shows all SIGNIFICANT_DIGITS digits (the formatter may have
    rounded it), else 0 (a shorter number was printed exactly)."""
    mantissa, _, exponent = text.lower().lstrip("+-").partition("e")
    digits = mantissa.replace(".", "")
    significant = _SIGNIFICANT.search(digits)
    if significant is None or len(significant.group()) < SIGNIFICANT_DIGITS:
        return 0.0
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** ((int(exponent) if exponent else 0) - decimals)


def _number_difference(where: str, old_text: str, new_text: str, tolerance: Tolerance, unit: str,
                       rounded: bool = True) -> NumberDifference:
    """`rounded`: the numbers were printed with SIGNIFICANT_DIGITS, so one unit of the last digit is allowed too."""
    old, new = float(old_text), float(new_text)
    scale = max(abs(old), abs(new)) if math.isfinite(old) and math.isfinite(new) else 0.0
    allowed = tolerance.atol + tolerance.rtol * scale
    if rounded:
        allowed += max(printing_unit(old_text), printing_unit(new_text))
    return NumberDifference(where, old, new, allowed, unit)


def _is_number(text: str) -> bool:
    return NUMBER.fullmatch(text.strip()) is not None


def _worse(a: NumberDifference | None, b: NumberDifference) -> NumberDifference:
    return b if a is None or b.severity > a.severity else a


def _split_table(text: str) -> tuple[list[str], list[str], list[list[str]]]:
    """Header lines (without '# '), column names and rows of cells, as parksteer.tables.write_csv writes them."""
    lines = text.splitlines()
    header = [line for line in lines if line.startswith("#")]
    body = [line for line in lines if not line.startswith("#") and line.strip()]
    if not body:
        raise ValueError("no header row")
    return header, body[0].split(","), [line.split(",") for line in body[1:]]


def _compare_text_with_numbers(where: str, old: str, new: str, tolerance: Tolerance, unit: str = "",
                               rounded: bool = True) -> tuple[str | None, NumberDifference | None]:
    """Text that may hold numbers (a header line, an SVG): identical with numbers as placeholders, numbers within."""
    if NUMBER.sub("#", old) != NUMBER.sub("#", new):
        return f"{where}: text differs", None
    worst = None
    for k, (a, b) in enumerate(zip(NUMBER.findall(old), NUMBER.findall(new)), start=1):
        if a != b:
            worst = _worse(worst, _number_difference(f"{where}, number {k}", a, b, tolerance, unit, rounded))
    return None, worst


def compare_tables(new_csv: Path, reference_csv: Path, family: Family) -> Comparison:
    """Compare a figure's CSV with its reference cell by cell under the family's tolerances."""
    old_header, old_names, old_rows = _split_table(Path(reference_csv).read_text(encoding="utf-8"))
    new_header, new_names, new_rows = _split_table(Path(new_csv).read_text(encoding="utf-8"))
    if old_names != new_names:
        return Comparison(f"columns differ: {old_names} -> {new_names}")
    if len(old_rows) != len(new_rows):
        return Comparison(f"{len(old_rows)} rows in the reference and {len(new_rows)} now")
    if len(old_header) != len(new_header):
        return Comparison(f"{len(old_header)} header lines in the reference and {len(new_header)} now")
    worst: NumberDifference | None = None
    for old_line, new_line in zip(old_header, new_header):
        key = old_line[1:].partition(":")[0].strip()
        structure, header_worst = _compare_text_with_numbers(f"header {key}", old_line, new_line, family.default)
        if structure is not None:
            return Comparison(structure)
        if header_worst is not None:
            worst = _worse(worst, header_worst)
    unit_column = old_names.index("unit") if "unit" in old_names else None
    for r, (old_row, new_row) in enumerate(zip(old_rows, new_rows), start=1):
        if len(old_row) != len(new_row):
            return Comparison(f"row {r} has {len(old_row)} cells in the reference and {len(new_row)} now")
        row_unit = old_row[unit_column] if unit_column is not None else None
        for name, a, b in zip(old_names, old_row, new_row):
            if a == b:
                continue
            if not (_is_number(a) and _is_number(b)):
                return Comparison(f"text column {name}, row {r}: {a!r} -> {b!r} (text must match exactly)")
            unit = unit_of(name, row_unit)
            diff = _number_difference(f"column {name}, row {r}", a, b, tolerance_for(family, unit), unit or "")
            worst = _worse(worst, diff)
    return Comparison(None, worst)


def _canonical_ids(svg: str) -> str:
    """matplotlib names clip paths and markers by a hash of their geometry (p0123456789, m0123456789); a moved
    coordinate renames them. Rename them in order of first appearance so only their geometry is compared."""
    names: dict[str, str] = {}

    def rename(match: re.Match) -> str:
        return names.setdefault(match.group(0), f"id_{len(names) + 1}")

    return re.sub(r"(?<=[\"#])[pm][0-9a-f]{10}(?=[\")])", rename, svg)


def compare_drawings(new_svg: Path, reference_svg_text: str, tolerance: Tolerance) -> Comparison:
    """Compare an SVG with its reference: identical text around the numbers, numbers within `tolerance` (points)."""
    old = _canonical_ids(reference_svg_text)
    new = _canonical_ids(Path(new_svg).read_text(encoding="utf-8"))
    old_lines, new_lines = old.splitlines(), new.splitlines()
    if len(old_lines) != len(new_lines):
        return Comparison(f"drawing has {len(old_lines)} lines in the reference and {len(new_lines)} now")
    worst: NumberDifference | None = None
    for n, (a, b) in enumerate(zip(old_lines, new_lines), start=1):
        if a == b:
            continue
        # matplotlib prints drawing numbers with fixed decimals, not 7 significant digits: no printing unit
        structure, line_worst = _compare_text_with_numbers(f"drawing line {n}", a, b, tolerance, "pt", rounded=False)
        if structure is not None:
            return Comparison(f"{structure} beyond its numbers ({a.strip()[:60]!r} -> {b.strip()[:60]!r})")
        if line_worst is not None:
            worst = _worse(worst, line_worst)
    return Comparison(None, worst)
