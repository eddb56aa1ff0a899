# Section 4: the multibody steering model. derive_model builds the compiled model of one effect set
# (cached under results/model, keyed by the model's source); simulate_model writes one run of the
# figures; fig12-fig16 and figContrib plot them.
from parksteer.figures.model import FIGURE_RUNS, MODEL_EFFECTS, VARIANT_MODEL, VARIANTS



MODEL_FIGURE_INPUTS = {
    name: [f"results/sim/{case}__{variant}.csv" for case, variant in runs] for name, runs in FIGURE_RUNS.items()
}


rule derive_model:
    input:
        sources=MODEL_SOURCES,
    output:
        manifest="results/model/derived_{model}.json",
    wildcard_constraints:
        model="|".join(MODEL_EFFECTS),
    log:
        "logs/derive_model/{model}.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/derive_model.py"


rule simulate_model:
    input:
        parameters=PARAMETERS,
        model=lambda w: f"results/model/derived_{VARIANT_MODEL[w.variant]}.json",
    output:
        csv="results/sim/{case}__{variant}.csv",
    wildcard_constraints:
        case="[a-z0-9_]+?",
        variant="|".join(VARIANTS),
    log:
        "logs/simulate_model/{case}__{variant}.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/simulate_model.py"


rule fig12:
    input:
        parameters=PARAMETERS,
        sims=MODEL_FIGURE_INPUTS["fig12"],
    output:
        svg="figures/fig12.svg",
        csv="figures/fig12.csv",
        json="results/fig12.json",
    log:
        "logs/fig12.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/model_figure.py"


rule fig13:
    input:
        parameters=PARAMETERS,
        sims=MODEL_FIGURE_INPUTS["fig13"],
    output:
        svg="figures/fig13.svg",
        csv="figures/fig13.csv",
        json="results/fig13.json",
    log:
        "logs/fig13.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/model_figure.py"


rule fig14:
    input:
        parameters=PARAMETERS,
        sims=MODEL_FIGURE_INPUTS["fig14"],
    output:
        svg="figures/fig14.svg",
        csv="figures/fig14.csv",
        json="results/fig14.json",
    log:
        "logs/fig14.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/model_figure.py"


rule fig15:
    input:
        parameters=PARAMETERS,
        sims=MODEL_FIGURE_INPUTS["fig15"],
    output:
        svg="figures/fig15.svg",
        csv="figures/fig15.csv",
        json="results/fig15.json",
    log:
        "logs/fig15.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/model_figure.py"


rule fig16:
    input:
        parameters=PARAMETERS,
        sims=MODEL_FIGURE_INPUTS["fig16"],
    output:
        svg="figures/fig16.svg",
        csv="figures/fig16.csv",
        json="results/fig16.json",
    log:
        "logs/fig16.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/model_figure.py"


rule figContrib:
    input:
        parameters=PARAMETERS,
        sims=MODEL_FIGURE_INPUTS["figContrib"],
    output:
        svg="figures/figContrib.svg",
        csv="figures/figContrib.csv",
        json="results/figContrib.json",
    log:
        "logs/figContrib.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/model_figure.py"
