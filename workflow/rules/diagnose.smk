# Model against measurement: compare, diagnose, add the missing effect, watch the error fall.
# diag_car_data makes the synthetic stand-in for the paper's car tests (config["car"]; its truth kept in a separate
# file); diag_compare and the case_study notebook walk it; diag_ladder plots the error as the model grows;
# diag_bench_batch diagnoses synthetic data sets of the hidden-effect benchmark (config["benchmark"]; the cases
# dealt into jobs of config["diagnosis_cases_per_job"], which run in parallel, each case in its own folder of the
# job's folder) and diag_benchmark scores them all. Every model a diagnosis replays (the base
# model and the base model with each candidate, the example user effect among them) is derived by rule derive
# before any of these runs. diag_outclass_batch and diag_outclass are the out-of-class benchmark
# (config["outclass"]): rival effects that are not candidates, hidden by a truth generator that is not the
# diagnosis model, scored against the physically closest candidate. diag_variation_batch and diag_variations are
# the variation benchmark (config["variations"]): records of other hands, loggers and drives, with nothing or a
# library effect hidden, scored against the targets of parksteer.experiments.variations. diag_signature_batch and
# diag_signature are the signature benchmark (config["signature"]): out-of-library effects and nulls, the
# residual's signature and the suggested effect scored per signature class (parksteer.figures.signature), its cases
# in jobs of config["signature_cases_per_job"].
DIAG_USER_EFFECT = os.path.relpath(PACKAGE_DIR / "examples" / "column_imbalance.py")
# candidate model specs, the car data set's files, the three benchmarks' case names (parksteer.plan.diagnosis)
DIAG_PLAN = plan(
    "diagnosis",
    {key: config[key] for key in ("car", "benchmark", "outclass", "variations", "signature")},
    PARAMETERS,
    DIAG_USER_EFFECT,
)
DIAG_MODELS = [model_manifest(name, spec) for name, spec in DIAG_PLAN["candidates"].items()]
DIAG_CAR_FILES = [f"results/diagnose/car/{name}" for name in DIAG_PLAN["car_files"]]
DIAG_BENCH_CASES = DIAG_PLAN["bench_cases"]
DIAG_OUTCLASS_CASES = DIAG_PLAN["outclass_cases"]
# the truth generator's models: the base model with each rival (none of them a candidate)
DIAG_OUTCLASS_MODELS = [model_manifest(f"with_{rival}", f"+{rival}") for rival in DIAG_PLAN["outclass_rivals"]]
DIAG_VARIATION_CASES = DIAG_PLAN["variation_cases"]
DIAG_PER_JOB = int(config.get("diagnosis_cases_per_job", 6))
DIAG_BENCH_BATCHES = case_batches("bench_", DIAG_BENCH_CASES, DIAG_PER_JOB)
DIAG_OUTCLASS_BATCHES = case_batches("outclass_", DIAG_OUTCLASS_CASES, DIAG_PER_JOB)
DIAG_VARIATION_BATCHES = case_batches("variations_", DIAG_VARIATION_CASES, DIAG_PER_JOB)
DIAG_SIGNATURE_CASES = DIAG_PLAN["signature_cases"]
DIAG_SIGNATURE_BATCHES = case_batches("signature_", DIAG_SIGNATURE_CASES,
                                      int(config.get("signature_cases_per_job", DIAG_PER_JOB)))


rule diag_car_data:
    input:
        parameters=PARAMETERS,
        models=DIAG_MODELS,
    output:
        files=DIAG_CAR_FILES,
        truth="results/diagnose/car_truth.json",
    params:
        code=code("diag_car_data"),
        car=config["car"],
    priority: PRIORITY["diag_car_data"]
    log:
        "logs/diag_car_data.log",
    benchmark:
        benchmark_file("diag_car_data")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_car_data.py"


