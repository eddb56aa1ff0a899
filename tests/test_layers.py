"""The package's imports point down the layer order and form no cycle.

The layer order is the import-linter contract in pyproject.toml (`[tool.importlinter]`); `lint-imports` checks
it. The cycle count is a separate scan of the source, so it holds for imports inside functions too and does not
depend on the contract being written right.
"""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import syntax_trees

REPO_ROOT = Path(__file__).resolve().parents[1]
SRC = REPO_ROOT / "src"


def module_names(src: Path, package: str = "parksteer") -> dict[str, Path]:
    """Every module of `package` under `src`, by dotted name (a package by its __init__)."""
    names = {}
    for path in sorted((src / package).rglob("*.py")):
        parts = list(path.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        names[".".join(parts)] = path
    return names


def import_graph(src: Path, package: str = "parksteer") -> dict[str, set[str]]:
    """Importer -> imported modules of `package`, from every import statement (top level or in a function)."""
    modules = module_names(src, package)
    graph: dict[str, set[str]] = {name: set() for name in modules}

    def resolve(name: str) -> str | None:
        # `from a.b import c` names module a.b.c when that exists, else a name in a.b: the nearest module.
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    for importer, path in modules.items():
        is_package = path.name == "__init__.py"
        for node in syntax_trees.nodes(path.read_text()):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = importer.split(".")
                    if not is_package:
                        anchor.pop()
                    anchor = anchor[: len(anchor) - (node.level - 1)]
                    base = ".".join(anchor + ([base] if base else []))
                targets = [f"{base}.{alias.name}" for alias in node.names]
            for target in targets:
                imported = resolve(target) if target.split(".")[0] == package else None
                if imported and imported != importer:
                    graph[importer].add(imported)
    return graph


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected groups of more than one module: each is one knot of import cycles."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[list[str]] = []

    def visit(node: str) -> None:  # Tarjan's algorithm
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            group = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                group.append(member)
                if member == node:
                    break
            if len(group) > 1:
                groups.append(sorted(group))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(groups)


def test_the_scan_finds_a_planted_cycle(tmp_path):
    """The cycle scan itself can fail: two modules that import each other are one cycle."""
    pkg = tmp_path / "parksteer"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "a.py").write_text("def f():\n    from . import b\n")
    (pkg / "sub" / "b.py").write_text("from parksteer.sub.a import f\n")
    (pkg / "c.py").write_text("from parksteer.sub import a\n")
    graph = import_graph(tmp_path)
    assert graph["parksteer.c"] == {"parksteer.sub.a"}
    assert import_cycles(graph) == [["parksteer.sub.a", "parksteer.sub.b"]]


def test_no_import_cycles_between_parksteer_modules():
    cycles = import_cycles(import_graph(SRC))
    assert cycles == [], f"{len(cycles)} import cycle(s) between parksteer modules: {cycles}"


def lint_imports(cwd: Path, src: Path) -> subprocess.CompletedProcess:
    """`lint-imports` with the contracts of pyproject.toml in `cwd`, on the package found under `src`."""
    exe = shutil.which("lint-imports") or str(Path(sys.executable).with_name("lint-imports"))
    if not Path(exe).exists():
        pytest.fail("lint-imports is not installed: install the test extras (requirements/test.lock)")
    env = {**os.environ, "PYTHONPATH": str(src)}
    # No cache: a stale .import_linter_cache must not hide a new import.
    return subprocess.run([exe, "--no-cache", "--no-logo"], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=300)


def test_import_contract_holds():
    """`lint-imports` keeps every contract in pyproject.toml: layers only point down, measure stands alone."""
    done = lint_imports(REPO_ROOT, SRC)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]


def test_the_contract_catches_an_upward_import(tmp_path):
    """The contract can fail: in a copy of the package, the file format importing the model breaks it."""
    shutil.copytree(SRC / "parksteer", tmp_path / "src" / "parksteer", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy2(REPO_ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    io = tmp_path / "src" / "parksteer" / "measure" / "io.py"
    io.write_text(io.read_text() + "\n\ndef _upward():\n    from ..model.numeric import simulate  # noqa: F401\n")
    done = lint_imports(tmp_path, tmp_path / "src")
    assert done.returncode != 0, done.stdout[-2000:]
    assert "parksteer.measure.io -> parksteer.model.numeric.simulate" in done.stdout, done.stdout[-4000:]


def test_the_contracts_keep_the_method_from_reporting_and_from_the_identification_tool(tmp_path):
    """The contracts can fail on the method's rooms: in a copy of the package, the calibration importing the
    reporting (which sits above the method) breaks the layers, and the replay engine importing the assist's
    identification (which uses the engine) breaks identify-apart."""
    shutil.copytree(SRC / "parksteer", tmp_path / "src" / "parksteer", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy2(REPO_ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    diagnose = tmp_path / "src" / "parksteer" / "diagnose"
    for module, planted in (("calibrate.py", "from ..reporting import report"),
                            ("engine.py", "from .identify import boost_map")):
        path = diagnose / module
        path.write_text(path.read_text() + f"\n\ndef _upward():\n    {planted}  # noqa: F401\n")
    done = lint_imports(tmp_path, tmp_path / "src")
    assert done.returncode != 0, done.stdout[-2000:]
    assert "parksteer.diagnose.calibrate -> parksteer.reporting.report" in done.stdout, done.stdout[-4000:]
    assert "parksteer.diagnose.engine -> parksteer.diagnose.identify.boost_map" in done.stdout, done.stdout[-4000:]


def test_no_rule_script_drives_the_command_line():
    """The workflow calls the package's functions, the command line's front door included (the diagnosis's intake),
    never the command line itself: no rule script or notebook imports parksteer.cli. The scan is checked on a
    planted line first, so that it can fail."""

    def drives_cli(source: str) -> bool:
        for node in ast.walk(ast.parse(source)):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            if isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            if any(n == "parksteer.cli" or n.startswith("parksteer.cli.") for n in names):
                return True
        return False

    assert drives_cli("from parksteer.cli import main\n") and drives_cli("import parksteer.cli\n")
    assert not drives_cli("from parksteer.diagnose.intake import intake\n")
    workflow = REPO_ROOT / "workflow"
    scripts = sorted(workflow.glob("scripts/*.py")) + sorted(workflow.glob("notebooks/*.py"))
    assert len(scripts) > 10
    assert [s.name for s in scripts if drives_cli(s.read_text(encoding="utf-8"))] == []
