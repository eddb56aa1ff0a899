"""A sweep's keys and values: the design variables, a key's bounds, and the checks of an axis's values (SI)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.symbolic.components import shipped_quantities
from ..parameters import registry
from .design import SweepError


# Grid values are rounded to this many significant digits so that linspace noise never changes a point id.
GRID_DIGITS = 12


@dataclass(frozen=True)
class DesignVariable:
    """A design quantity that sets several model parameters together."""

    name: str
    unit: str
    minimum: float
    maximum: float
    description: str
    replaces: tuple[str, ...]  # the model parameters it sets (an axis may not name them as well)


DESIGN_VARIABLES: dict[str, DesignVariable] = {
    v.name: v
    for v in (
        DesignVariable(
            "front_axle_load", "N", 1000.0, 30000.0,
            "total static load on the front wheels; the chassis mass follows (W/g minus the unsprung mass), "
            "the chassis keeps its lateral mass-centre position and the left/right split follows from statics",
            ("case.chassis_mass", "case.load_left", "case.load_right"),
        ),
        DesignVariable(
            "extra_offset", "m", 0.0, 0.2,
            "wheel spacer thickness: each wheel centre moves outboard by it (the paper's spacers); the "
            "left/right loads are re-split by statics about the wider track",
            ("case.wheel_centre_y", "case.extra_offset", "case.load_left", "case.load_right"),
        ),
        DesignVariable(
            "steering_ratio", "1", 5.0, 60.0,
            "overall steering ratio G, handwheel angle per road-wheel angle: the handwheel-to-rack ratio "
            "becomes G times the road-wheel-to-rack ratio, and the handwheel lock angle scales with G so that "
            "the rack travel and the road-wheel lock stay those of the base car",
            ("steering.handwheel_to_rack_ratio", "input.handwheel_lock_angle"),
        ),
        DesignVariable(
            "castor_angle", "rad", -0.3, 0.3,
            "castor angle, with the mechanical trail (z2 - z1) tan(castor) that keeps the steer axis through "
            "the wheel centre in side view, as in the paper's model",
            ("geometry.castor_angle", "geometry.mechanical_trail"),
        ),
    )
}


def parameter_bounds(key: str) -> tuple[float, float, bool, str]:
    """(lower, upper, lower_inclusive, unit) of a sweepable key; raise KeyError for an unknown key.

    A model quantity's bounds are its declaration's (the parameter file's, or an installed effect's); a design
    variable's are its own.
    """
    owner, _, name = key.partition(".")
    if not name:
        raise KeyError(key)
    if owner == "design":
        v = DESIGN_VARIABLES[name]
        return v.minimum, v.maximum, True, v.unit
    q = registry(shipped_quantities()).get(key)
    if q is None or q.is_list:
        raise KeyError(key)
    return q.lower, q.upper, q.lower_inclusive, q.unit


def check_key(where: str, key: Any) -> str:
    if not isinstance(key, str) or "." not in key:
        raise SweepError(f"{where}: {key!r} is not a parameter key (OWNER.NAME, e.g. tyre.tyre_pressure)")
    try:
        parameter_bounds(key)
    except KeyError:
        raise SweepError(
            f"{where}: unknown parameter {key!r} (a model parameter as for `parksteer simulate --set`, "
            f"or design.{{{', '.join(DESIGN_VARIABLES)}}})"
        ) from None
    return key


def read_number(where: str, value: Any) -> float:
    if isinstance(value, str):  # YAML 1.1 reads 1.2e5 (no dot) as a string
        try:
            value = float(value)
        except ValueError:
            pass
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SweepError(f"{where}: {value!r} is not a number")
    value = float(value)
    if not math.isfinite(value):
        raise SweepError(f"{where}: {value} is not finite")
    return value


def check_in_bounds(where: str, key: str, value: float) -> float:
    lower, upper, inclusive, unit = parameter_bounds(key)
    below = value < lower if inclusive else value <= lower
    if below or value > upper:
        bracket = "[" if inclusive else "("
        shown = f"{value:g}" if unit == "1" else f"{value:g} {unit}"
        raise SweepError(f"{where}: {shown} is out of bounds {bracket}{lower:g}, {upper:g}]")
    return value


def grid_value(value: float) -> float:
    return float(f"{value:.{GRID_DIGITS}g}")


def axis_values(where: str, key: str, raw: Any) -> tuple[float, ...]:
    """A list of numbers, or a grid {start, stop, num} (num evenly spaced values, both ends included)."""
    if isinstance(raw, dict):
        unknown = sorted(set(raw) - {"start", "stop", "num"})
        if unknown:
            raise SweepError(f"{where}.{unknown[0]}: unknown grid field (use start, stop, num)")
        missing = [k for k in ("start", "stop", "num") if k not in raw]
        if missing:
            raise SweepError(f"{where}: grid needs {missing[0]}")
        start, stop = read_number(f"{where}.start", raw["start"]), read_number(f"{where}.stop", raw["stop"])
        num = raw["num"]
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            raise SweepError(f"{where}.num: {num!r} is not a positive integer")
        if num == 1 and start != stop:
            raise SweepError(f"{where}.num: 1 value cannot span {start:g} to {stop:g}")
        values = [grid_value(v) for v in np.linspace(start, stop, num)]
    elif isinstance(raw, list):
        if not raw:
            raise SweepError(f"{where}: empty axis")
        values = [grid_value(read_number(f"{where}[{i}]", v)) for i, v in enumerate(raw)]
    elif raw is None:
        raise SweepError(f"{where}: empty axis")
    else:
        values = [grid_value(read_number(where, raw))]
    if len(set(values)) != len(values):
        raise SweepError(f"{where}: repeated value")
    for i, v in enumerate(values):
        check_in_bounds(f"{where}[{i}]", key, v)
    return tuple(values)


def check_conflicts(where: str, keys: list[str]) -> None:
    for key in keys:
        owner, _, name = key.partition(".")
        if owner != "design":
            continue
        for other in DESIGN_VARIABLES[name].replaces:
            if other in keys:
                raise SweepError(f"{where}: {key} sets {other}; sweep one of them, not both")
