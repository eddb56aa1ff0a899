# Model against measurement: compare, diagnose, add the missing effect, watch the error fall.
# diag_models derives the base model with each candidate effect once; diag_car_data makes the synthetic stand-in
# for the paper's car tests (its truth kept in a separate file); diag_compare and the case_study notebook walk it;
# diag_ladder plots the error as the model grows; diag_bench_case diagnoses one synthetic data set of the
# hidden-effect benchmark (one job each, so they run in parallel) and diag_benchmark scores them all.
from parksteer.diagnose import settings as DIAG
from parksteer.diagnose.benchmark import case_names as _bench_case_names
from parksteer.synthetic.datasets import file_name as _diag_file_name

DIAG_MODEL_SOURCES = MODEL_SOURCES + [
    "src/parksteer/examples/column_imbalance.py"
]
DIAG_CAR_FILES = [f"results/diagnose/car/{_diag_file_name(c, s)}" for c, s in DIAG.CAR_FILES]
DIAG_BENCH_CASES = _bench_case_names()
DIAG_BENCH_FILES = [_diag_file_name(c, s) for c, s in DIAG.BENCHMARK_FILES]


rule diag_models:
    input:
        sources=DIAG_MODEL_SOURCES,
    output:
        manifest="results/diagnose/models.json",
    log:
        "logs/diag_models.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_models.py"


rule diag_car_data:
    input:
        parameters=PARAMETERS,
        models="results/diagnose/models.json",
    output:
        files=DIAG_CAR_FILES,
        truth="results/diagnose/car_truth.json",
    log:
        "logs/diag_car_data.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_car_data.py"


rule diag_compare:
    input:
        parameters=PARAMETERS,
        files=DIAG_CAR_FILES,
    output:
        svg="figures/diag_compare.svg",
        csv="figures/diag_compare.csv",
        json="results/diag_compare.json",
    log:
        "logs/diag_compare.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_compare.py"


rule case_study:
    input:
        notebook="workflow/notebooks/case_study.py",
        parameters=PARAMETERS,
        files=DIAG_CAR_FILES,
        truth="results/diagnose/car_truth.json",
    output:
        notebook="results/case_study.ipynb",
        json="results/case_study.json",
        residuals="results/case_study_residuals.csv",
    log:
        "logs/case_study.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_case_study.py"


rule diag_ladder:
    input:
        study="results/case_study.json",
        residuals="results/case_study_residuals.csv",
    output:
        svg="figures/diag_ladder.svg",
        csv="figures/diag_ladder.csv",
        json="results/diag_ladder.json",
    log:
        "logs/diag_ladder.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_ladder.py"


rule diag_bench_case:
    input:
        parameters=PARAMETERS,
        models="results/diagnose/models.json",
    output:
        files=[f"results/diagnose/benchmark/{{name}}/{name}" for name in DIAG_BENCH_FILES],
        truth="results/diagnose/benchmark/{name}.truth.json",
        diagnosis="results/diagnose/benchmark/{name}.diagnosis.json",
    wildcard_constraints:
        name="|".join(DIAG_BENCH_CASES) if DIAG_BENCH_CASES else "none",
    log:
        "logs/diag_bench_case/{name}.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_bench_case.py"


rule diag_benchmark:
    input:
        truths=expand("results/diagnose/benchmark/{name}.truth.json", name=DIAG_BENCH_CASES),
        diagnoses=expand("results/diagnose/benchmark/{name}.diagnosis.json", name=DIAG_BENCH_CASES),
    output:
        svg="figures/diag_benchmark.svg",
        csv="figures/diag_benchmark.csv",
        json="results/diag_benchmark.json",
    log:
        "logs/diag_benchmark.log",
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_benchmark.py"
