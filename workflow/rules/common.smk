import ast
import json
import os
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
    "diag_peers": ["figures/diag_peers.svg", "figures/diag_peers.csv"],
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


# The import lists of parsed files are kept between runs in .snakemake/, each under its file's path, size and
# modification time, so a run parses only the files that changed (parsing all of them was most of the Snakefile's
# own time in a run with nothing to do). A missing or unreadable cache is rebuilt.
IMPORT_CACHE = Path(".snakemake") / "parksteer-imports.json"


def _read_import_cache():
    try:
        cached = json.loads(IMPORT_CACHE.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return cached if isinstance(cached, dict) else {}


_IMPORTS_KNOWN = _read_import_cache()
_IMPORTS_PARSED = {}


def _write_cache(path, data):
    """Write `data` as JSON into `path` atomically; a read-only directory is fine (the next run recomputes). Keys
    keep their order: a planned value read back must equal the value computed (rule parameters are compared
    with the previous run's, key order included)."""
    from parksteer.tables import atomic_path

    try:
        with atomic_path(path) as scratch:
            scratch.write_text(json.dumps(data), encoding="utf-8")
    except OSError:
        pass


def save_caches():
    """Keep what this run parsed (IMPORT_CACHE) and planned (PLAN_CACHE) for the next run."""
    if _IMPORTS_PARSED:
        _write_cache(IMPORT_CACHE, {**_IMPORTS_KNOWN, **_IMPORTS_PARSED})
    if _PLANNED:
        _write_cache(PLAN_CACHE, {"fingerprint": _PLAN_FINGERPRINT, "values": {**_PLAN_KNOWN, **_PLANNED}})


@lru_cache(maxsize=None)
def _imported_names(path, module):
    """Every module name an import statement of `path` (module `module`, or None for a script) may load; each
    file is parsed once per Snakemake run, however many rule scripts import it, and again only when it changes."""
    stat = path.stat()
    key, stamp = f"{path}|{module}", [stat.st_mtime_ns, stat.st_size]
    known = _IMPORTS_KNOWN.get(key)
    if isinstance(known, list) and len(known) == 2 and known[0] == stamp:
        return tuple(known[1])
    names = _parse_imports(path, module)
    _IMPORTS_PARSED[key] = [stamp, list(names)]
    return names


def _parse_imports(path, module):
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


# --- the plan: what the rules take from the package (parksteer.plan), kept between runs ---------------------
# Effect sets, case names and cache keys come from code that imports sympy and scipy (about 0.8 s). They are kept
# in .snakemake/ under a fingerprint of the package, configuration, data and examples (each file's size and
# modification time), the Python and sympy in use and this file; a value is recomputed when any of these, or a
# file its call names (`files`), changed. A missing or unreadable cache is rebuilt.
PLAN_CACHE = Path(".snakemake") / "parksteer-plan.json"


def _read_plan_cache():
    from parksteer.plan import fingerprint

    here = os.stat(Path(workflow.current_basedir) / "common.smk")  # this file writes and reads the cache
    current = json.loads(json.dumps([fingerprint(WORKFLOW_DIR.parent), [here.st_size, here.st_mtime_ns]]))
    try:
        cached = json.loads(PLAN_CACHE.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return current, {}
    if not isinstance(cached, dict) or cached.get("fingerprint") != current or not isinstance(cached.get("values"), dict):
        return current, {}
    return current, cached["values"]


_PLAN_FINGERPRINT, _PLAN_KNOWN = _read_plan_cache()
_PLANNED = {}


def planned(function, *args, files=()):
    """parksteer.plan.<function>(*args), from the plan cache when nothing it depends on changed."""
    stamps = []
    for name in files:
        try:
            stat = os.stat(name)
            stamps.append([str(name), stat.st_size, stat.st_mtime_ns])
        except OSError:
            stamps.append([str(name), None])
    key = json.dumps([function, args, stamps], sort_keys=True)
    if key in _PLANNED:
        return _PLANNED[key]
    if key in _PLAN_KNOWN:
        return _PLAN_KNOWN[key]
    import parksteer.plan

    value = json.loads(json.dumps(getattr(parksteer.plan, function)(*args)))
    _PLANNED[key] = value
    return value


def case_batches(prefix, names, per_job):
    """The cases `names` in jobs of at most `per_job` each, dealt in turn (so that a job mixes costly and cheap
    cases): {job id: its case names}. A job pays a process start and the package's imports once for its cases."""
    names = list(names)
    count = -(-len(names) // max(1, int(per_job)))
    return {f"{prefix}{k:02d}": names[k::count] for k in range(count)}


def case_outputs(folder, names, batches, suffix):
    """The `suffix` file (truth or diagnosis) of each case of `names`, in its job's folder (where run_batch puts
    it: parksteer.diagnose.benchmark.case_files), in the order of `names`."""
    job_of = {name: batch for batch, members in batches.items() for name in members}
    return [planned("case_file", f"{folder}/{job_of[name]}", name, suffix) for name in names]


def benchmark_file(rule, *wildcards):
    """The rule's benchmark file under results/benchmarks/<rule>/ (one per wildcard combination)."""
    stem = "__".join(f"{{{w}}}" for w in wildcards) or rule
    return f"results/benchmarks/{rule}/{stem}.tsv"


# --- compiled models: every named effect set the pipeline needs, derived once by rule derive ----------------
MODEL_SETS = {}  # name -> effects spec
MODEL_KEYS = {}  # name -> the model cache key its effect set has now
_MODEL_NAMES = {}  # the resolved effect names -> the name first registered for them


def model_manifest(name, spec):
    """Register the effect set `spec` as `name` (or under the name of an identical set registered before) and
    return the path of its manifest, results/model/<name>.json, which rule derive writes."""
    resolved = planned("model_set", spec, files=effect_files(spec))
    name = _MODEL_NAMES.setdefault(tuple(resolved["effects"]), name)
    MODEL_SETS.setdefault(name, spec)
    MODEL_KEYS.setdefault(name, resolved["key"])
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
# run. So before the DAG is built (the Snakefile calls check_outputs in the main process, never in a job), the
# content of what earlier runs wrote is checked, and what no job can have written is removed (damaged CSV, SVG,
# JSON and PDF outputs, model manifests whose cache entry is missing or unsound, temporary files and scratch
# directories of killed writers, and the lock of a killed run; parksteer.outputs says exactly what and how).
# Snakemake then treats a removed file as any missing one: a missing target is built, a missing intermediate as
# soon as a job that reads it runs (one whose readers are intact and up to date is needed by nothing and stays
# missing, as a temp() file would). Outputs a killed job left marked incomplete are rerun by `rerun-incomplete`
# in workflow/profiles/default. `--config check_outputs=False` skips the checks (for tests that stand empty
# placeholders in for outputs).
def check_outputs():
    """Remove damaged outputs, untrusted model manifests, leftovers of killed writers and a dead run's lock
    (parksteer.outputs.check_outputs), saying in one line each what was removed and why."""
    from parksteer.outputs import check_outputs as check

    for line in check(MODEL_KEYS):
        print(f"parksteer: {line}", file=sys.stderr)
