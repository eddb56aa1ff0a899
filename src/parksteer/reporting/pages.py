"""A diagnosis's JSON (:func:`parksteer.reporting.report.diagnosis_dict`) as markdown, and as one self-contained
HTML page (figures inlined as SVG, no external reference): both render the same sections
(:func:`parksteer.reporting.sections.report_sections`), so a section cannot be in one and not the other."""

from __future__ import annotations

import html
import re
from pathlib import Path

from ..tables import atomic_path
from .report import html_table
from .parts import Bullets, FigurePlace, Paragraph, Section, Table
from .sections import report_sections


def markdown_report(result: dict, figure: str | None = None, user_figure: str | None = None,
                    phases: list[dict] | None = None, ladder: dict | None = None) -> str:
    """A readable report of the JSON of a diagnosis (`figure`: the diagnosis's figure to link; `user_figure`: that of
    a user's effect in the model; `phases`, `ladder`: the residual by phase and the error ladder, where computed)."""
    links = {"diagnosis": (figure, "diagnosis"),
             "user_effect": (user_figure, "your effect: the ladder, the record, the residual by phase, the error "
                                          "falling")}
    lines = ["# Diagnosis: model against measurement"]
    for section in report_sections(result, phases, ladder):
        if section.title is not None:
            lines += ["", "#" * section.level + " " + section.title]
        for part in section.parts:
            if isinstance(part, Paragraph):
                lines += ["", f"**{part.lead}** {part.text}" if part.lead else part.text]
            elif isinstance(part, Bullets):
                lines += [""] + [f"- {line}" for line in part.lines]
            elif isinstance(part, Table):
                lines += ["", "| " + " | ".join(part.head) + " |", "|" + "---|" * len(part.head)]
                lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in part.rows]
            elif isinstance(part, FigurePlace) and links.get(part.name, (None,))[0]:
                path, alt = links[part.name]
                lines += ["", f"![{alt}]({path})"]
    return "\n".join(lines) + "\n"


def write_markdown(path: str | Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


_SVG_START = re.compile(r"<svg[\s>]")
_METADATA = re.compile(r"<metadata>.*?</metadata>\s*", re.DOTALL)


def inline_svg(text: str, prefix: str) -> str:
    """An SVG file's text as an inline element of a page that holds several: the XML declaration, the DOCTYPE
    (which names an external DTD) and the RDF metadata (which names vocabularies by URL) dropped, so the page
    refers to nothing outside itself, and every id prefixed with `prefix`, so two figures' ids cannot meet."""
    match = _SVG_START.search(text)
    if match is None:
        raise ValueError("not an SVG document")
    svg = _METADATA.sub("", text[match.start():])
    svg = re.sub(r'\bid="([^"]+)"', lambda m: f'id="{prefix}{m[1]}"', svg)
    svg = re.sub(r'href="#([^"]+)"', lambda m: f'href="#{prefix}{m[1]}"', svg)
    return re.sub(r"url\(#([^)]+)\)", lambda m: f"url(#{prefix}{m[1]})", svg)


_STYLE = """body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #bbb;padding:.25em .6em;text-align:right}
th:first-child,td:first-child{text-align:left}figure{margin:1em 0}figure svg{max-width:100%;height:auto}
figcaption{font-size:.9em;color:#555}.verdict{font-size:1.1em;padding:.6em;background:#f3f3f3}"""


def _plain(text: str) -> str:
    """Text of a section as HTML: escaped, markdown's backticks around names dropped."""
    return html.escape(text.replace("`", ""))


def html_report(result: dict, figures: list[tuple[str, str, str]], phases: list[dict] | None = None,
                ladder: dict | None = None, title: str | None = None) -> str:
    """One self-contained page of the same sections as :func:`markdown_report`, each figure inlined where its
    section places it (`figures`: ``(name, caption, svg text)``, the names of
    :class:`parksteer.reporting.sections.FigurePlace`)."""
    title = title or "Diagnosis: model against measurement"
    inlined = {name: (k, caption, svg) for k, (name, caption, svg) in enumerate(figures)}
    out = ["<!DOCTYPE html>", '<html lang="en">', "<head>", '<meta charset="utf-8">',
           f"<title>{html.escape(title)}</title>", f"<style>{_STYLE}</style>", "</head>", "<body>",
           f"<h1>{html.escape(title)}</h1>"]
    for section in report_sections(result, phases, ladder):
        if section.title is not None:
            out.append(f"<h{section.level}>{html.escape(section.title)}</h{section.level}>")
        for part in section.parts:
            if isinstance(part, Paragraph) and part.lead:
                out.append(f'<p class="verdict">{_plain(part.lead + " " + part.text)}</p>')
            elif isinstance(part, Paragraph):
                out.append(f"<p>{_plain(part.text)}</p>")
            elif isinstance(part, Bullets):
                out += ["<ul>"] + [f"<li>{_plain(line)}</li>" for line in part.lines] + ["</ul>"]
            elif isinstance(part, Table):
                out += html_table(list(part.head), [list(r) for r in part.rows])
            elif isinstance(part, FigurePlace) and part.name in inlined:
                k, caption, svg = inlined[part.name]
                out += ["<figure>", inline_svg(svg, f"f{k}-"), f"<figcaption>{html.escape(caption)}</figcaption>",
                        "</figure>"]
    out += ["</body>", "</html>"]
    return "\n".join(out) + "\n"
