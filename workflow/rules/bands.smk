# Bands on the headline numbers: each number the paper quotes over the reconstructed inputs (Hooke joint phase,
# lock angle, wheel radius, assembly mass centre, saw-tooth rounding), moved one at a time through parameter
# overrides of the figures' compiled model (parksteer.figures.bands). Writes the band table (CSV), a tornado
# figure (SVG) and the numbers the paper quotes (results/bands.json).


rule bands:
    input:
        parameters=PARAMETERS,
        model=model_manifest("full", None),
    output:
        svg=figure_report("figures/bands.svg", "bands"),
        csv=figure_report("figures/bands.csv", "bands"),
        json="results/bands.json",
    params:
        code=code("bands"),
    priority: PRIORITY["bands"]
    log:
        "logs/bands.log",
    benchmark:
        benchmark_file("bands")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/bands.py"
