# The reproduction article: every number it quotes is read from results/*.json and figures/*.csv.


# Every effect with its own quantities (declared in the effect's file), for the article's table of chosen values.
rule effects:
    input:
        parameters=PARAMETERS,
    output:
        json="results/effects.json",
    params:
        code=code("effects"),
    log:
        "logs/effects.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/effects.py"


rule paper:
    input:
        source=paper_sources(),
        parameters=PARAMETERS,
        loads="src/parksteer/data/published_loads.toml",
        effects="results/effects.json",
        figures=all_figure_files(),
        numbers=all_number_files(),
    output:
        pdf=figure_report("paper/parksteer.pdf", "paper", caption="paper"),
    params:
        code=code("paper"),
    log:
        "logs/paper.log",
    benchmark:
        benchmark_file("paper")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/paper.py"
