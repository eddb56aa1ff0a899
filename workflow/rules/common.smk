import json
import os
from pathlib import Path

import yaml

# Shared names. FIGURES maps each figure or table target to the files it writes: the one list of them. These are
# the files checksummed in figures/SHA256SUMS, the targets of rule `all` and the figures the paper shows.
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
    "diag_outclass": ["figures/diag_outclass.svg", "figures/diag_outclass.csv"],
    "diag_variations": ["figures/diag_variations.svg", "figures/diag_variations.csv"],
    "diag_signature": ["figures/diag_signature.svg", "figures/diag_signature.csv"],
    "diag_peers": ["figures/diag_peers.svg", "figures/diag_peers.csv"],
    "bands": ["figures/bands.svg", "figures/bands.csv"],
    "rivals": ["figures/rivals.svg", "figures/rivals.csv"],
    "assist_study": ["figures/assist_study.svg", "figures/assist_study.csv"],
    "diag_assisted": ["figures/diag_assisted.svg", "figures/diag_assisted.csv"],
}


def all_figure_files():
    return [f for files in FIGURES.values() for f in files]


def all_number_files():
    """The key numbers of each figure or table (results/<target>.json), which the paper quotes."""
    return [f"results/{name}.json" for name in FIGURES]


def paper_sources():
    return sorted(str(p) for p in Path("paper").glob("*.typ"))


# --- exact rebuilds: each rule's inputs include the package files its script can run ------------------------
# Read from the declaration workflow/code_inputs.yaml, which `parksteer plan` writes from the sources
# (parksteer.code_inputs) and tests/workflow/test_code_inputs.py keeps current. A changed module then reruns
# exactly the rules that can run it.
CHECKOUT = Path(workflow.current_basedir).parent.parent  # this file is workflow/rules/common.smk
PACKAGE_DIR = CHECKOUT / "src" / "parksteer"
CODE_INPUTS_FILE = CHECKOUT / "workflow" / "code_inputs.yaml"
CODE_INPUTS = yaml.load(CODE_INPUTS_FILE.read_text(encoding="utf-8"), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
_CHECKOUT_HERE = os.path.relpath(CHECKOUT)  # "." unless Snakemake runs in another directory (--directory)


def file_sources(path):
    """The package files the workflow file `path` (a rule script or notebook, relative to the checkout) can run,
    relative to the working directory."""
    if path not in CODE_INPUTS:
        sys.exit(f"parksteer: error: {CODE_INPUTS_FILE} has no entry for {path}: run `parksteer plan`")
    return [os.path.normpath(os.path.join(_CHECKOUT_HERE, name)) for name in CODE_INPUTS[path]]


def script_sources(script):
    """The package files the rule script workflow/scripts/<script>.py can run."""
    return file_sources(f"workflow/scripts/{script}.py")


# --- the plan: what the rules take from the package (parksteer.plan), kept between runs ---------------------
# Effect sets, case names and cache keys come from code that imports sympy and scipy (about 0.8 s). They are kept
# in .snakemake/ under a fingerprint of the package, configuration, data and examples (each file's size and
# modification time), the Python and sympy in use and this file; a value is recomputed when any of these, or a
# file its call names (`files`), changed. A missing or unreadable cache is rebuilt. The Snakefile saves what a
# run computed (save_plan) once every rule file is read.
PLAN_CACHE = Path(".snakemake") / "parksteer-plan.json"


def _read_plan_cache():
    from parksteer.plan import fingerprint

    here = os.stat(Path(workflow.current_basedir) / "common.smk")  # this file writes and reads the cache
    current = json.loads(json.dumps([fingerprint(CHECKOUT), [here.st_size, here.st_mtime_ns]]))
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
    from parksteer.errors import UsageError

    try:  # a configuration naming what is not defined (a rival that is not one): one line, before any job
        value = json.loads(json.dumps(getattr(parksteer.plan, function)(*args)))
    except UsageError as error:
        print(f"parksteer: error: {error}", file=sys.stderr)
        sys.exit(2)
    _PLANNED[key] = value
    return value


def save_plan():
    """Keep the values this run computed for the next run, written atomically (key order kept: a planned value
    read back must equal the value computed, since Snakemake compares rule parameters with the previous run's,
    key order included). A read-only folder is fine: the next run computes them again."""
    if not _PLANNED:
        return
    from parksteer.tables import atomic_path

    try:
        with atomic_path(PLAN_CACHE) as scratch:
            values = {**_PLAN_KNOWN, **_PLANNED}
            scratch.write_text(json.dumps({"fingerprint": _PLAN_FINGERPRINT, "values": values}), encoding="utf-8")
    except OSError:
        pass


def case_batches(prefix, names, per_job):
    """The cases `names` in jobs of at most `per_job` each, dealt in turn (so that a job mixes costly and cheap
    cases): {job id: its case names}. A job pays a process start and the package's imports once for its cases."""
    names = list(names)
    count = -(-len(names) // max(1, int(per_job)))
    return {f"{prefix}{k:02d}": names[k::count] for k in range(count)}


def case_outputs(folder, names, batches, suffix):
    """The `suffix` file (truth or diagnosis) of each case of `names`, in its job's folder (where run_batch puts
    it: parksteer.experiments.benchmark.case_files), in the order of `names`."""
    job_of = {name: batch for batch, members in batches.items() for name in members}
    return [planned("case_file", f"{folder}/{job_of[name]}", name, suffix) for name in names]


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
    resolved = planned("model_set", spec, files=effect_files(spec))
    name = _MODEL_NAMES.setdefault(tuple(resolved["effects"]), name)
    MODEL_SETS.setdefault(name, spec)
    return f"results/model/{name}.json"


def model_set(name):
    """The effects spec registered as `name`. Rule derive looks it up when it plans a job, once every rule file
    has registered its sets: the rule files can be included in any order."""
    if name not in MODEL_SETS:
        raise ValueError(f"results/model/{name}.json: no effect set named {name!r} (the sets: {', '.join(MODEL_SETS)})")
    return MODEL_SETS[name]


def effect_files(spec):
    """The effect modules outside the package that an effects spec names (``+path/to/effect.py``)."""
    items = spec if isinstance(spec, (list, tuple)) else (spec or "").split(",")
    return [item.strip().lstrip("+") for item in items if item.strip().endswith(".py")]


def figure_runs(wildcards):
    """The (case, variant) runs of the model figure `wildcards.figure` (config["model_figures"])."""
    return FIGURE_DESIGN.figures[wildcards.figure]
