"""No module of the package holds state that changes after import: state lives on the objects that own it.

Read from the source (an AST scan of every module under src/parksteer), so it holds for code no test runs:

- no ``global`` statement;
- no function writes into a module-level name: an item or attribute stored or deleted (``NAME[k] = v``,
  ``NAME.attr = v``, ``sys.modules[k] = v``), ``setattr``/``delattr`` on it, or a mutating method called on it
  (``NAME.append``, ``.update``, ``.pop`` ...);
- no module-level instance of a class of its own module whose methods (beyond ``__init__``) write its attributes;
- every ``functools.cache``/``lru_cache`` of a module-level function declares its return type, and that type holds
  no mutable object (str, numbers, tuple, frozenset, Path, frozen values of the package): a cache handing out one
  shared mutable object is module state by another name.

The exceptions, each with its reason, are :data:`EXCEPTIONS`, and each must still be needed (an exception that
no longer matches anything fails, so the list only shrinks).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import syntax_trees

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "parksteer"

# (module path under src/parksteer, name) -> why the module keeps that state.
EXCEPTIONS: dict[tuple[str, str], str] = {
    ("model/symbolic/derive.py", "Expr"): (
        "memoised_diff installs its short route as sympy's Expr.diff and puts sympy's own back when the last block "
        "using it ends: Kane's method and every node it recurses through call expr.diff, looked up on sympy's "
        "class, and sympy offers no other hook; the memo lives on the ShortDiff object the installed route holds"),
}

MUTATORS = frozenset({"append", "extend", "insert", "pop", "popitem", "remove", "discard", "add", "update",
                      "setdefault", "clear", "sort", "reverse", "__setitem__", "__delitem__", "__setattr__"})
# Types whose values hold nothing mutable: the package's own are frozen dataclasses of immutable fields, a
# read-only mapping of them (parameters.DeclaredQuantities: every method that changes a dict refuses) or, for
# Effect, stateless by contract (its per-build state lives on the model being built: components.Effect); a class
# (``type``) is a definition, made once.
IMMUTABLE_TYPES = frozenset({"str", "bytes", "int", "float", "bool", "complex", "None", "tuple", "frozenset",
                             "Path", "Quantity", "Effect", "MappingProxyType", "DeclaredQuantities", "type"})
CACHE_DECORATORS = frozenset({"cache", "lru_cache"})


def modules() -> list[Path]:
    return sorted(PACKAGE.rglob("*.py"))


def _root_name(node: ast.AST) -> str | None:
    """The name at the root of ``a.b[c].d`` (None when the chain passes through a call or starts elsewhere)."""
    while isinstance(node, (ast.Attribute, ast.Subscript)):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def _module_names(tree: ast.Module) -> set[str]:
    """Every name the module binds at its top level (assignments, definitions, names imported from a module, also
    inside if/try/with): the module state of the package, and the objects of other modules it could patch. A module
    imported whole (``import os``) is left out: the process state other libraries keep for their users (os.environ,
    a plotting style, sys.stderr while a rule runs) is written and restored where it is used; sys.modules is the one
    checked (:func:`_writes_in`)."""
    names: set[str] = set()

    def bind(statements):
        for node in statements:
            if isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for target in targets:
                    names.update(n.id for n in ast.walk(target) if isinstance(n, ast.Name))
            elif isinstance(node, ast.ImportFrom):
                names.update(a.asname or a.name for a in node.names)
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, (ast.If, ast.Try, ast.With)):
                bind(node.body)
                bind(getattr(node, "orelse", []))
                bind(getattr(node, "finalbody", []))
                for handler in getattr(node, "handlers", []):
                    bind(handler.body)
    bind(tree.body)
    return names


def _local_names(function: ast.AST) -> set[str]:
    """The names a function binds (arguments, assignments, loops, nested definitions; not imports, which name
    the same process-wide objects): they shadow the module's (nested functions' bindings are counted too, which can only hide a finding, never invent one)."""
    names: set[str] = set()
    for node in ast.walk(function):
        if isinstance(node, ast.arg):
            names.add(node.arg)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, (ast.Store, ast.Del)):
            names.add(node.id)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and node is not function:
            names.add(node.name)
    return names


def _writes_in(function: ast.AST, module_level: set[str]) -> list[tuple[int, str, str]]:
    """(line, name, what) for each write into a module-level name inside `function`."""
    shadowed = _local_names(function)
    imported = {a.asname or a.name for n in ast.walk(function) if isinstance(n, ast.ImportFrom) for a in n.names}
    outer = (module_level | imported) - shadowed
    found = []
    for node in ast.walk(function):
        if isinstance(node, (ast.Attribute, ast.Subscript)) and isinstance(node.ctx, (ast.Store, ast.Del)):
            name = _root_name(node)
            if name in outer or ast.unparse(node).startswith("sys.modules["):
                found.append((node.lineno, name, f"writes {ast.unparse(node)}"))
        elif isinstance(node, ast.Call):
            func = node.func
            if isinstance(func, ast.Attribute) and func.attr in MUTATORS:
                name = _root_name(func.value)
                if name in outer:
                    found.append((node.lineno, name, f"calls {ast.unparse(func)}()"))
            elif isinstance(func, ast.Name) and func.id in ("setattr", "delattr") and node.args:
                name = _root_name(node.args[0])
                if name in outer:
                    found.append((node.lineno, name, f"calls {func.id} on {ast.unparse(node.args[0])}"))
    return found


def _self_writing_classes(tree: ast.Module) -> set[str]:
    """Classes of the module with a method beyond __init__/__post_init__ that writes an attribute of self."""
    out = set()
    for cls in (n for n in tree.body if isinstance(n, ast.ClassDef)):
        for method in (n for n in cls.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))):
            if method.name in ("__init__", "__post_init__") or not method.args.args:
                continue
            this = method.args.args[0].arg
            if any(isinstance(n, (ast.Attribute, ast.Subscript)) and isinstance(n.ctx, (ast.Store, ast.Del))
                   and _root_name(n) == this for n in ast.walk(method)):
                out.add(cls.name)
    return out


def _annotation_names(annotation: ast.AST | None) -> list[str]:
    """The type names an annotation is made of (``tuple[tuple[str, Effect], ...]`` -> tuple, tuple, str, Effect)."""
    if annotation is None:
        return ["<none>"]
    if isinstance(annotation, ast.Constant) and isinstance(annotation.value, str):
        annotation = ast.parse(annotation.value, mode="eval").body
    names = []
    for node in ast.walk(annotation):
        if isinstance(node, ast.Name):
            names.append(node.id)
        elif isinstance(node, ast.Attribute):
            names.append(node.attr)
        elif isinstance(node, ast.Constant) and node.value is None:
            names.append("None")
    return names


def _cached_functions(tree: ast.Module) -> list[ast.FunctionDef]:
    out = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            for decorator in node.decorator_list:
                target = decorator.func if isinstance(decorator, ast.Call) else decorator
                name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", None)
                if name in CACHE_DECORATORS:
                    out.append(node)
    return out


def findings() -> list[tuple[str, int, str, str]]:
    """(module, line, name, what) for every piece of module-level state changed after import."""
    out = []
    for path in modules():
        where = path.relative_to(PACKAGE).as_posix()
        source = path.read_text(encoding="utf-8")
        module = syntax_trees.tree(source)
        for node in syntax_trees.nodes(source):
            if isinstance(node, ast.Global):
                out.extend((where, node.lineno, name, "global statement") for name in node.names)
        module_level = _module_names(module)
        functions = (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)
        for function in (n for n in syntax_trees.nodes(source) if isinstance(n, functions)):
            out.extend((where, line, name, what) for line, name, what in _writes_in(function, module_level))
        stateful = _self_writing_classes(module)
        for node in module.body:
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) \
                    and getattr(node.value.func, "id", None) in stateful:
                for target in node.targets:
                    out.append((where, node.lineno, ast.unparse(target),
                                f"an instance of {node.value.func.id}, whose methods write its attributes"))
        for function in _cached_functions(module):
            mutable = [n for n in _annotation_names(function.returns) if n not in IMMUTABLE_TYPES]
            if mutable:
                out.append((where, function.lineno, function.name,
                            f"a cache returning {', '.join(mutable)} (declare an immutable return type)"))
    return sorted(set(out))


def test_no_module_state_changes_after_import():
    """The fact checked: outside the listed exceptions, no module of src/parksteer has a `global` statement, a
    function writing into a module-level name, a module-level self-modifying instance, or a cache of a mutable
    value (module docstring)."""
    unexpected = [f"{where}:{line}: {name}: {what}" for where, line, name, what in findings()
                  if (where, name) not in EXCEPTIONS]
    assert not unexpected, "module-level state changed after import:\n" + "\n".join(unexpected)


def test_every_exception_is_still_needed():
    """The fact checked: each listed exception still matches a finding (a fixed one is taken off the list)."""
    matched = {(where, name) for where, _, name, _ in findings()}
    assert not set(EXCEPTIONS) - matched, f"exceptions no longer needed: {sorted(set(EXCEPTIONS) - matched)}"


@pytest.mark.parametrize("source, expected", [
    ("X = {}\ndef f():\n    X['a'] = 1\n", "X"),
    ("X = []\ndef f():\n    X.append(1)\n", "X"),
    ("import sys\ndef f(m):\n    sys.modules['m'] = m\n", "sys"),
    ("X = None\ndef f():\n    global X\n    X = 1\n", "X"),
    ("class W:\n    def start(self, s):\n        self.s = s\nWORKER = W()\n", "WORKER"),
    ("from functools import cache\n@cache\ndef f() -> dict:\n    return {}\n", "f"),
    ("X = {}\ndef f(m):\n    setattr(X, 'a', m)\n", "X"),
])
def test_the_scan_finds_each_kind_of_write(tmp_path, monkeypatch, source, expected):
    """The fact checked: each kind of write the scan is meant to catch, written into a module, is found (and the
    same module with the write inside a function on a local name is not)."""
    (tmp_path / "probe.py").write_text(source, encoding="utf-8")
    monkeypatch.setattr(__import__(__name__, fromlist=["PACKAGE"]), "PACKAGE", tmp_path)
    assert expected in {name for _, _, name, _ in findings()}
    (tmp_path / "probe.py").write_text("def f():\n    X = {}\n    X['a'] = 1\n    X.append(2)\n", encoding="utf-8")
    assert findings() == []
