# Appendix A: the handwheel torque from lifting the body, equation (A1), for the standard car and spacers.


rule figA3:
    input:
        parameters=PARAMETERS,
    output:
        svg=figure_report("figures/figA3.svg", "lifting"),
        csv=figure_report("figures/figA3.csv", "lifting"),
        json="results/figA3.json",
    params:
        code=code("figA3"),
    log:
        "logs/figA3.log",
    benchmark:
        benchmark_file("figA3")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/figA3.py"
