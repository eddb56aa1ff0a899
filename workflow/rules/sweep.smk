# Design exploration: the sweep declared in config["sweep"] (default config/sweeps/design.yaml; its large
# version with config["sweep_full"]), expanded into points and the points into batches of about
# config["sweep_batch_size"] (parksteer.sweep.expansion.batch_points; doubled until a sweep makes at most about
# 4,096 batches, so that a million points make some 2,600 jobs rather than 21,000), one sweep_batch job per batch,
# so that a point costs its physics rather than a process start, and the batches run in parallel with --cores N and
# unchanged on a cluster (workflow/profiles/slurm). Each batch job reads the compiled model of its effect sets
# ("free", and "braked" when the sweep simulates braked wheels) from the cache, where rule derive puts it, and
# never derives; sweep_<name> gathers the table, the key numbers and the torque maps.
# The plan holds the batch ids only: each batch's points are in the sweep's batch index (SWEEP_INDEX_DIR, written
# once per declaration while the DAG is built; parksteer.sweep.batch_index.write_batch_index), where its job reads
# them, so that the DAG of a million points costs the scheduler a name per batch and no spec.
from parksteer.errors import UsageError
from parksteer.sweep.declaration import DEFAULT_SWEEP_FILE
from parksteer.sweep.expansion import DEFAULT_BATCH_SIZE

SWEEP_BATCH_SIZE = int(config.get("sweep_batch_size", DEFAULT_BATCH_SIZE))
SWEEP_FILE = config.get("sweep", DEFAULT_SWEEP_FILE)
# true from the configuration file, True or "true" from `--config sweep_full=...` (the schema allows those
# spellings); written back as the boolean, which the batch jobs read
SWEEP_FULL = config.get("sweep_full", False) in (True, "true")
config["sweep_full"] = SWEEP_FULL
SWEEP_INDEX_DIR = ".snakemake/parksteer-sweeps"
# A bad declaration (empty axis, unknown key or effect, a value out of its bounds, a missing file) is refused
# here, while the DAG is built, with one line naming the file and the key.
try:
    SWEEP = plan("sweep", SWEEP_FILE, PARAMETERS, SWEEP_FULL, SWEEP_BATCH_SIZE, SWEEP_INDEX_DIR)
    SWEEP_MODEL_MANIFESTS = [
        model_manifest(f"sweep_{SWEEP['name']}_{variant}", effects) for variant, effects in SWEEP["model_sets"].items()
    ]
except UsageError as error:  # SweepError is one
    print(f"parksteer: error: {error}", file=sys.stderr)
    sys.exit(2)
SWEEP_NAME = SWEEP["name"]
SWEEP_BATCH_FILES = expand("results/sweeps/{sweep}/batches/{batch}.json", sweep=SWEEP_NAME, batch=SWEEP["batches"])


# A batch's id hashes its points' ids and each point's id hashes what it simulates; what the points share (case,
# effects, surface, braked wheels) is a parameter, and the declaration an input whose time does not count
# (ancient). Editing the declaration (another axis value, a new map) runs only the batches that gained or lost a
# point, never the whole sweep again. The job reads the batch size and sweep_full from the configuration as above.
rule sweep_batch:
    input:
        parameters=PARAMETERS,
        declaration=ancient(SWEEP_FILE),
        models=SWEEP_MODEL_MANIFESTS,
    output:
        batch="results/sweeps/{sweep}/batches/{batch}.json",
    params:
        code=code("sweep_batch"),
        shared=SWEEP["shared"],
        index_dir=SWEEP_INDEX_DIR,
    wildcard_constraints:
        sweep=SWEEP_NAME,
        batch="[0-9a-f]{10}",
    log:
        "logs/sweep_batch/{sweep}/{batch}.log",
    benchmark:
        benchmark_file("sweep_batch", "sweep", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/sweep_batch.py"


# Gathering the batches and drawing the maps takes seconds: on a cluster it runs on the submitting host instead of
# waiting in the queue and for the executor's status checks (one round of each, after the batch jobs).
rule:
    name:
        f"sweep_{SWEEP_NAME}"
    localrule: True
    input:
        sweep=SWEEP_FILE,
        parameters=PARAMETERS,
        batches=SWEEP_BATCH_FILES,
    output:
        svg=figure_report(f"figures/sweep_{SWEEP_NAME}.svg", "sweep", caption="sweep"),
        csv=figure_report(f"figures/sweep_{SWEEP_NAME}.csv", "sweep", caption="sweep"),
        json=f"results/sweep_{SWEEP_NAME}.json",
    params:
        code=code("sweep_figure"),
        full=SWEEP_FULL,
    log:
        f"logs/sweep_{SWEEP_NAME}.log",
    benchmark:
        benchmark_file(f"sweep_{SWEEP_NAME}")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/sweep_figure.py"
