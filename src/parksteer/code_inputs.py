"""The code a workflow script runs, as one digest: the rules pass it as a parameter, so that Snakemake reruns a rule
when the code it can run changes and for nothing else.

A script's modules are found statically: every `import` and `from ... import` of the script (inside functions
too), then of the modules those load, and so on; importing parksteer.a.b also runs parksteer/__init__.py and
parksteer/a/__init__.py, and the effect registry loads every module of model/symbolic/effects. Each module
counts by its text without docstrings, whole-line comments and blank lines, so that editing a docstring or a
comment line changes no digest, while any change to what the code does changes the digest of exactly the
scripts that can run it.
"""

from __future__ import annotations

import ast
import hashlib
from functools import lru_cache
from pathlib import Path

# What runs package code from the workflow: the rule scripts and the notebooks (relative to the checkout).
SCRIPT_FOLDERS = (Path("workflow") / "scripts", Path("workflow") / "notebooks")
PACKAGE = Path("src") / "parksteer"
# Imports no `import` statement shows: the effect registry loads every module of model/symbolic/effects.
REGISTRIES = {"parksteer.model.symbolic.components": PACKAGE / "model" / "symbolic" / "effects"}


@lru_cache(maxsize=None)
def _module_file(root: Path, name: str) -> Path | None:
    """The source file of module `name` in the checkout `root`'s package, or None (not parksteer's, or no module)."""
    parts = name.split(".")
    if parts[0] != "parksteer":
        return None
    base = root.joinpath(PACKAGE, *parts[1:])
    for candidate in (base / "__init__.py", base.with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


def _read(path: Path) -> tuple[tuple[str, ...], str]:
    """The module names `path`'s import statements name (absolute, or with the leading dots of a relative import)
    and its text without docstrings, whole-line comments and blank lines, from one parse (read again when the
    file's size or modification time changed)."""
    stat = path.stat()
    return _read_version(path, stat.st_mtime_ns, stat.st_size)


def _statements(nodes):
    """Every statement under `nodes`, nested ones included (an import or a definition is a statement, and no
    expression holds one, so the expressions need no visit)."""
    for node in nodes:
        yield node
        for field in ("body", "orelse", "finalbody", "handlers", "cases"):
            inner = getattr(node, field, None)
            if isinstance(inner, list):
                yield from _statements(inner)


@lru_cache(maxsize=None)
def _read_version(path: Path, mtime_ns: int, size: int) -> tuple[tuple[str, ...], str]:
    text = path.read_text(encoding="utf-8")
    tree = ast.parse(text, filename=str(path))
    imports, docstrings = [], []
    for node in (tree, *_statements(tree.body)):
        if isinstance(node, ast.Import):
            imports.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            target = "." * node.level + (node.module or "")
            imports.append(target)
            imports.extend(f"{target}.{alias.name}" if node.module else f"{target}{alias.name}" for alias in node.names)
        elif isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            first = node.body[0] if node.body else None
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
                docstrings.append((first.lineno, first.end_lineno))
    lines = text.splitlines()
    for start, end in docstrings:
        lines[start - 1:end] = [""] * (end - start + 1)
    kept = "\n".join(line for line in lines if line.strip() and not line.lstrip().startswith("#"))
    return tuple(imports), kept


def imported_names(path: Path, module: str | None) -> list[str]:
    """Every module name an import statement of `path` (module `module`, or None for a script) may load."""
    package = module if path.name == "__init__.py" else (module or "").rpartition(".")[0]
    names = []
    for name in _read(path)[0]:
        level = len(name) - len(name.lstrip("."))
        if level:
            anchor = package.split(".")[: len(package.split(".")) - level + 1]
            name = ".".join(anchor + ([name[level:]] if name[level:] else []))
        names.append(name)
    return names


@lru_cache(maxsize=None)
def _registered(root: Path, name: str) -> tuple[str, ...]:
    folder = REGISTRIES.get(name)
    if folder is None:
        return []
    prefix = ".".join(folder.relative_to("src").parts)
    return tuple(f"{prefix}.{p.stem}" for p in sorted((root / folder).glob("*.py")) if p.stem != "__init__")


@lru_cache(maxsize=None)
def _edges(root: Path, source: Path, name: str | None, mtime_ns: int, size: int) -> tuple[tuple[str, Path], ...]:
    """The package modules `source` (module `name`) loads directly, as (name, file): each module's edges are found
    once, however many scripts reach it (read again when the file's size or modification time changed)."""
    out: dict[str, Path] = {}
    for imported in imported_names(source, name):
        parts = imported.split(".")
        for depth in range(1, len(parts) + 1):
            prefix = ".".join(parts[:depth])
            for loaded in (prefix, *_registered(root, prefix)):
                if loaded not in out:
                    found = _module_file(root, loaded)
                    if found is not None:
                        out[loaded] = found
    return tuple(out.items())


def loaded_modules(root: Path, script: Path) -> set[str]:
    """The package modules running `script` (a file outside the package) can load, by name."""
    seen: set[str] = set()
    todo: list[tuple[Path, str | None]] = [(script, None)]
    while todo:
        source, name = todo.pop()
        stat = source.stat()
        for loaded, found in _edges(root, source, name, stat.st_mtime_ns, stat.st_size):
            if loaded not in seen:
                seen.add(loaded)
                todo.append((found, loaded))
    return seen


def script_files(root: str | Path, script: str | Path) -> list[str]:
    """The package files the workflow script `script` (relative to the checkout `root`) can run, relative to
    `root`, sorted."""
    root = Path(root).resolve()
    return sorted(_module_file(root, name).relative_to(root).as_posix() for name in loaded_modules(root, root / script))


def code_digest(root: str | Path, script: str | Path) -> str:
    """One digest of the code the workflow script `script` (relative to the checkout `root`) can run: its package
    modules' texts without docstrings and comment lines, by file. The script itself is not in it: Snakemake reruns a rule
    whose script changed on its own."""
    root = Path(root).resolve()
    files = script_files(root, script)
    lines = "".join(f"{name} {hashlib.sha256(_read(root / name)[1].encode()).hexdigest()}\n" for name in files)
    return hashlib.sha256(lines.encode("utf-8")).hexdigest()[:16]
