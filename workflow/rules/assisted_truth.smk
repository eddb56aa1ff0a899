# --- the assisted benchmark on an independent truth (parksteer.experiments.assisted_truth) --------------------
# Records of a column EPS written apart from the model's assist (parksteer.synthetic.assisted_truth: its own map,
# the control unit reading the torque sensor's steps, a worm gear both ways, the rotor's inertia and friction) over
# the manual replay of the Polo file's car, logged with a rack or with the handwheel angle only, each diagnosed
# with the owner's file (the gear's data sheet, the map point by point). Its cases (config["assisted_truth"];
# config/full_grids.yaml for the full design) are each made from their own seed: diag_assisted_truth_batch runs
# them in jobs of config["assisted_truth_cases_per_job"], each job writing the rows of its cases, and
# diag_assisted_truth scores and draws them. Part of `all` (FIGURES).
DIAG_ASSISTED_TRUTH_CASES = plan("assisted_truth_cases", config.get("assisted_truth"))
DIAG_ASSISTED_TRUTH_BATCHES = case_batches("truth_", DIAG_ASSISTED_TRUTH_CASES,
                                           int(config.get("assisted_truth_cases_per_job", 8)))


rule diag_assisted_truth_batch:
    input:
        parameters=PARAMETERS,
        vehicle="data/vehicles/polo_vi.toml",
        models=[ASSIST_MODELS["column"], *DIAG_ASSISTED_MODELS],  # the owner's file has the Polo's gear
    output:
        directory("results/diagnose/assisted_truth/{batch}"),
    params:
        code=code("diag_assisted_truth_batch"),
        cases=lambda wildcards: DIAG_ASSISTED_TRUTH_BATCHES[wildcards.batch],
        design=config.get("assisted_truth"),
    wildcard_constraints:
        batch="|".join(DIAG_ASSISTED_TRUTH_BATCHES) if DIAG_ASSISTED_TRUTH_BATCHES else "none",
    priority: PRIORITY["diag_assisted_truth_batch"]
    log:
        "logs/diag_assisted_truth_batch/{batch}.log",
    benchmark:
        benchmark_file("diag_assisted_truth_batch", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_assisted_truth_batch.py"


rule diag_assisted_truth:
    input:
        batches=expand("results/diagnose/assisted_truth/{batch}", batch=DIAG_ASSISTED_TRUTH_BATCHES),
        vehicle="data/vehicles/polo_vi.toml",
    output:
        svg=figure_report("figures/diag_assisted_truth.svg", "diagnose"),
        csv=figure_report("figures/diag_assisted_truth.csv", "diagnose"),
        json="results/diag_assisted_truth.json",
    params:
        code=code("diag_assisted_truth"),
        cases=DIAG_ASSISTED_TRUTH_CASES,
        design=config.get("assisted_truth"),
    log:
        "logs/diag_assisted_truth.log",
    benchmark:
        benchmark_file("diag_assisted_truth")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_assisted_truth.py"
