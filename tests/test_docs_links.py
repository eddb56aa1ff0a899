"""Every relative link of README.md and docs/*.md leads somewhere: its file exists, and its anchor, when it names
one, is a heading of the page it points to (as GitHub makes a heading's anchor)."""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]

LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^```.*?^```", re.S | re.M)
HEADING = re.compile(r"^#{1,6} (.+?)\s*#*$", re.M)


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but hyphens and underscores dropped, spaces hyphens."""
    text = re.sub(r"[`*]", "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(page: Path) -> set[str]:
    text = FENCE.sub("", page.read_text(encoding="utf-8"))
    return {anchor(h) for h in HEADING.findall(text)}


def broken_links(page: Path, root: Path = REPO) -> list[str]:
    """The relative links of `page` whose file is missing or whose anchor is no heading of it (one line each)."""
    text = FENCE.sub("", page.read_text(encoding="utf-8"))
    problems = []
    for target in LINK.findall(text):
        if re.match(r"[a-z]+:", target):  # http:, https:, mailto:: not the repository's
            continue
        path_text, _, fragment = target.partition("#")
        path = (page.parent / path_text).resolve() if path_text else page
        where = f"{page.relative_to(root)}: ({target})"
        if not path.exists():
            problems.append(f"{where}: no file {path_text}")
        elif fragment and path.suffix == ".md" and fragment not in anchors(path):
            problems.append(f"{where}: no heading #{fragment} in {path.relative_to(root)}")
    return problems


def test_every_relative_link_resolves():
    """Each relative link of the front page and of every docs page names a file that exists and, with an anchor,
    a heading of that page: a renamed page or heading fails here, not in a reader's browser."""
    problems = [line for page in PAGES for line in broken_links(page)]
    assert not problems, "broken links:\n" + "\n".join(problems)


def test_the_link_check_can_fail(tmp_path):
    """A link to a missing file and one to a missing heading are both reported; a good one is not."""
    (tmp_path / "other.md").write_text("# Title\n\n## A car's baseline: `diagnose`\n", encoding="utf-8")
    page = tmp_path / "page.md"
    page.write_text("[ok](other.md#a-cars-baseline-diagnose) [gone](missing.md) [no](other.md#nothing)\n"
                    "```sh\n[in a block](ignored.md)\n```\n", encoding="utf-8")
    problems = broken_links(page, root=tmp_path)
    assert len(problems) == 2
    assert "no file missing.md" in problems[0] and "no heading #nothing" in problems[1]


def test_every_page_is_in_the_table_of_contents():
    """docs/README.md, the table of contents, links every page of docs/ once, so that no page is out of the book."""
    contents = (REPO / "docs" / "README.md").read_text(encoding="utf-8")
    listed = re.findall(r"^\d+\. \[[^\]]+\]\(([\w.-]+\.md)\)", contents, re.M)
    pages = sorted(p.name for p in (REPO / "docs").glob("*.md") if p.name != "README.md")
    assert sorted(listed) == pages
    assert len(listed) == len(set(listed))


def test_every_figure_target_is_in_the_targets_page():
    """Each figure or table target of the workflow (FIGURES in workflow/rules/common.smk, the one list) has its row
    in docs/targets.md naming its files, so a new target cannot be left out of the page."""
    import ast

    text = (REPO / "workflow" / "rules" / "common.smk").read_text(encoding="utf-8")
    start = text.index("FIGURES = {") + len("FIGURES = ")
    figures = ast.literal_eval(text[start:text.index("\n}\n", start) + 2])
    page = (REPO / "docs" / "targets.md").read_text(encoding="utf-8")
    rows = {m.group(1): m.group(0) for m in re.finditer(r"^\| `(\w+)` \|.*$", page, re.M)}
    missing = [target for target in figures if target not in rows]
    assert not missing, f"targets without a row in docs/targets.md: {', '.join(missing)}"
    for target, files in figures.items():
        assert f"`{files[0]}`" in rows[target], f"docs/targets.md: the row of {target} does not name {files[0]}"
