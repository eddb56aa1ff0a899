import ast
import os
import shutil
from functools import lru_cache
from pathlib import Path

# Shared names. FIGURES maps each figure or table target to the files it writes;
# these are the files checksummed in figures/SHA256SUMS.
PARAMETERS = config["parameters"]

FIGURES = {
    "table1": ["figures/table1.csv"],
    "fig3": ["figures/fig3.svg", "figures/fig3.csv"],
    "fig4": ["figures/fig4.svg", "figures/fig4.csv"],
    "figA3": ["figures/figA3.svg", "figures/figA3.csv"],
    "fig12": ["figures/fig12.svg", "figures/fig12.csv"],
    "fig13": ["figures/fig13.svg", "figures/fig13.csv"],
    "fig14": ["figures/fig14.svg", "figures/fig14.csv"],
    "fig15": ["figures/fig15.svg", "figures/fig15.csv"],
    "fig16": ["figures/fig16.svg", "figures/fig16.csv"],
    "figContrib": ["figures/figContrib.svg", "figures/figContrib.csv"],
    "sweep_design": ["figures/sweep_design.svg", "figures/sweep_design.csv"],
    "diag_compare": ["figures/diag_compare.svg", "figures/diag_compare.csv"],
    "diag_ladder": ["figures/diag_ladder.svg", "figures/diag_ladder.csv"],
    "diag_benchmark": ["figures/diag_benchmark.svg", "figures/diag_benchmark.csv"],
}


def all_figure_files():
    return [f for files in FIGURES.values() for f in files]


def all_number_files():
    """The key numbers of each figure or table (results/<target>.json), which the paper quotes."""
    return [f"results/{name}.json" for name in FIGURES]


def paper_sources():
    return sorted(str(p) for p in Path("paper").glob("*.typ"))


# --- exact rebuilds: each rule's inputs include the package modules its script runs -------------------------
# The modules a script imports, found statically (every `import` and `from ... import`, also inside functions),
# then the modules those import, and so on; importing parksteer.a.b also runs parksteer/__init__.py and
# parksteer/a/__init__.py. A changed module then reruns exactly the rules that can run it.
WORKFLOW_DIR = Path(workflow.current_basedir).parent  # this file is workflow/rules/common.smk
SCRIPTS_DIR = WORKFLOW_DIR / "scripts"
PACKAGE_DIR = WORKFLOW_DIR.parent / "src" / "parksteer"
# Imports no `import` statement shows: the effect registry loads every module of model/symbolic/effects.
DYNAMIC_IMPORTS = {
    "parksteer.model.symbolic.components": tuple(
        f"parksteer.model.symbolic.effects.{p.stem}"
        for p in sorted((PACKAGE_DIR / "model" / "symbolic" / "effects").glob("*.py"))
        if p.stem != "__init__"
    ),
}


