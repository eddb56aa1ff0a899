# A vehicle's assist sizing: the peak rack force at standstill and creeping speeds, and the motor torque and current
# (or pressure) that keep the driver's torque under config["assist"]["target_torque"] over the lock-to-lock cycle,
# with the two figures, under the vehicle's own folders; never part of `all`:
#   snakemake --cores 2 vehicle_assist --config vehicle=polo_vi
# The assist is the vehicle file's [assist], else a column assist at its assumed defaults.
from parksteer.vehicle import ASSIST_EFFECTS as _ASSIST_EFFECTS, assist_of as _assist_of

# one model per assist kind, each with the rolling tyre; and the rolling tyre alone (the unassisted car)
ASSIST_MODELS = {kind: model_manifest(f"assist_{kind}", f"+turn_slip,+{effect}")
                 for kind, effect in _ASSIST_EFFECTS.items()}
CREEPING_MODEL = model_manifest("turn_slip", "+turn_slip")


def assist_models(wildcards):
    """The unassisted and the assisted model of the vehicle's sizing study."""
    effect = _assist_of(_load_vehicle(vehicle_file(wildcards.vehicle), PARAMETERS)) or _ASSIST_EFFECTS["column"]
    kind = next(k for k, e in _ASSIST_EFFECTS.items() if e == effect)
    return [CREEPING_MODEL, ASSIST_MODELS[kind]]


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


def vehicle_assist_files(wildcards):
    name = config.get("vehicle")
    if name is None:
        raise ValueError("vehicle_assist needs the vehicle's name: --config vehicle=<name> (data/vehicles/<name>.toml)")
    return [
        f"results/vehicles/{name}/assist/sizing.csv",
        f"figures/vehicles/{name}/assist_torque_against_rack.svg",
        f"figures/vehicles/{name}/assist_rack_force_against_speed.svg",
    ]


rule vehicle_assist:
    input:
        vehicle_assist_files,
