"""An assisted car's baseline: where its vehicle file gives only the gear's data (its boost map assumed, or a line),
the map and the gear's hidden numbers are identified from the healthy records first, as ``parksteer assist
identify`` does (:func:`.identify.assist_identify.identify_boost`), and the vehicle file it writes is the
one the baseline and every later record are diagnosed with."""

from __future__ import annotations

from pathlib import Path

from ..model.symbolic.components import power_assist_of
from ..parameters import Parameters


def needs_identification(files, params: Parameters, effects) -> bool:
    """Whether the car's map is to be read from its records: an electric assist whose file states no measured
    or identified boost table (its source ``assumed``, or only the boost line), and records with the motor
    current beside the torsion-bar torque."""
    assist = power_assist_of(effects)
    if assist is None or assist.power_assist != "electric":
        return False
    source = params.sources.get(f"{assist.name}.boost.assist", "assumed")
    if not source.startswith("assumed"):
        return False
    return all(f.motor_column == "motor_current_A" and f.measurement.torque_sensor == "torsion_bar" for f in files)


def identified_vehicle(files, params: Parameters, effects, vehicle, say) -> str | None:
    """The vehicle file's text with its ``[assist]`` identified from `files` (None where not needed, or where the
    file's path is not known)."""
    if vehicle is None or not needs_identification(files, params, effects):
        return None
    from .identify.assist_identify import identify_boost

    say("baseline: the assist's map and gear identified from the healthy records (as parksteer assist identify)")
    found = identify_boost([f.measurement for f in files], params)
    return found.to_vehicle_toml(Path(vehicle).read_text(encoding="utf-8"))
