# Design exploration: the sweep declared in config["sweep"] (default config/sweeps/design.yaml; its large
# version with config["sweep_full"]), expanded into one sweep_point job per point, so that it runs in parallel
# with --cores N and unchanged on a cluster (workflow/profiles/slurm). Each point job reads the compiled model
# of its effect sets ("free", and "braked" when the sweep simulates braked wheels) from the cache, where rule
# derive puts it, and never derives; sweep_<name> gathers the table, the key numbers and the torque maps.
from parksteer.parameters import load_parameters
from parksteer.sweep import load_sweep

SWEEP = load_sweep(
    config.get("sweep", "config/sweeps/design.yaml"),
    load_parameters(PARAMETERS),
    full=bool(config.get("sweep_full", False)),
)
SWEEP_POINT_FILES = expand(
    "results/sweeps/{sweep}/points/{point}.json", sweep=SWEEP.name, point=SWEEP.point_ids
)
SWEEP_MODEL_MANIFESTS = [
    model_manifest(f"sweep_{SWEEP.name}_{variant}", effects) for variant, effects in SWEEP.model_sets.items()
]


# The point's values are a parameter, not an input file, and its id hashes them: editing the declaration
# (another axis value, a new map) runs only the points that are new, never the whole sweep again.
rule sweep_point:
    input:
        parameters=PARAMETERS,
        models=SWEEP_MODEL_MANIFESTS,
        code=script_sources("sweep_point"),
    output:
        point="results/sweeps/{sweep}/points/{point}.json",
    params:
        spec=lambda wildcards: SWEEP.point_spec(wildcards.point),
    wildcard_constraints:
        sweep=SWEEP.name,
        point="[0-9a-f]{10}",
    log:
        "logs/sweep_point/{sweep}/{point}.log",
    benchmark:
        benchmark_file("sweep_point", "sweep", "point")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/sweep_point.py"


rule:
    name:
        f"sweep_{SWEEP.name}"
    input:
        sweep=str(SWEEP.path),
        parameters=PARAMETERS,
        points=SWEEP_POINT_FILES,
        code=script_sources("sweep_figure"),
    output:
        svg=f"figures/sweep_{SWEEP.name}.svg",
        csv=f"figures/sweep_{SWEEP.name}.csv",
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