@lru_cache(maxsize=None)
def _module_file(name):
    """The source file of module `name` in this checkout's package, or None (not parksteer's, or not a module)."""
    parts = name.split(".")
    if parts[0] != "parksteer":
        return None
    base = PACKAGE_DIR.joinpath(*parts[1:])
    for candidate in (base / "__init__.py", base.with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


@lru_cache(maxsize=None)
def _imported_names(path, module):
    """Every module name an import statement of `path` (module `module`, or None for a script) may load; each
    file is parsed once per Snakemake run, however many rule scripts import it."""
    package = module if path.name == "__init__.py" else (module or "").rpartition(".")[0]
    names = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(anchor + ([node.module] if node.module else []))
            else:
                target = node.module
            names.append(target)
            names.extend(f"{target}.{alias.name}" for alias in node.names)  # `from pkg import submodule`
    return tuple(names)


@lru_cache(maxsize=None)
def _closure(path, module):
    """The modules loaded by running `path` (as module `module`, None for a script), by name."""
    seen, todo = set(), [(Path(path), module)]
    while todo:
        source, name = todo.pop()
        for imported in _imported_names(source, name):
            parts = imported.split(".")
            for depth in range(1, len(parts) + 1):
                prefix = ".".join(parts[:depth])
                for loaded in (prefix, *DYNAMIC_IMPORTS.get(prefix, ())):
                    found = _module_file(loaded)
                    if found is not None and loaded not in seen:
                        seen.add(loaded)
                        todo.append((found, loaded))
    return frozenset(seen)


def file_sources(path):
    """The package files a Python file outside the package (a notebook in percent format) loads."""
    return sorted(os.path.relpath(_module_file(n)) for n in _closure(Path(path).resolve(), None))


def script_sources(script):
    """The package files a rule script (workflow/scripts/<script>.py) loads, relative to the working directory."""
    return file_sources(SCRIPTS_DIR / f"{script}.py")


def benchmark_file(rule, *wildcards):
    """The rule's benchmark file under results/benchmarks/<rule>/ (one per wildcard combination)."""
    stem = "__".join(f"{{{w}}}" for w in wildcards) or rule
    return f"results/benchmarks/{rule}/{stem}.tsv"


# --- compiled models: every named effect set the pipeline needs, derived once by rule derive ----------------
MODEL_SETS = {}  # name -> effects spec
_MODEL_NAMES = {}  # the resolved effect names -> the name first registered for them


def model_manifest(name, spec):
    """Register the effect set `spec` as `name` (or under the name of an identical set registered before) and
    return the path of its manifest, results/model/<name>.json, which rule derive writes."""
    from parksteer.model.symbolic.components import resolve_effects

    effects = tuple(e.name for e in resolve_effects(spec))
    name = _MODEL_NAMES.setdefault(effects, name)
    MODEL_SETS.setdefault(name, spec)
    return f"results/model/{name}.json"


def effect_files(spec):
    """The effect modules outside the package that an effects spec names (``+path/to/effect.py``)."""
    items = spec if isinstance(spec, (list, tuple)) else (spec or "").split(",")
    return [item.strip().lstrip("+") for item in items if item.strip().endswith(".py")]


def figure_runs(wildcards):
    """The (case, variant) runs of the model figure `wildcards.figure` (config["model_figures"])."""
    return FIGURE_DESIGN.figures[wildcards.figure]


# --- damage and interruptions: what the next ordinary run repairs -----------------------------------------------
# Snakemake compares timestamps only: a truncated intermediate newer than its inputs would be trusted on every
# run. So before the DAG is built (in the main process, not in the jobs), check_outputs looks at the content of
# what earlier runs wrote and removes what cannot be what a rule wrote. Snakemake then treats it as any missing
# file: a missing target is built, and a missing intermediate is rebuilt as soon as a job that reads it runs (one
# whose consumers are intact and up to date is needed by nothing, and is left missing, as Snakemake leaves a
# temp() file). Removed are:
#   - a CSV, SVG, JSON or PDF a rule wrote (results/, figures/, paper/) that is empty, truncated or unparsable;
#   - a model manifest results/model/<set>.json whose cache key is not the one the set has now, or whose cache
#     entry is missing or fails its SHA-256 check (a manifest is trusted only if what it points at is sound);
#   - temporary files of writers that were killed (parksteer.tables.atomic_path), and scratch directories of
#     killed model builds;
#   - the lock of a Snakemake run that was killed (no Snakemake process runs in this folder any more).
# Outputs a killed job left marked incomplete are rerun by `rerun-incomplete` in workflow/profiles/default.
# `--config check_outputs=false` skips the checks (tests that stand empty placeholder files in for outputs).
CHECKED_ROOTS = ("results", "figures", "paper")
CHECKED_SUFFIXES = (".csv", ".svg", ".json", ".ipynb", ".pdf")


def _content_problem(path):
    """Why the output `path` cannot be what a rule wrote, or None."""
    import json

    from parksteer.checksums import integrity_problem

    if path.suffix in (".csv", ".svg"):
        return integrity_problem(path)
    if path.stat().st_size == 0:
        return "empty"
    if path.suffix == ".pdf":
        with path.open("rb") as f:
            head = f.read(5)
            f.seek(max(0, path.stat().st_size - 1024))
            tail = f.read()
        return None if head == b"%PDF-" and b"%%EOF" in tail else "not a complete PDF (truncated)"
    try:
        json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        return f"not readable JSON ({exc})"
    return None


def _manifest_problem(path, spec):
    """Why the model manifest `path` of effect set `spec` cannot be trusted, or None."""
    import json

    from parksteer.model.codegen.cache import cache_root, entry_is_sound, model_key
    from parksteer.model.symbolic.components import resolve_effects

    try:
        key = json.loads(path.read_text(encoding="utf-8"))["key"]
    except (ValueError, UnicodeDecodeError, KeyError, TypeError) as exc:
        return f"not a model manifest ({type(exc).__name__}: {exc})"
    expected = model_key(resolve_effects(spec))
    if key != expected:
        return f"names cache entry {key}, but the model's sources now key it {expected}"
    if not entry_is_sound(cache_root() / key):
        return f"its cache entry {cache_root() / key} is missing or fails its SHA-256 check"
    return None


def _other_snakemake_here():
    """True if a Snakemake process other than this one (and its parents) runs in this folder, or if that cannot be
    told (no /proc)."""
    proc = Path("/proc")
    if not (proc / "self" / "cwd").exists():
        return True
    mine, pid = set(), os.getpid()
    while pid > 1 and pid not in mine:  # this process and its ancestors
        mine.add(pid)
        try:
            pid = int((proc / str(pid) / "stat").read_text().rpartition(")")[2].split()[1])
        except (OSError, ValueError, IndexError):
            break
    here = os.path.realpath(os.getcwd())
    for entry in proc.iterdir():
        if not entry.name.isdigit() or int(entry.name) in mine:
            continue
        try:
            argv = (entry / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        names = [os.path.basename(a.decode(errors="replace")) for a in argv[:3]]
        if "snakemake" not in names:
            continue
        try:
            if os.path.realpath(entry / "cwd") != here:
                continue
        except OSError:
            return True  # a Snakemake whose folder cannot be read: perhaps this one
        return True
    return False


def check_outputs():
    """Remove damaged outputs, untrusted model manifests, leftovers of killed writers and a dead run's lock (see
    above); say in one line each what was removed and why."""
    from parksteer.model.codegen.cache import cache_root, clean_stale_scratch
    from parksteer.tables import remove_stale_temporaries

    def removed(path, why):
        print(f"parksteer: removed {path}: {why}; it is rebuilt", file=sys.stderr)

    locks = Path(".snakemake") / "locks"
    if locks.is_dir() and any(locks.iterdir()) and not _other_snakemake_here():
        shutil.rmtree(locks, ignore_errors=True)
        print("parksteer: removed the lock of a Snakemake run that is no longer running", file=sys.stderr)
    for path in remove_stale_temporaries(*CHECKED_ROOTS):
        removed(path, "a temporary file of a killed writer")
    for path in clean_stale_scratch(cache_root()):
        removed(path, "a scratch directory of a killed model build")
    model_dir = Path("results") / "model"
    manifests = {model_dir / f"{name}.json": spec for name, spec in MODEL_SETS.items()}
    for path in _written_files():
        why = _content_problem(path)
        if why is None and path in manifests:
            why = _manifest_problem(path, manifests[path])
        if why is not None:
            path.unlink(missing_ok=True)
            removed(path, why)


def _written_files():
    """The files rules write that check_outputs reads: results/ (but the model cache's entries, checked through
    their manifests, and Snakemake's benchmark records), figures/*.{svg,csv} (not figures/reference, which is
    source) and paper/*.pdf."""
    for folder, subfolders, names in os.walk("results"):
        if Path(folder) == Path("results"):
            subfolders[:] = [d for d in subfolders if d != "benchmarks"]
        if Path(folder) == Path("results") / "model":
            subfolders.clear()
        for name in sorted(names):
            path = Path(folder) / name
            if path.suffix in CHECKED_SUFFIXES and not name.startswith("."):
                yield path
    yield from sorted(p for p in Path("figures").glob("*") if p.suffix in (".svg", ".csv") and p.is_file())
    yield from sorted(p for p in Path("paper").glob("*.pdf") if p.is_file())
