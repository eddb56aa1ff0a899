# Names the vehicle study's rules (workflow/rules/vehicle.smk) share: the vehicle file, its measurement files (a
# folder, or synthetic ones of its load cases), the import options from the configuration, the study's files.
from parksteer.vehicle import load_vehicle as _load_vehicle

VEHICLE_SUFFIXES = (".csv", ".txt", ".mf4", ".mdf", ".dat")


def vehicle_file(name):
    return f"data/vehicles/{name}.toml"


def vehicle_runs(name):
    """(case, surface) of a vehicle's synthetic measurements: every load case on the ground, the first on air."""
    cases = _load_vehicle(vehicle_file(name), PARAMETERS).case_names
    return [(case, "ground") for case in cases] + [(cases[0], "air_bearing")]


def vehicle_measurements(wildcards):
    folder = config.get("vehicle_data")
    if folder is None:
        return [f"results/vehicles/{wildcards.vehicle}/synthetic"]  # a directory: the rule scripts list it
    files = sorted(str(p) for p in Path(folder).iterdir() if p.suffix.lower() in VEHICLE_SUFFIXES)
    if not files:
        raise ValueError(f"vehicle_data {folder}: no measurement file ({', '.join(VEHICLE_SUFFIXES)})")
    return files


def check_vehicle_data():
    """A study of a folder of measurement files (`vehicle_data`): each file read while the DAG is built, as the
    study's rules will read it (the vehicle's values, `vehicle_map`, `vehicle_case`, `vehicle_surface`), so that a
    file the study cannot use (no surface stated, a channel the map lacks, a unit slip) stops Snakemake with its
    one line and exit status 2, not a failed job with the cause in its log."""
    folder, name = config.get("vehicle_data"), config.get("vehicle")
    if folder is None or name is None:
        return
    import contextlib
    import io

    from parksteer.errors import UsageError
    from parksteer.measure.channel_map import channel_map_from_options
    from parksteer.measure.importers import load_record

    keys = "--case, --surface and --map-file are --config vehicle_case=, vehicle_surface= and vehicle_map="
    try:
        if not Path(vehicle_file(name)).is_file():
            raise UsageError(f"--config vehicle={name}: no file {vehicle_file(name)} (write it with `parksteer "
                             "vehicle new`, docs/vehicles.md)")
        if not Path(folder).is_dir():
            raise UsageError(f"--config vehicle_data={folder}: no such folder")
        params = _load_vehicle(vehicle_file(name), PARAMETERS)
        channel_map = channel_map_from_options(None, config.get("vehicle_map"))
        for path in vehicle_measurements(None):
            with contextlib.redirect_stderr(io.StringIO()):  # the rules write a file's notes; here only its refusal
                load_record(path, channel_map, config.get("vehicle_case"), config.get("vehicle_surface"), params)
    except ValueError as error:  # UsageError is one, as is vehicle_measurements' empty folder
        hint = f" (in vehicle_study, {keys})" if any(o in str(error) for o in ("--case", "--surface", "--map")) else ""
        print(f"parksteer: error: {error}{hint}", file=sys.stderr)
        sys.exit(2)


def vehicle_options():
    """How every file of the study is read, from the configuration: its channel map file, case and surface."""
    return {"map_file": config.get("vehicle_map"), "case": config.get("vehicle_case"),
            "surface": config.get("vehicle_surface")}


def vehicle_study_files(wildcards):
    name = config.get("vehicle")
    if name is None:
        raise ValueError("vehicle_study needs the vehicle's name: --config vehicle=<name> (data/vehicles/<name>.toml)")
    return [
        f"results/vehicles/{name}/compare.json",
        f"figures/vehicles/{name}/compare.svg",
        f"results/vehicles/{name}/diagnosis.json",
        f"figures/vehicles/{name}/diagnosis.svg",
        f"results/vehicles/{name}/report.md",
        f"results/vehicles/{name}/report.html",
    ]


# --- the assist sizing study (workflow/rules/assist.smk) ---
from parksteer.vehicle import (ASSIST_EFFECTS as _ASSIST_EFFECTS, ASSISTED_EFFECTS as _ASSISTED_EFFECTS,
                               CREEPING_EFFECTS as _CREEPING_EFFECTS, assist_of as _assist_of)

# one model per assist kind, each with the rolling tyre; and the rolling tyre alone (the unassisted car)
ASSIST_MODELS = {kind: model_manifest(f"assist_{kind}", spec) for kind, spec in _ASSISTED_EFFECTS.items()}
CREEPING_MODEL = model_manifest("turn_slip", _CREEPING_EFFECTS)


def assist_models(wildcards):
    """The unassisted and the assisted model of the vehicle's sizing study."""
    effect = _assist_of(_load_vehicle(vehicle_file(wildcards.vehicle), PARAMETERS)) or _ASSIST_EFFECTS["column"]
    kind = next(k for k, e in _ASSIST_EFFECTS.items() if e == effect)
    return [CREEPING_MODEL, ASSIST_MODELS[kind]]


def vehicle_assist_files(wildcards):
    name = config.get("vehicle")
    if name is None:
        raise ValueError("vehicle_assist needs the vehicle's name: --config vehicle=<name> (data/vehicles/<name>.toml)")
    return [
        f"results/vehicles/{name}/assist/sizing.csv",
        f"figures/vehicles/{name}/assist_torque_against_rack.svg",
        f"figures/vehicles/{name}/assist_rack_force_against_speed.svg",
    ]
