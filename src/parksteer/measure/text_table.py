"""Delimited text tables as loggers and spreadsheets write them: metadata lines, a header, an optional units row
and the data cells (:func:`read_table`), and the number in a cell (:func:`parse_number`). Every defect is one
line naming the file and, where it applies, the column, the data row and its line number."""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import UsageError


# The most data rows a record may have: an hour at 1 kHz. A longer record is refused before it is parsed.
MAX_SAMPLES = 3_600_000


def parse_number(text: str, where: str) -> float:
    cell = text.strip()
    if not cell:
        raise UsageError(f"{where}: empty cell where a number is required")
    try:
        value = float(cell)
    except ValueError:
        raise UsageError(f"{where}: {cell!r} is not a number") from None
    if not math.isfinite(value):
        raise UsageError(f"{where}: {cell!r} is not a finite number")
    return value


DELIMITERS = {",": "comma", ";": "semicolon", "\t": "tab"}


_DECIMAL_COMMA = re.compile(r"^\s*[+-]?\d*,\d+([eE][+-]?\d+)?\s*$")


@dataclass(frozen=True)
class Table:
    """A delimited text table as written: metadata, header, an optional units row and the raw data cells."""

    where: Path | str
    metadata: dict[str, str]
    header: list[str]
    header_line: int
    units: list[str] | None
    rows: list[tuple[int, list[str]]]  # (line number, cells)
    delimiter: str
    decimal: str

    @property
    def line_numbers(self) -> list[int]:
        return [line_no for line_no, _ in self.rows]

    def column(self, j: int, name: str | None = None) -> np.ndarray:
        """Column `j` as floats; a cell that is not a finite number is refused naming column, row and line."""
        name = self.header[j] if name is None else name
        texts = [cells[j] for _, cells in self.rows]
        if self.decimal == ",":
            texts = [text.replace(",", ".") for text in texts]
        try:  # float() strips a cell as parse_number does; the loop below names the first cell that is no number
            values = np.fromiter(map(float, texts), dtype=float, count=len(texts))
        except (ValueError, TypeError):
            values = None
        if values is not None and np.isfinite(values).all():
            return values
        values = np.empty(len(self.rows))
        for row, (line_no, cells) in enumerate(self.rows, start=1):
            cell = cells[j]
            if self.decimal == ",":
                cell = cell.replace(",", ".")
            values[row - 1] = parse_number(cell, f"{self.where}: column {name!r}, row {row} (line {line_no})")
        return values


def _split(line: str, delimiter: str) -> list[str]:
    """The cells of a line; a cell in double quotes (as spreadsheets write "0.01" or "time_s") loses its quotes,
    and a delimiter inside quotes is part of the cell."""
    if '"' not in line:
        return list(map(str.strip, line.split(delimiter)))
    cells = next(csv.reader([line], delimiter=delimiter, skipinitialspace=True))
    return [_unquote(cell.strip()) for cell in cells]


def _unquote(cell: str) -> str:
    """'"0.01"' -> '0.01' (a quoted cell followed by spaces keeps its quotes through the csv module)."""
    if len(cell) >= 2 and cell[0] == cell[-1] == '"':
        return cell[1:-1].replace('""', '"').strip()
    return cell


def _delimiter(header_text: str) -> str:
    """The header names the columns once each: the delimiter it uses most is the file's (tab, semicolon, else
    comma)."""
    counts = {d: header_text.count(d) for d in ("\t", ";")}
    return max(counts, key=counts.get) if max(counts.values()) > 0 else ","


def header_cells(text: str, rows: int = 1) -> list[list[str]]:
    """The cells of the header row and the `rows` - 1 rows after it (fewer if the text ends), split as
    :func:`read_table` splits them; for a reader to tell a format by its first lines."""
    found: list[list[str]] = []
    delimiter = ","
    for line in text.removeprefix("\ufeff").splitlines():
        if not line.strip() or (line.startswith("#") and not found):
            continue
        if not found:
            delimiter = _delimiter(line)
        found.append(_split(line, delimiter))
        if len(found) == rows:
            break
    return found


def is_number(cell: str, decimal: str = ".") -> bool:
    """Whether `cell` reads as a number with the decimal mark `decimal` ("." or ",")."""
    try:
        float(cell.replace(",", ".") if decimal == "," else cell)
    except ValueError:
        return False
    return True


def read_table(text: str, where: Path | str) -> Table:
    """Split text into metadata, header, optional units row and data rows; detect the dialect.

    Accepted as loggers and spreadsheets write them: a UTF-8 byte-order mark, CRLF or CR line ends, blank lines
    anywhere, comma, semicolon or tab between cells (the one the header row uses most), a decimal comma (with a
    semicolon or tab delimiter), and a units row right under the header (every cell not a number, e.g.
    ``s;mm;N*m``). Each row must have as many cells as the header.
    """
    if text.startswith("\ufeff"):  # a byte-order mark, as spreadsheets write
        text = text[1:]
    metadata: dict[str, str] = {}
    header_text: str | None = None
    header_line = 0
    lines: list[tuple[int, str]] = []
    for line_no, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        if line.startswith("#"):
            if header_text is not None:
                raise UsageError(f"{where}: line {line_no}: metadata line after the header row; move it above")
            key, colon, value = line[1:].partition(":")
            key = key.strip()
            if not colon or not key:
                raise UsageError(f"{where}: line {line_no}: metadata must read '# key: value', got {line.strip()!r}")
            if key in metadata:
                raise UsageError(f"{where}: line {line_no}: metadata key {key!r} given twice")
            metadata[key] = value.strip()
        elif header_text is None:
            header_text, header_line = line, line_no
        else:
            lines.append((line_no, line))
    if header_text is None:
        raise UsageError(f"{where}: empty file (no header row)")
    delimiter = _delimiter(header_text)
    header = _split(header_text, delimiter)
    if any(not name for name in header):
        raise UsageError(f"{where}: line {header_line}: empty column name in the header row")
    seen = set()
    for name in header:
        if name in seen:
            raise UsageError(f"{where}: column {name!r} appears twice in the header row")
        seen.add(name)
    if len(lines) > MAX_SAMPLES:
        raise UsageError(f"{where}: {len(lines)} data rows, beyond the {MAX_SAMPLES} a record may have (an hour at "
                         "1 kHz); cut it to the steering cycles")
    rows = [(line_no, _split(line, delimiter)) for line_no, line in lines]
    decimal = "."
    if delimiter != "," and any(_DECIMAL_COMMA.match(cell) for _, cells in rows[:200] for cell in cells):
        decimal = ","
    units = None
    if rows and any(rows[0][1]) and not any(is_number(cell, decimal) for cell in rows[0][1] if cell):
        units = rows.pop(0)[1]
        if len(units) != len(header):
            raise UsageError(
                f"{where}: units row (line {header_line + 1}): {len(units)} fields where the header has {len(header)}"
            )
    if not rows:
        raise UsageError(f"{where}: no data rows after the header")
    for row, (line_no, cells) in enumerate(rows, start=1):
        if len(cells) != len(header):
            raise UsageError(
                f"{where}: row {row} (line {line_no}): {len(cells)} fields where the header has {len(header)}"
            )
    return Table(where, metadata, header, header_line, units, rows, delimiter, decimal)
