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
        code=script_sources("vehicle_assist_size"),
    output:
        csv=figure_report("results/vehicles/{vehicle}/assist/sizing.csv", "vehicle", caption="vehicle_assist_size"),
        torque=figure_report("figures/vehicles/{vehicle}/assist_torque_against_rack.svg", "vehicle",
                             caption="vehicle_assist_size"),
        force=figure_report("figures/vehicles/{vehicle}/assist_rack_force_against_speed.svg", "vehicle",
                            caption="vehicle_assist_size"),
    params:
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
