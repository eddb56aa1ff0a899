"""The article's build: the availability statement carries the commit the PDF is built from."""

from __future__ import annotations

import re
import subprocess

from parksteer.paper import build, source_commit


def test_source_commit_names_the_checkout_and_says_when_it_is_not_one(repo_root, tmp_path):
    """In the repository the commit is git's own HEAD (40 hex digits, marked when tracked files differ from it);
    outside any repository the statement says so instead of naming a commit."""
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=repo_root, capture_output=True, text=True,
                          check=True).stdout.strip()
    commit = source_commit(repo_root)
    assert re.fullmatch(r"[0-9a-f]{40}( \+ uncommitted changes)?", commit)
    assert commit.startswith(head)
    assert source_commit(tmp_path) == "unknown (not a git checkout)"


def test_build_hands_the_commit_to_the_document(tmp_path):
    """A document that prints sys.inputs.commit gets the commit given to build: it compiles only when the input is
    present (the assert fails otherwise), and two commits give two different PDFs."""
    (tmp_path / "a.typ").write_text('#assert("commit" in sys.inputs)\n#sys.inputs.commit\n', encoding="utf-8")
    pdfs = []
    for commit in ("0" * 40, "1" * 40):
        out = tmp_path / f"{commit[0]}.pdf"
        assert build(tmp_path / "a.typ", out, root=tmp_path, commit=commit) == 1
        pdfs.append(out.read_bytes())
    assert pdfs[0] != pdfs[1]