rule diag_compare:
    input:
        parameters=PARAMETERS,
        files=DIAG_CAR_FILES,
    output:
        svg=figure_report("figures/diag_compare.svg", "diagnose"),
        csv=figure_report("figures/diag_compare.csv", "diagnose"),
        json="results/diag_compare.json",
    params:
        code=code("diag_compare"),
    log:
        "logs/diag_compare.log",
    benchmark:
        benchmark_file("diag_compare")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_compare.py"


# Snakemake's `notebook:` directive is not used: it runs only .ipynb (JSON) notebooks, not this jupytext
# percent-format .py one, and it keeps the executed notebook as a log, never as an output.
rule case_study:
    input:
        notebook="workflow/notebooks/case_study.py",
        parameters=PARAMETERS,
        files=DIAG_CAR_FILES,
        truth="results/diagnose/car_truth.json",
        assisted_record="data/measurements/example_polo_assisted.csv",
        assisted_vehicle="data/vehicles/polo_vi.toml",
        # the models its diagnosis of the assisted record replays (assist.smk), derived before it like a benchmark's
        assisted_models=lambda wildcards: DIAG_ASSISTED_MODELS,
    output:
        notebook="results/case_study.ipynb",
        json="results/case_study.json",
        residuals="results/case_study_residuals.csv",
    params:
        code=code("diag_case_study"),
        notebook_code=code("workflow/notebooks/case_study.py"),
    priority: PRIORITY["case_study"]
    log:
        "logs/case_study.log",
    benchmark:
        benchmark_file("case_study")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_case_study.py"


rule diag_ladder:
    input:
        study="results/case_study.json",
        residuals="results/case_study_residuals.csv",
    output:
        svg=figure_report("figures/diag_ladder.svg", "diagnose"),
        csv=figure_report("figures/diag_ladder.csv", "diagnose"),
        json="results/diag_ladder.json",
    params:
        code=code("diag_ladder"),
    log:
        "logs/diag_ladder.log",
    benchmark:
        benchmark_file("diag_ladder")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_ladder.py"


