"""Numeric values for the generated code: the parameter vector of one run.

The vector holds, in the order the compiled model lists them, the core parameters of
data/parameters.toml, the parameters of each effect, the values derived from the case
and the geometry (king-pin axis frames, wheel centres, inertias in the steered frames,
static tyre deflections, the roll spring's neutral angle), and the handwheel input table.

Overrides are ``{"owner.name": value}``: an owner that is a section of the parameter file
(vehicle, steering, geometry, tyre, input) changes that entry (and so every default read
from it); ``case.<key>`` changes the chosen Table B1 case; an effect's name sets that
effect's parameter. Each value is checked against its bounds.
"""

from __future__ import annotations

import dataclasses
import math
import numpy as np

from ...errors import UsageError
from ...geometry import steer_axis
from ...parameters import CASE_SCHEMA, SCHEMA, Parameters
from ..symbolic.components import Effect, EffectParameter
from ..symbolic.system import CORE_PARAMETERS, DERIVED, SIDES

SURFACES = {"ground": 1.0, "air_bearing": 0.0}

# Model parameters the paper does not give and the parameter file may not (yet) hold:
# read from the file when present, else this documented default.
MODEL_PARAMETERS: dict[str, EffectParameter] = {
    "steering.rack_axis_z": EffectParameter(
        "rack_axis_z", "m", -2.0, 2.0,
        "choice: the rack's axis at wheel-centre height (z down); it only sets the rack's small share of the "
        "roll inertia and of the weight moment under roll",
        default=0.2, file_key="steering.rack_axis_z",
    ),
}


def parse_overrides(items: list[str] | None) -> dict[str, float]:
    """``["EFFECT.PARAM=VALUE", ...]`` to a dict; malformed items raise UsageError."""
    out: dict[str, float] = {}
    for item in items or []:
        key, sep, raw = item.partition("=")
        key = key.strip()
        if not sep or "." not in key or not raw.strip():
            raise UsageError(f"--set {item!r}: expected OWNER.PARAM=VALUE")
        try:
            value = float(raw)
        except ValueError:
            raise UsageError(f"--set {item!r}: {raw.strip()!r} is not a number") from None
        if not math.isfinite(value):
            raise UsageError(f"--set {item!r}: value must be finite")
        out[key] = value
    return out


def _check_spec(key: str, spec, value: float) -> float:
    below = value < spec.lower if spec.lower_inclusive else value <= spec.lower
    if below or value > spec.upper or spec.is_list:
        bracket = "[" if spec.lower_inclusive else "("
        raise UsageError(f"{key} = {value:g} {spec.unit} is out of bounds {bracket}{spec.lower:g}, {spec.upper:g}]")
    return value


@dataclasses.dataclass(frozen=True)
class RunValues:
    """The resolved values of one run: parameters (possibly overridden), case, effect parameters."""

    params: Parameters
    case: str
    surface: str
    effect_values: dict[str, dict[str, float]]
    model_values: dict[str, float]

    def header(self, effects: list[Effect]) -> dict[str, str]:
        """Every value that enters the model, with its unit, keyed ``param.<owner>.<name>``."""
        out: dict[str, str] = {}
        for section, name in CORE_PARAMETERS + _GEOMETRY_KEYS + _INPUT_KEYS:
            out[f"param.{section}.{name}"] = f"{self.params[f'{section}.{name}']:.10g} {SCHEMA[section][name].unit}"
        for key, spec in MODEL_PARAMETERS.items():
            out[f"param.{key}"] = f"{self.model_values[key]:.10g} {spec.unit}"
        for name, value in self.params.case(self.case).items():
            out[f"param.case.{name}"] = f"{value:.10g} {CASE_SCHEMA[name].unit}"
        for effect in effects:
            for spec in effect.parameters:
                out[f"param.{effect.name}.{spec.name}"] = f"{self.effect_values[effect.name][spec.name]:.10g} {spec.unit}"
        return out


_GEOMETRY_KEYS = tuple(("geometry", k) for k in SCHEMA["geometry"]) + (
    ("vehicle", "chassis_cg_z"), ("vehicle", "roll_axis_z"), ("steering", "steering_assembly_cg_outboard"),
    ("steering", "steering_assembly_inertia_x"), ("steering", "steering_assembly_inertia_y"),
    ("steering", "steering_assembly_inertia_z"),
)
_INPUT_KEYS = tuple(("input", k) for k in SCHEMA["input"])


