# Section 4: the multibody steering model. simulate_model writes one run of the figures (a case and a variant of
# config["variants"]) with the compiled model rule derive builds; model_figure plots the runs of one figure of
# config["model_figures"] (fig12-fig16, figContrib), each also a named target (`snakemake fig12`).
from parksteer.figures.model import FigureDesign

FIGURE_DESIGN = FigureDesign.from_config(config)
VARIANT_MANIFESTS = {name: model_manifest(v.model, v.effects) for name, v in FIGURE_DESIGN.variants.items()}


rule simulate_model:
    input:
        parameters=PARAMETERS,
        model=lambda w: VARIANT_MANIFESTS[w.variant],
    output:
        csv="results/sim/{case}__{variant}.csv",
    params:
        code=code("simulate_model"),
        effects=lambda w: FIGURE_DESIGN.variants[w.variant].effects,
        surface=lambda w: FIGURE_DESIGN.variants[w.variant].surface,
    wildcard_constraints:
        case="[a-z0-9_]+?",
        variant="|".join(FIGURE_DESIGN.variants),
    log:
        "logs/simulate_model/{case}__{variant}.log",
    benchmark:
        benchmark_file("simulate_model", "case", "variant")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/simulate_model.py"


rule model_figure:
    input:
        parameters=PARAMETERS,
        sims=lambda w: [f"results/sim/{case}__{variant}.csv" for case, variant in figure_runs(w)],
    output:
        svg=figure_report("figures/{figure}.svg", "model", caption="model_figure"),
        csv=figure_report("figures/{figure}.csv", "model", caption="model_figure"),
        json="results/{figure}.json",
    params:
        code=code("model_figure"),
        runs=lambda w: [list(run) for run in figure_runs(w)],
        labels=lambda w: {
            v: FIGURE_DESIGN.variants[v].label for _, v in figure_runs(w) if FIGURE_DESIGN.variants[v].label
        },
    wildcard_constraints:
        figure="|".join(FIGURE_DESIGN.figures),
    log:
        "logs/model_figure/{figure}.log",
    benchmark:
        benchmark_file("model_figure", "figure")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/model_figure.py"


for _figure in FIGURE_DESIGN.figures:

    rule:
        name:
            _figure
        input:
            FIGURES[_figure],
        localrule: True
