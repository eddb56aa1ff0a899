import json
import os
from pathlib import Path

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
    "assist_creep": ["figures/assist_creep.svg", "figures/assist_creep.csv"],
    "diag_assisted": ["figures/diag_assisted.svg", "figures/diag_assisted.csv"],
    "diag_assisted_truth": ["figures/diag_assisted_truth.svg", "figures/diag_assisted_truth.csv"],
    "diag_baseline": ["figures/diag_baseline.svg", "figures/diag_baseline.csv"],
}


def all_figure_files():
    return [f for files in FIGURES.values() for f in files]


def all_number_files():
    """The key numbers of each figure or table (results/<target>.json), which the paper quotes."""
    return [f"results/{name}.json" for name in FIGURES]


def paper_sources():
    return sorted(str(p) for p in Path("paper").glob("*.typ"))


# --- exact rebuilds: each rule passes the digest of the package code its script runs as the parameter `code` ----
# (parksteer.code_inputs.code_digest: the modules the script imports, statically, without their docstrings).
# Snakemake reruns a job whose parameters changed, so an edit of a module reruns exactly the rules that can run
# it, and an edited docstring, comment or test reruns nothing.
CHECKOUT = Path(workflow.current_basedir).parent.parent  # this file is workflow/rules/common.smk
PACKAGE_DIR = CHECKOUT / "src" / "parksteer"


def code(script):
    """The digest of the package code the rule script workflow/scripts/<script>.py runs (or the notebook whose
    path is `script`), as an input function: taken for the jobs a run plans, not for every rule at parse time."""
    from parksteer.code_inputs import code_digest

    path = script if script.endswith(".py") else f"workflow/scripts/{script}.py"
    return lambda wildcards: code_digest(CHECKOUT, path)


def plan(function, *args):
    """parksteer.plan.<function>(*args) as plain JSON data: what the rules take from the package (effect sets, case
    names). A configuration naming what is not defined (a rival that is not one) stops here with one line, before
    any job."""
    import parksteer.plan
    from parksteer.errors import UsageError

    try:
        return json.loads(json.dumps(getattr(parksteer.plan, function)(*args)))
    except UsageError as error:
        print(f"parksteer: error: {error}", file=sys.stderr)
        sys.exit(2)


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
    return [plan("case_file", f"{folder}/{job_of[name]}", name, suffix) for name in names]


def benchmark_file(rule, *wildcards):
    """The rule's benchmark file under results/benchmarks/<rule>/ (one per wildcard combination)."""
    stem = "__".join(f"{{{w}}}" for w in wildcards) or rule
    return f"results/benchmarks/{rule}/{stem}.tsv"


# --- the order of jobs on few cores: Snakemake's `priority:` (0 unless listed) ----------------------------------
# A cold build on 2 cores is bound by its work, so what costs wall time is a core left idle at the end while one
# long job runs alone. The compiled models go first (every benchmark job waits on them, and each derive job takes a
# few seconds), then the jobs that take longest, longest first (list scheduling, longest job first), so that the
# short figure and summary jobs fill the cores at the end. diag_car_data is short but the case study waits on it.
# The order follows each rule's longest job in results/benchmarks/<rule>/ of a cold build.
PRIORITY = {
    "derive": 100,
    "diag_car_data": 90,
    "diag_assisted_batch": 60,
    "diag_signature_batch": 55,
    "diag_peers_batch": 50,
    "diag_variation_batch": 50,
    "diag_baseline_batch": 45,
    "diag_assisted_truth_batch": 45,
    "case_study": 40,
    "diag_bench_batch": 35,
    "diag_outclass_batch": 30,
    "bands": 20,
    "assist_creep": 20,
}


# --- compiled models: every named effect set the pipeline needs, derived once by rule derive ----------------
MODEL_SETS = {}  # name -> effects spec
_MODEL_NAMES = {}  # the resolved effect names -> the name first registered for them


def model_manifest(name, spec):
    """Register the effect set `spec` as `name` (or under the name of an identical set registered before) and
    return the path of its manifest, results/model/<name>.json, which rule derive writes."""
    resolved = plan("model_set", spec)
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
