"""A logger's or spreadsheet's text export: its own channel names, units in brackets after a name
(``RackPos [mm]``) or in a units row under the header, any dialect :func:`parksteer.measure.text_table.read_table`
accepts (semicolons or tabs, a decimal comma, quoted cells). Every text file that is not the native format."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

from ...errors import UsageError
from ..text_table import Table, read_table
from .base import Record, Source, decode_text, name_and_unit


class LoggerCsvReader:
    name: ClassVar[str] = "logger CSV"
    suffixes: ClassVar[tuple[str, ...]] = (".csv", ".tsv", ".txt")

    def sniff(self, head: bytes) -> bool:
        """Any file: the reader of last resort (a file that is not text is refused as not UTF-8)."""
        return True

    def read(self, raw: bytes, where: Path) -> Record:
        table = read_table(decode_text(raw, where), where)
        return Record(self.name, table_sources(table), dict(table.metadata), table.line_numbers,
                      lambda source: table.column(source.column, source.name))


def table_sources(table: Table) -> list[Source]:
    """The channels of a table: name and unit from the header cell ('RackPos[mm]') or the units row."""
    sources = []
    for j, cell in enumerate(table.header):
        name, unit = name_and_unit(cell)
        row_unit = table.units[j].strip() if table.units is not None and table.units[j].strip() else None
        if unit is not None and row_unit is not None and unit != row_unit:
            raise UsageError(f"{table.where}: column {name!r}: header says [{unit}] but the units row says {row_unit!r}")
        sources.append(Source(name, unit if unit is not None else row_unit, column=j))
    names = [s.name for s in sources]
    for name in names:
        if names.count(name) > 1:
            raise UsageError(f"{table.where}: column {name!r} appears twice in the header row")
    return sources
