"""Every relative link of README.md and docs/*.md reaches a file of the repository, and every `#anchor` a heading of
that file (as GitHub makes a heading's anchor), so a reader following the front page into the book never lands on
nothing; the table of contents (docs/README.md) lists every page, and docs/targets.md every figure target."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCUMENTS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^```.*?^```", re.S | re.M)


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but hyphens dropped, spaces made hyphens."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    text = FENCE.sub("", path.read_text(encoding="utf-8"))
    return {anchor(m.group(1)) for m in re.finditer(r"^#+\s+(.*)$", text, re.M)}


def links(path: Path) -> list[tuple[int, str]]:
    text = FENCE.sub(lambda m: "\n" * m.group(0).count("\n"), path.read_text(encoding="utf-8"))
    return [(text.count("\n", 0, m.start()) + 1, m.group(1)) for m in LINK.finditer(text)]


def test_anchor_follows_github():
    assert anchor("A cold build on 2 cores") == "a-cold-build-on-2-cores"
    assert anchor("Damage: `parksteer repair`, run before the pipeline") == \
        "damage-parksteer-repair-run-before-the-pipeline"


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda p: str(p.relative_to(REPO)))
def test_every_relative_link_reaches_a_file_and_heading(document):
    broken = []
    for line, target in links(document):
        if re.match(r"[a-z]+:", target):  # http:, https:, mailto: are not checked here (no network)
            continue
        name, _, fragment = target.partition("#")
        path = (document.parent / name).resolve() if name else document
        if not path.exists():
            broken.append(f"{document.name}:{line}: {target}: no such file")
        elif fragment and path.suffix == ".md" and fragment not in anchors(path):
            broken.append(f"{document.name}:{line}: {target}: no heading with that anchor in {path.name}")
    assert not broken, "\n".join(broken)


def test_the_front_page_links_the_page_that_draws_the_house():
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    assert "(docs/house.md)" in readme
    assert len([t for _, t in links(REPO / "README.md") if t.startswith("docs/")]) >= 10  # the links are read


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
