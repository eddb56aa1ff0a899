# The reproduction article: every number it quotes is read from results/*.json and figures/*.csv.


rule paper:
    input:
        source=paper_sources(),
        parameters=PARAMETERS,
        figures=all_figure_files(),
        numbers=all_number_files(),
        code=script_sources("paper"),
    output:
        pdf=figure_report("paper/parksteer.pdf", "paper", caption="paper"),
    log:
        "logs/paper.log",
    benchmark:
        benchmark_file("paper")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/paper.py"
