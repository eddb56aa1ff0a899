"""The native format (data/measurements/README.md): a text table whose header names only native columns, SI units
in the names, no units row. Any dialect :func:`parksteer.measure.text_table.read_table` accepts (delimiter, line ends,
byte-order mark, blank lines)."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

from ..io import ALLOWED_COLUMNS
from ..text_table import header_cells, is_number, read_table
from .base import Record, Source, decode_text


class NativeCsvReader:
    name: ClassVar[str] = "native CSV"
    suffixes: ClassVar[tuple[str, ...]] = (".csv",)

    def sniff(self, head: bytes) -> bool:
        """The header row names only native columns and the row under it holds numbers (no units row)."""
        rows = header_cells(head.decode("utf-8", errors="replace"), rows=2)
        if len(rows) < 1 or not all(name in ALLOWED_COLUMNS for name in rows[0]):
            return False
        return len(rows) < 2 or all(is_number(cell, ",") for cell in rows[1] if cell)

    def read(self, raw: bytes, where: Path) -> Record:
        table = read_table(decode_text(raw, where), where)
        sources = [Source(name, None, column=j) for j, name in enumerate(table.header)]
        return Record(self.name, sources, dict(table.metadata), table.line_numbers,
                      lambda source: table.column(source.column, source.name))
