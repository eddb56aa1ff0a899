# --- the baseline benchmark (parksteer.experiments.baseline) ------------------------------------------------------
# Cars the model does not fit (a quirk of their own in every record: parksteer.synthetic.quirks, quirk_eps), the
# healthy record the baseline, each later record diagnosed absolutely and against it. One job a car
# (diag_baseline_batch: its records, its baseline, its diagnoses), diag_baseline scores and draws them. Part of
# `all` (FIGURES); config["baseline"], config/full_grids.yaml for every quirk and the assisted car.
DIAG_BASELINE_CARS = [car["name"] for car in config.get("baseline", {}).get("cars", [])]


rule diag_baseline_batch:
    input:
        parameters=PARAMETERS,
        vehicle="data/vehicles/polo_vi.toml",  # an assisted car's manual part and gear
        models=[*DIAG_MODELS, ASSIST_MODELS["column"], *DIAG_ASSISTED_MODELS],
    output:
        "results/diagnose/baseline/{car}.json",
    params:
        code=code("diag_baseline_batch"),
        design=config.get("baseline"),
    wildcard_constraints:
        car="|".join(DIAG_BASELINE_CARS) if DIAG_BASELINE_CARS else "none",
    priority: PRIORITY["diag_baseline_batch"]
    log:
        "logs/diag_baseline_batch/{car}.log",
    benchmark:
        benchmark_file("diag_baseline_batch", "car")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_baseline_batch.py"


rule diag_baseline:
    input:
        cars=expand("results/diagnose/baseline/{car}.json", car=DIAG_BASELINE_CARS),
    output:
        svg=figure_report("figures/diag_baseline.svg", "diagnose"),
        csv=figure_report("figures/diag_baseline.csv", "diagnose"),
        json="results/diag_baseline.json",
    params:
        code=code("diag_baseline"),
    log:
        "logs/diag_baseline.log",
    benchmark:
        benchmark_file("diag_baseline")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_baseline.py"
