"""The parts a diagnosis report's section is made of, which both pages render (:mod:`parksteer.reporting.pages`):
a paragraph, a list, a table, a figure's place, and the section holding them (:mod:`parksteer.reporting.sections`
writes them)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Paragraph:
    text: str
    lead: str | None = None  # a bold lead (the verdict's head)


@dataclass(frozen=True)
class Bullets:
    lines: tuple[str, ...]


@dataclass(frozen=True)
class Table:
    head: tuple[str, ...]
    rows: tuple[tuple, ...]


@dataclass(frozen=True)
class FigurePlace:
    """Where a figure goes, by its name (``diagnosis``, ``phases``, ``ladder``, ``user_effect``): each page puts
    the figure it was given under that name there (the markdown report links it, the HTML page inlines it)."""

    name: str


@dataclass(frozen=True)
class Section:
    title: str | None  # None: the verdict (before the first heading) or a note without a heading
    parts: tuple = field(default_factory=tuple)
    level: int = 2


def table(head, rows) -> Table:
    return Table(tuple(head), tuple(tuple(r) for r in rows))
