# A vehicle's assist sizing: the peak rack force at standstill and creeping speeds, and the motor torque and current
# (or pressure) that keep the driver's torque under config["assist"]["target_torque"] over the lock-to-lock cycle,
# with the two figures, under the vehicle's own folders; never part of `all`:
#   snakemake --cores 2 vehicle_assist --config vehicle=polo_vi
# The assist is the vehicle file's [assist], else a column assist at its assumed defaults.
rule vehicle_assist_size:
    input:
        parameters=PARAMETERS,
        vehicle=vehicle_file("{vehicle}"),
        models=assist_models,
    output:
        csv=figure_report("results/vehicles/{vehicle}/assist/sizing.csv", "vehicle", caption="vehicle_assist_size"),
        torque=figure_report("figures/vehicles/{vehicle}/assist_torque_against_rack.svg", "vehicle",
                             caption="vehicle_assist_size"),
        force=figure_report("figures/vehicles/{vehicle}/assist_rack_force_against_speed.svg", "vehicle",
                            caption="vehicle_assist_size"),
    params:
        code=code("vehicle_assist_size"),
        target=config["assist"]["target_torque"],
        speeds=config["assist"]["speeds_kmh"],
    log:
        "logs/vehicles/{vehicle}/assist_size.log",
    benchmark:
        benchmark_file("vehicle_assist_size", "vehicle")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/vehicle_assist_size.py"


rule vehicle_assist:
    input:
        vehicle_assist_files,


# The paper's car with today's steering (parksteer.figures.assist_study): the lock-to-lock cycle without
# assistance, with the column electric assist and with the hydraulic assist at their assumed defaults, for the four
# wheel offsets at standstill and the unladen car at creeping speeds. Writes the figure (SVG), the table (CSV) and
# the numbers the paper quotes (results/assist_study.json); part of `all` (FIGURES).
rule assist_study:
    input:
        parameters=PARAMETERS,
        loads="src/parksteer/data/published_loads.toml",
        models=[CREEPING_MODEL, ASSIST_MODELS["column"], ASSIST_MODELS["hydraulic"]],
    output:
        svg=figure_report("figures/assist_study.svg", "model"),
        csv=figure_report("figures/assist_study.csv", "model"),
        json="results/assist_study.json",
    params:
        code=code("assist_study"),
        target=config["assist"]["target_torque"],
    log:
        "logs/assist_study.log",
    benchmark:
        benchmark_file("assist_study")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/assist_study.py"


# Creeping over speed and tyre (parksteer.figures.assist_creep): the paper's car without assist at 1, 3 and 5 km/h
# over the turn-slip slope q_Dz8, the share of its standstill moment the rolling tyre keeps and the crossover where
# the tyre's share of the plateau equals the rack friction's; about 130 cycles of 25 ms, bisection included, once
# the creeping model is compiled. Writes the figure, its table and results/assist_creep.json; part of `all` (FIGURES).
rule assist_creep:
    input:
        parameters=PARAMETERS,
        loads="src/parksteer/data/published_loads.toml",
        models=[CREEPING_MODEL],
    output:
        svg=figure_report("figures/assist_creep.svg", "model"),
        csv=figure_report("figures/assist_creep.csv", "model"),
        json="results/assist_creep.json",
    params:
        code=code("assist_creep"),
    priority: PRIORITY["assist_creep"]
    log:
        "logs/assist_creep.log",
    benchmark:
        benchmark_file("assist_creep")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/assist_creep.py"


# The assisted benchmark (parksteer.experiments.assisted_benchmark, parksteer.figures.assisted): records of the Polo
# file's car with its column assist, hands of the variation benchmark and its logger with the car's torsion-bar and
# current channels, with nothing, a candidate of an assisted car or an out-of-class change hidden, each diagnosed
# from its written file; scored against the variation benchmark's targets. Its cases (31 of the full design's 62,
# config["assisted_benchmark"]; config/full_grids.yaml for all) are each made from their own seed: diag_assisted_batch runs them in jobs of config["assisted_cases_per_job"] (dealt in turn, as the other
# diagnosis benchmarks' cases, so that the jobs run in parallel and each mixes costly and cheap cases), each job
# writing one row per case, and diag_assisted scores and draws the rows. The candidate models are derived in the
# jobs (the model cache locks each build: jobs that need one at once build it once). Part of `all` (FIGURES).
DIAG_ASSISTED_CASES = plan("assisted_cases", config.get("assisted_benchmark"))
DIAG_ASSISTED_BATCHES = case_batches("assisted_", DIAG_ASSISTED_CASES,
                                     int(config.get("assisted_cases_per_job", 16)))
# the models its jobs (and those of the independent truth's, assisted_truth.smk) replay and make records with,
# derived before them: parallel jobs compile none side by side
DIAG_ASSISTED_MODELS = [model_manifest(name, spec) for name, spec in
                        plan("assisted_models", "data/vehicles/polo_vi.toml").items()]


rule diag_assisted_batch:
    input:
        parameters=PARAMETERS,
        vehicle="data/vehicles/polo_vi.toml",
        models=[ASSIST_MODELS["column"], *DIAG_ASSISTED_MODELS],
    output:
        directory("results/diagnose/assisted/{batch}"),
    params:
        code=code("diag_assisted_batch"),
        cases=lambda wildcards: DIAG_ASSISTED_BATCHES[wildcards.batch],
    wildcard_constraints:
        batch="|".join(DIAG_ASSISTED_BATCHES) if DIAG_ASSISTED_BATCHES else "none",
    priority: PRIORITY["diag_assisted_batch"]
    log:
        "logs/diag_assisted_batch/{batch}.log",
    benchmark:
        benchmark_file("diag_assisted_batch", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_assisted_batch.py"


rule diag_assisted:
    input:
        batches=expand("results/diagnose/assisted/{batch}", batch=DIAG_ASSISTED_BATCHES),
        vehicle="data/vehicles/polo_vi.toml",
    output:
        svg=figure_report("figures/diag_assisted.svg", "diagnose"),
        csv=figure_report("figures/diag_assisted.csv", "diagnose"),
        json="results/diag_assisted.json",
    params:
        code=code("diag_assisted"),
        cases=DIAG_ASSISTED_CASES,
    log:
        "logs/diag_assisted.log",
    benchmark:
        benchmark_file("diag_assisted")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_assisted.py"
