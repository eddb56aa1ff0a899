"""Every third-party module the code imports is pinned in the lock file of the command that runs it.

The README's quick start 1 installs `requirements/pipeline.lock` and runs the whole pipeline; quick start 2
installs `requirements/test.lock` and runs the tests. A module imported by `src/` or by a rule (its script, its
notebook or the workflow files themselves), at the top of a file or lazily inside a function, must resolve to a
distribution pinned in `pipeline.lock`, or else be an optional extra: a distribution that `pyproject.toml` names
only under `[project.optional-dependencies]`, imported only where a missing install turns into a one-line
`UsageError` that names the extra. A module imported by `tests/` must resolve to a distribution pinned in
`test.lock`. And each lock holds every dependency of what it pins, so `pip install -r` resolves nothing itself.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import pytest

from packaging.requirements import Requirement

import syntax_trees

REPO_ROOT = Path(__file__).resolve().parents[1]
PIPELINE_LOCK = REPO_ROOT / "requirements" / "pipeline.lock"
TEST_LOCK = REPO_ROOT / "requirements" / "test.lock"


def normalised(name: str) -> str:
    """A distribution name as PEP 503 compares them."""
    return re.sub(r"[-_.]+", "-", name).lower()


def lock_pins(path: Path) -> dict[str, str]:
    """Distribution -> pinned version of a lock file, following its `-r` includes."""
    pins = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        if line.startswith("-r "):
            pins.update(lock_pins(path.parent / line[3:].strip()))
            continue
        name, _, version = line.partition("==")
        pins[normalised(name)] = version.strip()
    return pins


def imports_in(source: str, where: str) -> dict[str, list[tuple[str, int, bool]]]:
    """Top-level module name -> [(file, line, guarded)] for every absolute import in `source`, in functions too.
    `guarded` is true where the import sits in a `try` whose handlers catch ImportError."""
    guarded_lines: set[int] = set()
    for node in syntax_trees.nodes(source):
        if isinstance(node, ast.Try) and any(
            handler.type is not None and "ImportError" in ast.unparse(handler.type) for handler in node.handlers
        ):
            for inner in node.body:
                guarded_lines.update(range(inner.lineno, (inner.end_lineno or inner.lineno) + 1))
    found: dict[str, list[tuple[str, int, bool]]] = {}
    for node in syntax_trees.nodes(source):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        else:
            continue
        for name in names:
            found.setdefault(name.split(".")[0], []).append((where, node.lineno, node.lineno in guarded_lines))
    return found


def python_of_workflow_file(path: Path) -> str:
    """The imports of a Snakefile or rule file as Python source (Snakemake's grammar is Python's plus rule blocks;
    the imports are plain Python lines, at any indentation), one `import module` line per file line, so that
    line numbers stay the file's."""
    out = []
    for line in path.read_text(encoding="utf-8").splitlines():
        match = re.match(r"\s*(?:import\s+([\w.]+)|from\s+(\w[\w.]*)\s+import\s)", line)
        out.append(f"import {match.group(1) or match.group(2)}" if match else "")
    return "\n".join(out)


def third_party_imports(roots: list[Path]) -> dict[str, list[tuple[str, int, bool]]]:
    """Top-level module -> its import sites, for every third-party module the files under `roots` import."""
    found: dict[str, list[tuple[str, int, bool]]] = {}
    # the files' own modules and packages (a test helper, a benchmark script), which no distribution installs
    local = {"parksteer"} | {part for root in roots if root.is_dir() for path in root.rglob("*.py")
                             for part in path.relative_to(root).with_suffix("").parts}
    for root in roots:
        files = [root] if root.is_file() else sorted(root.rglob("*"))
        for path in files:
            if path.suffix == ".py":
                source = path.read_text(encoding="utf-8")
            elif path.suffix == ".smk" or path.name == "Snakefile":
                source = python_of_workflow_file(path)
            else:
                continue
            for module, sites in imports_in(source, str(path.relative_to(REPO_ROOT))).items():
                if module in sys.stdlib_module_names or module in local or module == "__future__":
                    continue
                found.setdefault(module, []).extend(sites)
    return found


DISTRIBUTIONS = metadata.packages_distributions()


def distributions_of(module: str) -> list[str]:
    return [normalised(d) for d in DISTRIBUTIONS.get(module, [])]


