"""Helpers shared by the model tests (plain functions, imported by name)."""

from __future__ import annotations

import numpy as np


def first_ramp(result, rack_from_m: float = 0.02, rack_to_m: float = 0.06):
    """Mask of the first steer towards right lock with the rack between the two positions (the plateau)."""
    c = result.columns
    t_lock = result.values.params["input.time_to_right_lock"]
    return (c["time_s"] < t_lock) & (c["rack_m"] >= rack_from_m) & (c["rack_m"] <= rack_to_m)


def plateau_mean(result, column: str = "handwheel_torque_Nm") -> float:
    return float(np.mean(result.columns[column][first_ramp(result)]))


def column_angle_per_rack(params, rack_m):
    """d(column angle)/d(rack) through the Hooke joint, from tan(theta_c - phase) = cos(a) tan(theta_p - phase):
    G_hr cos(a) / (cos^2 psi + cos^2(a) sin^2 psi), psi = G_hr rack - phase (the joint's speed ratio)."""
    ratio = params["steering.handwheel_to_rack_ratio"]
    a = params["steering.hooke_joint_angle"]
    psi = ratio * np.asarray(rack_m) - params["steering.hooke_joint_phase"]
    return ratio * np.cos(a) / (np.cos(psi) ** 2 + np.cos(a) ** 2 * np.sin(psi) ** 2)

# Every friction and damper of the paper's model off (for energy balances).
DISSIPATION_OFF = {
    "steering.rack_friction_force": 0.0,
    "tyre.carcass_torsional_damping": 0.0,
    "steering.column_torsional_damping": 0.0,
    "tyre.radial_damping": 0.0,
    "vehicle.chassis_roll_damping": 0.0,
}


def with_effect(name: str, strength_key: str, case: str = "unladen", strength: float | None = None,
                overrides=None, **kwargs):
    """The paper's model plus effect `name`, at its default strength (0) or at `strength` of `name.strength_key`."""
    from parksteer.model.numeric.simulate import simulate

    chosen = {} if strength is None else {f"{name}.{strength_key}": strength}
    return simulate(case, effects=f"+{name}", overrides={**(overrides or {}), **chosen}, **kwargs)


def rack_effect_text(class_name: str, name: str, description: str, quantity: str, unit: str, upper: str,
                     force: str, docstring: str = "") -> str:
    """The text of a user-effect file: one quantity `name.quantity` (unit, 0 to `upper`, default 0) and a force
    `force` (an expression in `model` and `k`, the kinematics) along the rack, reacted on the rack housing.
    `force` may start with statements on lines of their own; its last line is the force."""
    *lines, last = force.split("\n")
    body = "".join(f"        {line}\n" for line in lines)
    head = f'"""{docstring}"""\n' if docstring else ""
    return f'''
{head}from parksteer.model.symbolic.components import Effect
from parksteer.model.symbolic.system import action_reaction
from parksteer.parameters import Quantity


class {class_name}(Effect):
    name = "{name}"
    description = "{description}"
    in_default_set = False
    quantities = (Quantity("{name}.{quantity}", "{unit}", 0.0, {upper}, lower_inclusive=True, default=0.0,
                           source="test"),)
    uses = ("{name}.{quantity}",)

    def loads(self, model):
        k = model.kinematics
{body}        return action_reaction(k.rack_point, {last}, k.rack_housing_point)


EFFECT = {class_name}()
'''


def effect_documentation(name: str) -> str:
    """What the effect `name` documents of itself: its module's docstring (the contract) and its section of the docs
    (a heading ending in ``(`name`)`` on a page of docs/: the derivation, its reasoning and its sources)."""
    import re
    import sys
    from pathlib import Path

    from parksteer.model.symbolic.components import discover_effects

    text = sys.modules[type(discover_effects()[name]).__module__].__doc__ or ""
    heading = re.compile(r"^#{2,4} [^\n]*\(`%s`\)\n(.*?)(?=^#{2,3} |\Z)" % re.escape(name), re.S | re.M)
    for page in sorted((Path(__file__).resolve().parents[2] / "docs").glob("*.md")):
        found = heading.search(page.read_text(encoding="utf-8"))
        if found:
            text += "\n" + found.group(1)
    return text
