# Design exploration: the sweep declared in config["sweep"] (default config/sweeps/design.yaml; its large
# version with config["sweep_full"]), expanded into points and the points into batches of about
# config["sweep_batch_size"] (parksteer.sweep.declaration.batch_points), one sweep_batch job per batch, so that a
# point costs its physics rather than a process start, and the batches run in parallel with --cores N and
# unchanged on a cluster (workflow/profiles/slurm). Each batch job reads the compiled model of its effect sets
# ("free", and "braked" when the sweep simulates braked wheels) from the cache, where rule derive puts it, and
# never derives; sweep_<name> gathers the table, the key numbers and the torque maps.
from parksteer.parameters import load_parameters
from parksteer.errors import UsageError
from parksteer.sweep import load_sweep
from parksteer.sweep.declaration import DEFAULT_BATCH_SIZE

SWEEP_BATCH_SIZE = int(config.get("sweep_batch_size", DEFAULT_BATCH_SIZE))
# A bad declaration (empty axis, unknown key or effect, a value out of its bounds, a missing file) is refused
# here, while the DAG is built, with one line naming the file and the key.
try:
    SWEEP = load_sweep(
        config.get("sweep", "config/sweeps/design.yaml"),
        load_parameters(PARAMETERS),
        full=bool(config.get("sweep_full", False)),
    )
    SWEEP_BATCHES = SWEEP.batches(SWEEP_BATCH_SIZE)
    SWEEP_MODEL_MANIFESTS = [
        model_manifest(f"sweep_{SWEEP.name}_{variant}", effects) for variant, effects in SWEEP.model_sets.items()
    ]
except UsageError as error:  # SweepError is one
    print(f"parksteer: error: {error}", file=sys.stderr)
    sys.exit(2)
SWEEP_BATCH_FILES = expand(
    "results/sweeps/{sweep}/batches/{batch}.json", sweep=SWEEP.name, batch=sorted(SWEEP_BATCHES)
)


# A batch's id hashes its points' ids and each point's id hashes what it simulates; the points' values are a
# parameter, not an input file. Editing the declaration (another axis value, a new map) runs only the batches
# that gained or lost a point, never the whole sweep again.
rule sweep_batch:
    input:
        parameters=PARAMETERS,
        models=SWEEP_MODEL_MANIFESTS,
        code=script_sources("sweep_batch"),
    output:
        batch="results/sweeps/{sweep}/batches/{batch}.json",
    params:
        spec=lambda wildcards: SWEEP.batch_spec(wildcards.batch, SWEEP_BATCH_SIZE),
    wildcard_constraints:
        sweep=SWEEP.name,
        batch="[0-9a-f]{10}",
    log:
        "logs/sweep_batch/{sweep}/{batch}.log",
    benchmark:
        benchmark_file("sweep_batch", "sweep", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/sweep_batch.py"


rule:
    name:
        f"sweep_{SWEEP.name}"
    input:
        sweep=str(SWEEP.path),
        parameters=PARAMETERS,
        batches=SWEEP_BATCH_FILES,
        code=script_sources("sweep_figure"),
    output:
        svg=figure_report(f"figures/sweep_{SWEEP.name}.svg", "sweep", caption="sweep"),
        csv=figure_report(f"figures/sweep_{SWEEP.name}.csv", "sweep", caption="sweep"),
        json=f"results/sweep_{SWEEP.name}.json",
    params:
        full=SWEEP.full,
    log:
        f"logs/sweep_{SWEEP.name}.log",
    benchmark:
        benchmark_file(f"sweep_{SWEEP.name}")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/sweep_figure.py"