def project() -> dict:
    return tomllib.loads((REPO_ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]


def optional_extras() -> dict[str, str]:
    """Distribution -> the extra that installs it, for distributions that only an extra (not `test`) names."""
    core = {normalised(Requirement(r).name) for r in project()["dependencies"]}
    extras = {}
    for extra, requirements in project()["optional-dependencies"].items():
        if extra == "test":
            continue
        for requirement in requirements:
            name = normalised(Requirement(requirement).name)
            if name not in core:
                extras.setdefault(name, extra)
    return extras


PIPELINE_ROOTS = [REPO_ROOT / "src", REPO_ROOT / "workflow"]


def test_every_module_the_pipeline_imports_is_pinned_for_quick_start_1():
    """A module that a rule can import and that quick start 1 does not install stops the pipeline half-way on a
    fresh machine (the peers' benchmark once did, with ModuleNotFoundError). Pinned, or an optional extra
    imported only behind a one-line error."""
    pins = lock_pins(PIPELINE_LOCK)
    extras = optional_extras()
    unpinned = []
    for module, sites in sorted(third_party_imports(PIPELINE_ROOTS).items()):
        dists = distributions_of(module)
        if not dists:
            unpinned.append(f"{module} (imported at {sites[0][0]}:{sites[0][1]}) is installed by no distribution")
            continue
        if any(d in pins for d in dists):
            continue
        optional = [d for d in dists if d in extras]
        if not optional:
            unpinned.append(f"{module} ({', '.join(dists)}, imported at {sites[0][0]}:{sites[0][1]}) is neither "
                            f"pinned in {PIPELINE_LOCK.name} nor an optional extra")
            continue
        bare = [f"{file}:{line}" for file, line, guarded in sites if not guarded]
        if bare:
            unpinned.append(f"{module} is the optional extra [{extras[optional[0]]}] but imported unguarded at "
                            f"{', '.join(bare)}")
    assert not unpinned, "\n".join(unpinned)


def test_every_module_the_tests_import_is_pinned_for_quick_start_2():
    pins = lock_pins(TEST_LOCK)
    unpinned = []
    for module, sites in sorted(third_party_imports([REPO_ROOT / "tests", REPO_ROOT / "benchmarks"]).items()):
        dists = distributions_of(module)
        if not any(d in pins for d in dists):
            unpinned.append(f"{module} ({', '.join(dists) or 'no distribution'}, imported at "
                            f"{sites[0][0]}:{sites[0][1]}) is not pinned in {TEST_LOCK.name}")
    assert not unpinned, "\n".join(unpinned)


@pytest.mark.parametrize("lock", [PIPELINE_LOCK, TEST_LOCK], ids=lambda p: p.name)
def test_each_lock_pins_every_dependency_of_what_it_pins(lock):
    """A dependency missing from a lock is resolved by pip on the day of the install, at whatever version the
    registry then serves: the install is no longer the one the checksums were made with."""
    pins = lock_pins(lock)
    missing = []
    environment = {"extra": ""}
    for name in sorted(pins):
        try:
            requirements = metadata.requires(name) or []
        except metadata.PackageNotFoundError:
            missing.append(f"{name} is pinned but not installed here")
            continue
        for text in requirements:
            requirement = Requirement(text)
            if requirement.marker is not None and not requirement.marker.evaluate(environment):
                continue
            if normalised(requirement.name) not in pins:
                missing.append(f"{name} needs {requirement.name}, which {lock.name} does not pin")
    assert not missing, "\n".join(missing)


def test_the_core_dependencies_are_pinned_for_quick_start_1():
    pins = lock_pins(PIPELINE_LOCK)
    missing = [r for r in project()["dependencies"] if normalised(Requirement(r).name) not in pins]
    assert not missing, f"pyproject.toml's dependencies not pinned in {PIPELINE_LOCK.name}: {missing}"


MISSING_EXTRAS = [
    # (the module hidden, the extra, the sample file's name and bytes, the arguments after it)
    ("asammdf", "mdf", "run.mf4", b"MDF     4.10    " + bytes(48), []),
    ("can", "bus", "run.log", b"(1700000000.000000) can0 0A0#0000000000000000\n", ["--bus", "vw_mqb"]),
]


@pytest.mark.parametrize(("module", "extra", "name", "content", "arguments"), MISSING_EXTRAS,
                         ids=[row[1] for row in MISSING_EXTRAS])
def test_a_missing_extra_is_one_line_naming_it(tmp_path, module, extra, name, content, arguments):
    """Without the extra's module, reading a file that needs it (an MDF file; a raw CAN log) stops with exit
    status 2 and one line that names the file read (the log, or the car's DBC, which python-can's cantools needs
    too) and the extra to install."""
    sample = tmp_path / name
    sample.write_bytes(content)
    script = (
        f"import sys; sys.modules[{module!r}] = None\n"
        "from parksteer.cli import main\n"
        f"sys.exit(main(['compare', {str(sample)!r}, *{arguments!r}]))\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert (name in lines[0] or ".dbc" in lines[0]) and f"pip install 'parksteer[{extra}]'" in lines[0]
