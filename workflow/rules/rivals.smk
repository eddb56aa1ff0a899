# Rivals of lifting: each rival effect of the library given the strength that matches lifting's rise toward lock
# in the unladen ground test, then the source's other tests (part laden, air bearings, 68.5 mm spacers) simulated
# with it, to name the test that tells it from lifting (parksteer.figures.rivals). Writes the figure (SVG), the
# table (CSV) and the numbers the paper quotes (results/rivals.json). The rivals are config["rivals"], a selection
# of the effects that declare one.
_RIVALS = plan("rival_names", config.get("rivals"))


rule rivals:
    input:
        parameters=PARAMETERS,
        models=[model_manifest("full", None)] + [model_manifest(f"with_{r}", f"+{r}") for r in _RIVALS],
    output:
        svg=figure_report("figures/rivals.svg", "bands"),
        csv=figure_report("figures/rivals.csv", "bands"),
        json="results/rivals.json",
    params:
        code=code("rivals"),
        rivals=_RIVALS,
    log:
        "logs/rivals.log",
    benchmark:
        benchmark_file("rivals")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/rivals.py"