rule diag_bench_batch:
    input:
        parameters=PARAMETERS,
        models=DIAG_MODELS,
    output:
        directory("results/diagnose/benchmark/{batch}"),
    params:
        code=code("diag_bench_batch"),
        design=config["benchmark"],
        cases=lambda wildcards: DIAG_BENCH_BATCHES[wildcards.batch],
    wildcard_constraints:
        batch="|".join(DIAG_BENCH_BATCHES) if DIAG_BENCH_BATCHES else "none",
    priority: PRIORITY["diag_bench_batch"]
    log:
        "logs/diag_bench_batch/{batch}.log",
    benchmark:
        benchmark_file("diag_bench_batch", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_bench_batch.py"


rule diag_benchmark:
    input:
        batches=expand("results/diagnose/benchmark/{batch}", batch=DIAG_BENCH_BATCHES),
    output:
        svg=figure_report("figures/diag_benchmark.svg", "diagnose"),
        csv=figure_report("figures/diag_benchmark.csv", "diagnose"),
        json="results/diag_benchmark.json",
    params:
        code=code("diag_benchmark"),
        design=config["benchmark"],
        truths=case_outputs("results/diagnose/benchmark", DIAG_BENCH_CASES, DIAG_BENCH_BATCHES, "truth"),
        diagnoses=case_outputs("results/diagnose/benchmark", DIAG_BENCH_CASES, DIAG_BENCH_BATCHES, "diagnosis"),
    log:
        "logs/diag_benchmark.log",
    benchmark:
        benchmark_file("diag_benchmark")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_benchmark.py"


rule diag_outclass_batch:
    input:
        parameters=PARAMETERS,
        models=DIAG_MODELS + DIAG_OUTCLASS_MODELS,
    output:
        directory("results/diagnose/outclass/{batch}"),
    params:
        code=code("diag_outclass_batch"),
        design=config["outclass"],
        benchmark=config["benchmark"],
        cases=lambda wildcards: DIAG_OUTCLASS_BATCHES[wildcards.batch],
    wildcard_constraints:
        batch="|".join(DIAG_OUTCLASS_BATCHES) if DIAG_OUTCLASS_BATCHES else "none",
    priority: PRIORITY["diag_outclass_batch"]
    log:
        "logs/diag_outclass_batch/{batch}.log",
    benchmark:
        benchmark_file("diag_outclass_batch", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_outclass_batch.py"


rule diag_outclass:
    input:
        batches=expand("results/diagnose/outclass/{batch}", batch=DIAG_OUTCLASS_BATCHES),
    output:
        svg=figure_report("figures/diag_outclass.svg", "diagnose"),
        csv=figure_report("figures/diag_outclass.csv", "diagnose"),
        json="results/diag_outclass.json",
    params:
        code=code("diag_outclass"),
        design=config["outclass"],
        benchmark=config["benchmark"],
        truths=case_outputs("results/diagnose/outclass", DIAG_OUTCLASS_CASES, DIAG_OUTCLASS_BATCHES, "truth"),
        diagnoses=case_outputs("results/diagnose/outclass", DIAG_OUTCLASS_CASES, DIAG_OUTCLASS_BATCHES, "diagnosis"),
    log:
        "logs/diag_outclass.log",
    benchmark:
        benchmark_file("diag_outclass")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_outclass.py"


rule diag_variation_batch:
    input:
        parameters=PARAMETERS,
        models=DIAG_MODELS,
    output:
        directory("results/diagnose/variations/{batch}"),
    params:
        code=code("diag_variation_batch"),
        design=config["variations"],
        cases=lambda wildcards: DIAG_VARIATION_BATCHES[wildcards.batch],
    wildcard_constraints:
        batch="|".join(DIAG_VARIATION_BATCHES) if DIAG_VARIATION_BATCHES else "none",
    priority: PRIORITY["diag_variation_batch"]
    log:
        "logs/diag_variation_batch/{batch}.log",
    benchmark:
        benchmark_file("diag_variation_batch", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_variation_batch.py"


rule diag_variations:
    input:
        batches=expand("results/diagnose/variations/{batch}", batch=DIAG_VARIATION_BATCHES),
    output:
        svg=figure_report("figures/diag_variations.svg", "diagnose"),
        csv=figure_report("figures/diag_variations.csv", "diagnose"),
        json="results/diag_variations.json",
    params:
        code=code("diag_variations"),
        design=config["variations"],
        truths=case_outputs("results/diagnose/variations", DIAG_VARIATION_CASES, DIAG_VARIATION_BATCHES, "truth"),
        diagnoses=case_outputs("results/diagnose/variations", DIAG_VARIATION_CASES, DIAG_VARIATION_BATCHES, "diagnosis"),
    log:
        "logs/diag_variations.log",
    benchmark:
        benchmark_file("diag_variations")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_variations.py"


rule diag_signature_batch:
    input:
        parameters=PARAMETERS,
        models=DIAG_MODELS,
    output:
        directory("results/diagnose/signature/{batch}"),
    params:
        code=code("diag_signature_batch"),
        design=config["signature"],
        cases=lambda wildcards: DIAG_SIGNATURE_BATCHES[wildcards.batch],
    wildcard_constraints:
        batch="|".join(DIAG_SIGNATURE_BATCHES) if DIAG_SIGNATURE_BATCHES else "none",
    priority: PRIORITY["diag_signature_batch"]
    log:
        "logs/diag_signature_batch/{batch}.log",
    benchmark:
        benchmark_file("diag_signature_batch", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_signature_batch.py"


rule diag_signature:
    input:
        batches=expand("results/diagnose/signature/{batch}", batch=DIAG_SIGNATURE_BATCHES),
    output:
        svg=figure_report("figures/diag_signature.svg", "diagnose"),
        csv=figure_report("figures/diag_signature.csv", "diagnose"),
        json="results/diag_signature.json",
    params:
        code=code("diag_signature"),
        design=config["signature"],
        rows=case_outputs("results/diagnose/signature", DIAG_SIGNATURE_CASES, DIAG_SIGNATURE_BATCHES, "diagnosis"),
    log:
        "logs/diag_signature.log",
    benchmark:
        benchmark_file("diag_signature")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_signature.py"