def resolve_values(params: Parameters, case: str, effects: list[Effect], overrides: dict[str, float] | None,
                   surface: str = "ground", all_effects: dict[str, Effect] | None = None) -> RunValues:
    """Apply `overrides` to the parameter file's values and fill every effect parameter."""
    if surface not in SURFACES:
        raise UsageError(f"unknown surface {surface!r} (known: {', '.join(SURFACES)})")
    params.case(case)  # raises a one-line error for an unknown case
    overrides = dict(overrides or {})
    sections = {k: dict(v) for k, v in params.sections.items()}
    cases = {k: dict(v) for k, v in params.cases.items()}
    by_name = {e.name: e for e in effects}
    effect_overrides: dict[str, dict[str, float]] = {}
    model_overrides: dict[str, float] = {}
    for key, value in overrides.items():
        owner, _, name = key.partition(".")
        if key in MODEL_PARAMETERS:
            model_overrides[key] = MODEL_PARAMETERS[key].check(owner, value)
        elif owner in SCHEMA and owner not in ("rig", "spacers"):
            if name not in SCHEMA[owner]:
                raise UsageError(f"--set {key}: unknown parameter {name!r} of section {owner}")
            sections[owner][name] = _check_spec(key, SCHEMA[owner][name], float(value))
        elif owner == "case":
            if name not in CASE_SCHEMA:
                raise UsageError(f"--set {key}: unknown case parameter {name!r}")
            cases[case][name] = _check_spec(key, CASE_SCHEMA[name], float(value))
        elif owner in by_name:
            by_name[owner].parameter(name)
            effect_overrides.setdefault(owner, {})[name] = float(value)
        elif all_effects is not None and owner in all_effects:
            raise UsageError(f"--set {key}: effect {owner} is not in the model")
        else:
            raise UsageError(f"--set {key}: unknown owner {owner!r} (an effect of the model or a parameter section)")
    params = dataclasses.replace(params, sections=sections, cases=cases)
    effect_values = {}
    for effect in effects:
        values = {}
        for spec in effect.parameters:
            raw = effect_overrides.get(effect.name, {}).get(spec.name, spec.default_value(params))
            values[spec.name] = spec.check(effect.name, raw)
        effect_values[effect.name] = values
    model_values = {key: model_overrides.get(key, spec.default_value(params)) for key, spec in MODEL_PARAMETERS.items()}
    return RunValues(params, case, surface, effect_values, model_values)


def derived_values(values: RunValues) -> dict[str, float]:
    """Values computed from the case and the geometry, keyed as in parksteer.model.symbolic.system."""
    params, case = values.params, values.case
    c = params.case(case)
    roll_axis_z = params["vehicle.roll_axis_z"]
    ground_z = params["geometry.ground_z"]
    out = {
        "chassis_mass": c["chassis_mass"],
        "chassis_cg_y": c["chassis_cg_y"],
        "chassis_cg_z_below_roll_axis": params["vehicle.chassis_cg_z"] - roll_axis_z,
        "rack_z_below_roll_axis": values.model_values["steering.rack_axis_z"] - roll_axis_z,
        "roll_axis_z": roll_axis_z,
        "ground_z": ground_z,
        "wheel_radius": ground_z - params["geometry.wheel_centre_z"],
        "roll_spring_neutral": 0.0,  # set by the static balance (simulate.balance_roll_spring)
        "surface_grip": SURFACES[values.surface],
    }
    inertia_body = np.diag([params[f"steering.steering_assembly_inertia_{a}"] for a in "xyz"])
    for side in SIDES:
        axis = steer_axis(params, case, side)
        frame = axis.axis_frame
        foot = axis.foot
        centre = frame.T @ (axis.wheel_centre - foot)
        outboard = centre / np.linalg.norm(centre)
        cg = params["steering.steering_assembly_cg_outboard"] * outboard
        # Inertia given about axes parallel to the body axes at zero steer; S turns with the wheel.
        inertia = frame.T @ inertia_body @ frame
        load = c[f"load_{side}"]
        entries = {f"foot_{a}": foot[i] for i, a in enumerate("xyz")}
        entries.update({f"axis_frame_{i}{j}": frame[i, j] for i in range(3) for j in range(3)})
        entries.update({f"centre_in_axis_{a}": centre[i] for i, a in enumerate("xyz")})
        entries.update({f"assembly_cg_in_axis_{a}": cg[i] for i, a in enumerate("xyz")})
        for (i, j), key in zip(((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)), ("xx", "yy", "zz", "xy", "yz", "zx")):
            entries[f"assembly_inertia_{key}"] = inertia[i, j]
        entries["static_tyre_deflection"] = load / params["tyre.radial_stiffness"]
        out.update({f"{side}.{k}": v for k, v in entries.items()})
    return out


def parameter_vector(names: list[str], values: RunValues, input_table: np.ndarray) -> np.ndarray:
    """The vector p of the compiled model (its parameter order is `names`), followed by the input table."""
    derived = derived_values(values)
    vector = np.empty(len(names) + len(input_table))
    for i, key in enumerate(names):
        owner, _, name = key.partition(".")
        if owner == DERIVED:
            vector[i] = derived[name]
        elif owner in values.effect_values:
            vector[i] = values.effect_values[owner][name]
        elif key in values.model_values:
            vector[i] = values.model_values[key]
        else:
            vector[i] = values.params[key]
    vector[len(names):] = input_table
    return vector


__all__ = ["RunValues", "resolve_values", "derived_values", "parameter_vector", "parse_overrides", "SURFACES",
           "MODEL_PARAMETERS"]
