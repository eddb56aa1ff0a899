"""The declaration of each workflow script's package files (workflow/code_inputs.yaml), which the rules list as
inputs: it is what the sources give now (`parksteer plan --check`), it names the modules a script really runs,
and an import added to a module makes it stale until `parksteer plan` writes it again."""

from __future__ import annotations

import shutil
from pathlib import Path

import yaml

from parksteer.cli import main
from parksteer.code_inputs import DECLARATION, stale_scripts, trace


def _declared(root: Path) -> dict[str, list[str]]:
    return yaml.safe_load((root / DECLARATION).read_text(encoding="utf-8"))


def test_the_declaration_is_current(repo_root):
    """Every script's entry is what tracing the sources gives: after an import is added or removed, this fails
    until `parksteer plan` is run and the file committed."""
    assert stale_scripts(repo_root) == []
    assert set(_declared(repo_root)) == {
        p.relative_to(repo_root).as_posix()
        for folder in ("workflow/scripts", "workflow/notebooks")
        for p in (repo_root / folder).glob("*.py")
    }


def test_each_script_is_declared_with_the_modules_it_runs(repo_root):
    """Fig. A3's script runs figures/lifting.py and no model code; the derivation runs every effect module (loaded by
    the effect registry, which no import statement shows) and no numerics; a sweep batch runs the numerics; the case
    study notebook the diagnosis."""
    declared = _declared(repo_root)
    fig_a3 = declared["workflow/scripts/figA3.py"]
    assert "src/parksteer/figures/lifting.py" in fig_a3 and "src/parksteer/__init__.py" in fig_a3
    assert not any(name.startswith("src/parksteer/model/") for name in fig_a3)
    derive = declared["workflow/scripts/derive.py"]
    effects = sorted((repo_root / "src/parksteer/model/symbolic/effects").glob("*.py"))
    assert {p.relative_to(repo_root).as_posix() for p in effects} <= set(derive)
    assert not any(name.startswith("src/parksteer/model/numeric/") for name in derive)
    assert "src/parksteer/model/numeric/simulate.py" in declared["workflow/scripts/sweep_batch.py"]
    assert "src/parksteer/diagnose/settings.py" in declared["workflow/notebooks/case_study.py"]


def test_an_added_import_makes_the_declaration_stale_until_plan_writes_it(tmp_path, capsys):
    """In a copy of the package and scripts, figures/lifting.py gains an import of the sweep: `parksteer plan
    --check` fails naming the scripts that run lifting.py (Fig. A3's among them, not the derivation's); after
    `parksteer plan` the check passes and Fig. A3's entry holds the sweep's modules."""
    root = Path(__file__).resolve().parents[2]
    for folder in ("src/parksteer", "workflow/scripts", "workflow/notebooks"):
        shutil.copytree(root / folder, tmp_path / folder, ignore=shutil.ignore_patterns("__pycache__"))
    (tmp_path / "workflow" / "Snakefile").write_text("", encoding="utf-8")
    shutil.copy(root / DECLARATION, tmp_path / DECLARATION)
    assert main(["plan", "--root", str(tmp_path), "--check"]) == 0
    lifting = tmp_path / "src" / "parksteer" / "figures" / "lifting.py"
    lifting.write_text(lifting.read_text(encoding="utf-8") + "\nfrom ..sweep import declaration\n", encoding="utf-8")

    assert main(["plan", "--root", str(tmp_path), "--check"]) == 1
    stale = stale_scripts(tmp_path)
    assert "workflow/scripts/figA3.py" in stale and "workflow/scripts/derive.py" not in stale
    assert "workflow/scripts/figA3.py is not current" in capsys.readouterr().out

    assert main(["plan", "--root", str(tmp_path)]) == 0
    assert main(["plan", "--root", str(tmp_path), "--check"]) == 0
    assert "src/parksteer/sweep/declaration.py" in _declared(tmp_path)["workflow/scripts/figA3.py"]
    assert _declared(tmp_path) == trace(tmp_path)
