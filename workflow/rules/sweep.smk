# Design exploration: the sweep declared in config["sweep"] (default config/sweeps/design.yaml; its large
# version with config["sweep_full"]), expanded into one sweep_point job per point, so that it runs in parallel
# with --cores N and unchanged on a cluster (workflow/profiles/slurm). Each point job reads the compiled model
# from the cache (rule derive_model, or sweep_model for an effect set of its own, such as the braked-wheel
# run) and never derives; sweep_<name> gathers the table, the key numbers and the torque maps.
from parksteer.figures.model import MODEL_EFFECTS
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


# The compiled model of each effect set the points need ("free", and "braked" when the sweep simulates braked
# wheels): the pipeline's derive_model output where it builds that set, else this file's sweep_model.
SWEEP_MODEL_MANIFESTS = {
    variant: next(
        (f"results/model/derived_{name}.json" for name, spec in MODEL_EFFECTS.items() if spec == effects),
        f"results/sweeps/{SWEEP.name}/model_{variant}.json",
    )
    for variant, effects in SWEEP.model_sets.items()
}


rule sweep_model:
    input:
        sources=MODEL_SOURCES,
    output:
        manifest="results/sweeps/{sweep}/model_{variant}.json",
    params:
        effects=lambda wildcards: SWEEP.model_sets[wildcards.variant],
    wildcard_constraints:
        sweep=SWEEP.name,
        variant="free|braked",
    log:
        "logs/sweep_model/{sweep}_{variant}.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/sweep_model.py"


# The point's values are a parameter, not an input file, and its id hashes them: editing the declaration
# (another axis value, a new map) runs only the points that are new, never the whole sweep again.
rule sweep_point:
    input:
        parameters=PARAMETERS,
        models=list(SWEEP_MODEL_MANIFESTS.values()),
    output:
        point="results/sweeps/{sweep}/points/{point}.json",
    params:
        spec=lambda wildcards: SWEEP.point_spec(wildcards.point),
    wildcard_constraints:
        sweep=SWEEP.name,
        point="[0-9a-f]{10}",
    log:
        "logs/sweep_point/{sweep}/{point}.log",
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
    output:
        svg=f"figures/sweep_{SWEEP.name}.svg",
        csv=f"figures/sweep_{SWEEP.name}.csv",
        json=f"results/sweep_{SWEEP.name}.json",
    params:
        full=SWEEP.full,
    log:
        f"logs/sweep_{SWEEP.name}.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/sweep_figure.py"
