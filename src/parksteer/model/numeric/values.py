"""Numeric values for the generated code: the parameter vector of one run.

The vector holds, in the order the compiled model lists them, the value of every quantity that
enters the equations (by key: ``steering.rack_friction_force``, ``rack_lash.lash``, ...), the values
derived from the case and the geometry (``derived.*``: king-pin axis frames, wheel centres, inertias in
the steered frames, static tyre deflections, the roll spring's neutral angle), and the handwheel input
table. Overrides are ``{key: value}`` in the one namespace of :mod:`parksteer.parameters`
(``case.<name>`` changes the chosen Table B1 case); each is checked against its quantity's bounds.
"""

from __future__ import annotations

import dataclasses
import math
from functools import lru_cache

import numpy as np

from ... import portable as pm
from ...errors import UsageError
from ...geometry import steer_axis
from ...names import SIDES, SURFACES
from ...parameters import CASE_SCHEMA, SCHEMA, DeclaredQuantities, Parameters
from ..symbolic.components import Effect, known_quantities
from ..symbolic.system import CORE_PARAMETERS, DERIVED


def parse_overrides(items: list[str] | None) -> dict[str, float]:
    """``["KEY=VALUE", ...]`` to a dict; malformed items raise UsageError (keys are checked on use)."""
    out: dict[str, float] = {}
    for item in items or []:
        key, sep, raw = item.partition("=")
        key = key.strip()
        if not sep or "." not in key or not raw.strip():
            raise UsageError(f"--set {item!r}: expected SECTION.NAME=VALUE")
        try:
            value = float(raw)
        except ValueError:
            raise UsageError(f"--set {item!r}: {raw.strip()!r} is not a number") from None
        if not math.isfinite(value):
            raise UsageError(f"--set {item!r}: value must be finite")
        out[key] = value
    return out


@dataclasses.dataclass(frozen=True)
class RunValues:
    """The resolved values of one run: the parameters with the overrides applied, the case and the surface."""

    params: Parameters
    case: str
    surface: str

    def value(self, key: str) -> float:
        """The value of quantity `key` in this run (``case.<name>`` from the run's case)."""
        return float(self.params.value(key, self.case))

    def header(self, effects: list[Effect]) -> dict[str, str]:
        """Every value that enters the model, with its unit, keyed ``param.<key>``."""
        keys = [*CORE_PARAMETERS, *_GEOMETRY_KEYS, *_INPUT_KEYS, *(f"case.{name}" for name in CASE_SCHEMA)]
        for effect in effects:
            keys += [k for k in effect.uses if k not in keys]
        return {f"param.{key}": f"{self.value(key):.10g} {self.params.quantity(key).unit}" for key in keys}


_GEOMETRY_KEYS = tuple(f"geometry.{k}" for k in SCHEMA["geometry"]) + (
    "vehicle.chassis_cg_z", "vehicle.roll_axis_z", "steering.rack_axis_z", "steering.steering_assembly_cg_outboard",
    "steering.steering_assembly_inertia_x", "steering.steering_assembly_inertia_y",
    "steering.steering_assembly_inertia_z",
)
_INPUT_KEYS = tuple(f"input.{k}" for k in SCHEMA["input"])


@lru_cache(maxsize=32)
def _known_quantities(effects: tuple[Effect, ...]) -> DeclaredQuantities:
    """:func:`parksteer.model.symbolic.components.known_quantities` of `effects`, gathered once per tuple of the same
    effect objects (an effect's quantities are fixed when it is made; the installed effects' are read once a
    process): some fifty effects' quantities are gathered and checked for each, and a diagnosis prepares hundreds of
    runs."""
    return known_quantities(effects)


def resolve_values(params: Parameters, case: str, effects: list[Effect], overrides: dict[str, float] | None,
                   surface: str = "ground", all_effects: dict[str, Effect] | None = None) -> RunValues:
    """The parameter file's values with `overrides` applied, for the case `case`, knowing the quantities of the
    installed effects, of `effects` and of `all_effects` (as :func:`parksteer.model.symbolic.components.
    with_effect_quantities` does: :func:`_known_quantities`).

    An override of a quantity only an effect has is refused when that effect is not in the model.
    """
    if surface not in SURFACES:
        raise UsageError(f"unknown surface {surface!r} (known: {', '.join(SURFACES)})")
    params.case(case)  # raises a one-line error for an unknown case
    in_model = {e.name for e in effects}
    for key in overrides or {}:
        section = key.partition(".")[0]
        if all_effects is not None and section in all_effects and section not in in_model:
            raise UsageError(f"--set {key}: effect {section} is not in the model")
    params = params.knowing(_known_quantities((*effects, *(all_effects or {}).values())))
    try:
        params = params.with_overrides(overrides, case=case)
    except UsageError as exc:
        raise UsageError(f"--set {exc}") from None
    return RunValues(params, case, surface)


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
        "rack_z_below_roll_axis": params["steering.rack_axis_z"] - roll_axis_z,
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
        centre = pm.matmul(frame.T, axis.wheel_centre - foot)
        outboard = centre / pm.norm(centre)
        cg = params["steering.steering_assembly_cg_outboard"] * outboard
        # Inertia given about axes parallel to the body axes at zero steer; S turns with the wheel.
        inertia = pm.matmul(pm.matmul(frame.T, inertia_body), frame)
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
    """The vector p of the compiled model (its parameter order is `names`, keys), followed by the input table."""
    derived = derived_values(values)
    vector = np.empty(len(names) + len(input_table))
    for i, key in enumerate(names):
        owner, _, name = key.partition(".")
        vector[i] = derived[name] if owner == DERIVED else values.value(key)
    vector[len(names):] = input_table
    return vector


__all__ = ["RunValues", "resolve_values", "derived_values", "parameter_vector", "parse_overrides"]
