"""Build the reproduction article (paper/parksteer.typ) to PDF with Typst.

The document reads every number it quotes from pipeline outputs (results/*.json,
figures/*.csv, src/parksteer/data/parameters.toml), so the compile root is the repository. A fixed
creation timestamp and Typst's embedded fonts only (no system fonts) make the PDF
depend on its inputs alone.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import typst

from .tables import atomic_path

FIXED_TIMESTAMP = 0  # 1970-01-01T00:00:00Z, as SOURCE_DATE_EPOCH=0


def source_commit(root: str | Path = ".") -> str:
    """The git commit of the checkout at `root` the article is built from, with "+ uncommitted changes" when its
    tracked files differ from it; "unknown (not a git checkout)" outside a repository or without git."""
    def git(*args: str) -> str:
        return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, check=True).stdout.strip()

    try:
        commit = git("rev-parse", "HEAD")
        dirty = git("status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.CalledProcessError):
        return "unknown (not a git checkout)"
    return commit + (" + uncommitted changes" if dirty else "")


def build(main_typ: str | Path, out_pdf: str | Path, root: str | Path = ".", commit: str | None = None) -> int:
    """Compile `main_typ` to `out_pdf`; return the page count. The document reads `commit` (default: the checkout's,
    :func:`source_commit`) as ``sys.inputs.commit`` for its availability statement."""
    commit = source_commit(root) if commit is None else commit
    compiler = typst.Compiler(str(main_typ), root=str(root), ignore_system_fonts=True, sys_inputs={"commit": commit})
    pdf = compiler.compile(format="pdf", timestamp=FIXED_TIMESTAMP)
    with atomic_path(out_pdf) as tmp:
        tmp.write_bytes(pdf)
    return page_count(pdf)


def page_count(pdf: bytes) -> int:
    """Number of page objects in a PDF (uncompressed object dictionaries, as Typst writes them)."""
    return len(re.findall(rb"/Type\s*/Page(?![s\w])", pdf))
