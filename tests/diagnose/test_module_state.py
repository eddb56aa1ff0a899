"""The diagnosis keeps no module-level mutable state: what replays and changes is the replay engine's
(parksteer.diagnose.engine.ReplayEngine), handed to every stage.

Scanned from the source: no ``global`` statement in diagnose/ or model/numeric/, and no module-level name of
either that its module changes in place (an item set or deleted, an augmented assignment, a mutating
method called on it, an attribute set on it). The one exception is parksteer.diagnose.parallel.WORKER, the
per-process object a worker's pool initializer fills (written only in worker processes; its docstring says why
it must exist).
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src" / "parksteer"
MUTATING = {"append", "extend", "insert", "update", "setdefault", "pop", "popitem", "clear", "add", "remove",
            "discard", "start"}
PER_PROCESS = {("parallel.py", "WORKER")}


def _modules(*folders: str) -> list[Path]:
    return sorted(p for folder in folders for p in (SRC / folder).rglob("*.py"))


def test_no_global_statement_in_the_method_or_the_numerics():
    found = [f"{path.relative_to(SRC)}:{node.lineno}" for path in _modules("diagnose", "model/numeric")
             for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))) if isinstance(node, ast.Global)]
    assert found == []


def test_no_module_level_name_of_the_method_or_the_numerics_is_changed_in_place():
    changed = []
    for path in _modules("diagnose", "model/numeric"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        names = {target.id for node in tree.body if isinstance(node, (ast.Assign, ast.AnnAssign))
                 for target in (node.targets if isinstance(node, ast.Assign) else [node.target])
                 if isinstance(target, ast.Name)}

        def base(node):
            while isinstance(node, (ast.Subscript, ast.Attribute)):
                node = node.value
            return node.id if isinstance(node, ast.Name) else None

        for node in ast.walk(tree):
            targets = []
            if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign, ast.Delete)):
                targets = node.targets if isinstance(node, (ast.Assign, ast.Delete)) else [node.target]
                targets = [t for t in targets if isinstance(t, (ast.Subscript, ast.Attribute))
                           or (isinstance(node, ast.AugAssign) and isinstance(t, ast.Name))]
            elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in MUTATING:
                targets = [node.func.value]
            for target in targets:
                name = base(target)
                if name in names and (path.name, name) not in PER_PROCESS:
                    changed.append(f"{path.relative_to(SRC)}:{node.lineno} {name}")
    assert changed == []
