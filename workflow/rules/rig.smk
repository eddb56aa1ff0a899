# Section 2, the static tyre rig: Table 1 recomputed, Fig. 3 (torque against pressure, equations (1)
# and (2)) and Fig. 4 (torque against pin offset, wheel free to roll and braked).


rule table1:
    input:
        parameters=PARAMETERS,
        printed="src/parksteer/data/table1_printed.csv",
    output:
        csv=figure_report("figures/table1.csv", "rig"),
        json="results/table1.json",
    params:
        code=code("table1"),
    log:
        "logs/table1.log",
    benchmark:
        benchmark_file("table1")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/table1.py"


rule fig3:
    input:
        parameters=PARAMETERS,
    output:
        svg=figure_report("figures/fig3.svg", "rig"),
        csv=figure_report("figures/fig3.csv", "rig"),
        json="results/fig3.json",
    params:
        code=code("fig3"),
    log:
        "logs/fig3.log",
    benchmark:
        benchmark_file("fig3")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/fig3.py"


rule fig4:
    input:
        parameters=PARAMETERS,
    output:
        svg=figure_report("figures/fig4.svg", "rig"),
        csv=figure_report("figures/fig4.csv", "rig"),
        json="results/fig4.json",
    params:
        code=code("fig4"),
    log:
        "logs/fig4.log",
    benchmark:
        benchmark_file("fig4")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/fig4.py"
