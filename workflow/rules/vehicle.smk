# Your own car: a vehicle's study (compare, diagnose with its ladder, figures, report) from its measurement files,
# written under its own name (results/vehicles/<vehicle>/, figures/vehicles/<vehicle>/), never into the
# reproduction's checksummed outputs and never part of `all`:
#   snakemake --cores 2 vehicle_study --config vehicle=polo_vi                          (synthetic measurements)
#   snakemake --cores 2 vehicle_study --config vehicle=my_car vehicle_data=logs/my_car vehicle_map=my_car.map \
#       vehicle_case=kerb vehicle_surface=ground
# `vehicle` names data/vehicles/<vehicle>.toml; without `vehicle_data` the study runs on synthetic measurements
# of that car (each load case on the ground, the first also on air bearings, config["car"]'s hidden effect).
wildcard_constraints:
    vehicle="[A-Za-z0-9_-]+",

check_vehicle_data()


rule vehicle_synthetic_data:
    input:
        parameters=PARAMETERS,
        vehicle=vehicle_file("{vehicle}"),
        models=DIAG_MODELS,
    output:
        files=directory("results/vehicles/{vehicle}/synthetic"),
    params:
        code=code("vehicle_data"),
        runs=lambda w: vehicle_runs(w.vehicle),
        car=config["car"],
    log:
        "logs/vehicles/{vehicle}/synthetic_data.log",
    benchmark:
        benchmark_file("vehicle_synthetic_data", "vehicle")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/vehicle_data.py"


rule vehicle_compare:
    input:
        parameters=PARAMETERS,
        vehicle=vehicle_file("{vehicle}"),
        models=DIAG_MODELS,
        files=vehicle_measurements,
    output:
        json="results/vehicles/{vehicle}/compare.json",
        svg=figure_report("figures/vehicles/{vehicle}/compare.svg", "vehicle", caption="vehicle_compare"),
    params:
        code=code("vehicle_compare"),
        options=vehicle_options(),
    log:
        "logs/vehicles/{vehicle}/compare.log",
    benchmark:
        benchmark_file("vehicle_compare", "vehicle")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/vehicle_compare.py"


rule vehicle_diagnose:
    input:
        parameters=PARAMETERS,
        vehicle=vehicle_file("{vehicle}"),
        models=DIAG_MODELS,
        files=vehicle_measurements,
    output:
        json="results/vehicles/{vehicle}/diagnosis.json",
        svg=figure_report("figures/vehicles/{vehicle}/diagnosis.svg", "vehicle", caption="vehicle_diagnose"),
        md="results/vehicles/{vehicle}/report.md",
        html=figure_report("results/vehicles/{vehicle}/report.html", "vehicle", caption="vehicle_report"),
    params:
        code=code("vehicle_diagnose"),
        options=vehicle_options(),
    log:
        "logs/vehicles/{vehicle}/diagnose.log",
    benchmark:
        benchmark_file("vehicle_diagnose", "vehicle")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/vehicle_diagnose.py"


rule vehicle_study:
    input:
        vehicle_study_files,
