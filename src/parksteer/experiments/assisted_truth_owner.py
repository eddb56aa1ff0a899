"""The owner's file of the assisted truth benchmark's car: the vehicle file an owner would write from the gear's
data sheet and the control unit's map (:func:`owner_file`), or the one the identification of the assist writes
from a baseline record (:func:`identified_route`); :data:`ROUTES` names both."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import UsageError
from ..parameters import Parameters
from .assisted_truth_design import TruthDesign


def owner_vehicle_text(base_text: str, design: TruthDesign) -> str:
    """The owner's vehicle file: `base_text` (a column-assisted car's file) with its ``[assist]`` and
    ``[assist.boost]`` replaced by the gear's data sheet and the map written at ``design.map_points_Nm``; the
    motor's friction, which no data sheet gives, at the assumed default of the assist template."""
    from ..model.numeric.assist import assist_template

    g = design.gear
    sheet = "data sheet of the truth's gear (parksteer.synthetic.assisted_truth.TruthGear)"
    given = {"torsion_bar_stiffness": (g.torsion_bar_stiffness, sheet), "reduction_ratio": (g.reduction, sheet),
             "efficiency": (g.efficiency, sheet), "back_efficiency": (g.back_efficiency, sheet),
             "torque_constant": (g.torque_constant_Nm_per_A, sheet),
             "motor_torque_limit": (g.torque_constant_Nm_per_A * g.current_limit_A, sheet + ": current limit x k_t"),
             "motor_inertia": (g.motor_inertia_kg_m2, sheet)}
    section = assist_template("column", given, table=True)
    torques = list(design.map_points_Nm)
    assists = [float(a) for a in design.boost(np.array(torques))]
    fmt = lambda xs: "[" + ", ".join(repr(round(x, 6)) for x in xs) + "]"  # noqa: E731
    section += ("\n[assist.boost]\n"
                f'torsion_bar_torque = {{ value = {fmt(torques)}, unit = "N m", source = "the control unit\'s map, '
                'read point by point" }\n'
                f'assist = {{ value = {fmt(assists)}, unit = "N m", source = "the control unit\'s map, read point by '
                'point" }\n')
    cut = re.search(r"^(# Power assistance.*\n)?\[assist\]", base_text, flags=re.M)
    if cut is None:
        raise UsageError("owner's file: the base vehicle file has no [assist] section")
    return base_text[:cut.start()] + section


@dataclass
class Owner:
    """The owner's file read as parameters, its assist effect's name and the effects a diagnosis uses."""

    params: Parameters
    assist: str
    effects: list = field(default_factory=list)


def owner_file(base_path: str | Path, design: TruthDesign, folder: str | Path) -> Owner:
    from ..model.numeric.assist import effects_with_assist
    from ..model.symbolic.components import resolve_effects
    from ..vehicle import vehicle_from_text

    path = Path(folder) / "owner.toml"
    text = owner_vehicle_text(Path(base_path).read_text(encoding="utf-8"), design)
    path.write_text(text, encoding="utf-8")
    params = vehicle_from_text(text, path)
    spec = effects_with_assist(None, params)
    return Owner(params, spec.lstrip("+"), resolve_effects(spec))


def template_default(key: str) -> float:
    """The assumed default of the column assist's quantity `key` (what the owner's file keeps)."""
    from ..model.symbolic.components import discover_effects

    effect = discover_effects()["electric_assist_column"]
    return float(next(q.default for q in effect.quantities if q.name == key))


# The files a diagnosis can be given, by route: route -> (owner, baseline, folder) -> Owner, with `owner` the
# owner's file (:func:`owner_file`), `baseline` the path of the tier's baseline record (a null of the truth's car
# on ``TruthDesign.baseline_variation``, made apart from the cases) and `folder` a scratch folder. "map": the
# owner's file as it is; "identified": the file `parksteer assist identify` writes from the baseline, read as an
# Owner. The baseline is made only when a route of the design is in BASELINE_ROUTES.
def identified_route(owner: Owner, baseline: Path, folder: str | Path) -> Owner:
    """The file `parksteer assist identify` writes from the tier's baseline record and the owner's file (its
    gear's data; its map is not used): the identified table, the product k_t eta_f N, the motor friction."""
    from ..diagnose.identify.assist_identify import identify_boost
    from ..model.numeric.assist import effects_with_assist
    from ..model.symbolic.components import resolve_effects
    from ..vehicle import vehicle_from_text

    source = Path(folder) / "owner.toml"
    found = identify_boost([baseline], source, case=None)
    path = Path(folder) / f"identified_{Path(baseline).stem}.toml"
    text = found.to_vehicle_toml(source.read_text(encoding="utf-8"))
    path.write_text(text, encoding="utf-8")
    params = vehicle_from_text(text, path)
    spec = effects_with_assist(None, params)
    return Owner(params, spec.lstrip("+"), resolve_effects(spec))


ROUTES = {"map": lambda owner, baseline, folder: owner, "identified": identified_route}


BASELINE_ROUTES = {"identified"}
