"""The code parameter of each rule: the digest of the package modules its script runs (parksteer.code_inputs).
It names the modules a script really runs, follows an added import without any step of a maintainer's, ignores
docstrings and comment lines, and changes for exactly the scripts that can run an edited module."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import syntax_trees

from parksteer.code_inputs import code_digest, script_files

ROOT = Path(__file__).resolve().parents[2]


def _scripts(root: Path) -> list[str]:
    return sorted(p.relative_to(root).as_posix() for folder in ("workflow/scripts", "workflow/notebooks")
                  for p in (root / folder).glob("*.py"))


@pytest.fixture
def package_copy(tmp_path) -> Path:
    """A copy of the package and the workflow's scripts, free to edit."""
    for folder in ("src/parksteer", "workflow/scripts", "workflow/notebooks"):
        shutil.copytree(ROOT / folder, tmp_path / folder, ignore=shutil.ignore_patterns("__pycache__", "prebuilt"))
    return tmp_path


def test_each_script_runs_the_modules_it_imports():
    """Fig. A3's script runs figures/lifting.py and no model code; the derivation runs every effect module (loaded by
    the effect registry, which no import statement shows) and no numerics; a sweep batch runs the numerics; the case
    study notebook the diagnosis."""
    fig_a3 = script_files(ROOT, "workflow/scripts/figA3.py")
    assert "src/parksteer/figures/lifting.py" in fig_a3 and "src/parksteer/__init__.py" in fig_a3
    assert not any(name.startswith("src/parksteer/model/") for name in fig_a3)
    derive = script_files(ROOT, "workflow/scripts/derive.py")
    effects = sorted((ROOT / "src/parksteer/model/symbolic/effects").glob("*.py"))
    assert {p.relative_to(ROOT).as_posix() for p in effects} <= set(derive)
    assert not any(name.startswith("src/parksteer/model/numeric/") for name in derive)
    assert "src/parksteer/model/numeric/simulate.py" in script_files(ROOT, "workflow/scripts/sweep_batch.py")
    assert "src/parksteer/diagnose/settings.py" in script_files(ROOT, "workflow/notebooks/case_study.py")


def test_a_docstring_or_comment_changes_no_digest_and_code_changes_exactly_its_users(package_copy):
    """Rewording a module's docstring and a function's, and adding a comment line, leave every script's digest as
    it was; a statement added to sweep/run.py changes the digest of exactly the scripts whose files include it
    (the sweep batch's among them, not Fig. A3's)."""
    before = {s: code_digest(package_copy, s) for s in _scripts(package_copy)}
    run = package_copy / "src/parksteer/sweep/run.py"
    text = run.read_text(encoding="utf-8")
    first_def = text.index('"""', text.index("\ndef ")) + 3
    run.write_text('"""Reworded. ' + text[3:first_def] + "Reworded. " + text[first_def:] + "\n# a comment\n",
                   encoding="utf-8")
    assert {s: code_digest(package_copy, s) for s in before} == before

    run.write_text(run.read_text(encoding="utf-8") + "\n_EDITED = 1\n", encoding="utf-8")
    after = {s: code_digest(package_copy, s) for s in before}
    changed = {s for s in before if after[s] != before[s]}
    users = {s for s in before if "src/parksteer/sweep/run.py" in script_files(package_copy, s)}
    assert changed == users
    assert "workflow/scripts/sweep_batch.py" in changed and "workflow/scripts/figA3.py" not in changed


def test_an_added_import_is_followed_without_a_step(package_copy):
    """figures/lifting.py gains an import of the sweep: Fig. A3's script now runs the sweep's declaration, and an
    edit there changes its digest; nothing had to be regenerated."""
    lifting = package_copy / "src/parksteer/figures/lifting.py"
    lifting.write_text(lifting.read_text(encoding="utf-8") + "\nfrom ..sweep import declaration\n", encoding="utf-8")
    assert "src/parksteer/sweep/declaration.py" in script_files(package_copy, "workflow/scripts/figA3.py")
    before = code_digest(package_copy, "workflow/scripts/figA3.py")
    declaration = package_copy / "src/parksteer/sweep/declaration.py"
    declaration.write_text(declaration.read_text(encoding="utf-8") + "\n_EDITED = 1\n", encoding="utf-8")
    assert code_digest(package_copy, "workflow/scripts/figA3.py") != before


def test_imports_are_found_wherever_a_statement_can_hold_them():
    """Every module the package's files and the workflow's scripts import, at any depth (inside functions, `try`,
    `with`, `if` and `match` blocks), is among the names the digest follows: checked against a walk of every node of
    each file's syntax tree, an independent way of finding the same import statements."""
    import ast

    from parksteer.code_inputs import _read

    files = [*(ROOT / "src/parksteer").rglob("*.py"), *(ROOT / p for p in _scripts(ROOT))]
    for path in files:
        every = []
        for node in syntax_trees.nodes(path.read_text(encoding="utf-8")):
            if isinstance(node, ast.Import):
                every += [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                every.append("." * node.level + (node.module or ""))
        assert set(every) <= set(_read(path)[0]), path
    nested = [p for p in files if "\n        from " in p.read_text(encoding="utf-8")]
    assert nested  # the package does import inside blocks within functions: the check above covers such imports
