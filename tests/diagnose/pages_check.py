"""What the tests of the two report pages compare: the sections each page shows, in order."""

from __future__ import annotations

import html
import re

from parksteer.reporting.pages import html_report, markdown_report


def markdown_sections(text: str) -> list[str]:
    """The headings of a markdown report below its title (## and ###), in order."""
    return re.findall(r"^#{2,3} (.+)$", text, re.M)


def html_sections(page: str) -> list[str]:
    """The headings of an HTML report below its title (h2 and h3), in order, unescaped."""
    return [html.unescape(t) for t in re.findall(r"<h[23]>(.*?)</h[23]>", page)]


def both_pages(result: dict, phases=None, ladder=None) -> tuple[str, str]:
    """The markdown report and the HTML page of `result`, from the same inputs."""
    return markdown_report(result, phases=phases, ladder=ladder), html_report(result, [], phases, ladder)


def assert_same_sections(result: dict, phases=None, ladder=None) -> tuple[str, str]:
    """Each section of the markdown report is in the HTML page and the reverse, in the same order; returns both."""
    text, page = both_pages(result, phases, ladder)
    assert markdown_sections(text) == html_sections(page)
    return text, page
