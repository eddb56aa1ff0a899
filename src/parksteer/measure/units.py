"""Units of a record's channels: a channel's unit, as a logger writes it, converted to its native column's SI unit
with pint (refused in one line when pint does not know it or it measures something else)."""

from __future__ import annotations

import numpy as np

from ..errors import UsageError
from ..names import TORQUE
from .channel_map import ANGLE, CURRENT, MOTOR_TORQUE, RACK, SPEED, TIME, TORSION_BAR
from .readers.base import refusal

# The pint unit each native column is converted to.
SI_UNITS = {TIME: "s", RACK: "m", TORQUE: "N*m", ANGLE: "rad", "load_left_N": "N", "load_right_N": "N",
            SPEED: "m/s", TORSION_BAR: "N*m", CURRENT: "A", MOTOR_TORQUE: "N*m"}
UNIT_DIMENSIONS = {TIME: "time", RACK: "length", TORQUE: "torque", ANGLE: "angle", "load_left_N": "force",
                   "load_right_N": "force", SPEED: "speed", TORSION_BAR: "torque", CURRENT: "current",
                   MOTOR_TORQUE: "torque"}

# Logger spellings pint reads as something else: "Nm" is pint's number-metre, never a torque on a logger.
UNIT_SPELLINGS = {"Nm": "N*m", "rev": "revolution", "Nmm": "N*mm", "kNm": "kN*m", "deg.": "deg", "sec": "s", "kph": "km/h"}
ANGLE_UNIT_WORDS = ("radian", "degree", "revolution", "turn", "grade", "arcminute", "arcsecond")


def unit_registry():
    """pint's application registry (pint's default units, built by pint on first use: it takes a few tenths of a
    second); the package never defines units in it."""
    import pint

    return pint.get_application_registry()


def conversion(unit: str | None, target: str, where: str):
    """A function taking values in `unit` to the SI unit of native column `target`; refused in one line when
    pint does not know the unit or its dimension is not the target's."""
    si = SI_UNITS[target]
    if unit is None or unit.strip() == "" or unit.strip() == si:
        return lambda values: np.asarray(values, dtype=float)
    text = UNIT_SPELLINGS.get(unit.strip(), unit.strip())
    ureg = unit_registry()
    try:
        parsed = ureg.parse_units(text)
    except Exception:  # pint raises several types (undefined unit, syntax, tokenizer) for one user mistake
        raise refusal(where, f"unit {unit!r} is not a unit pint knows") from None
    try:
        factor = float(ureg.Quantity(1.0, parsed).to(si).magnitude)
    except Exception:
        raise UsageError(
            f"{where}: unit {unit!r} is not a unit of {UNIT_DIMENSIONS[target]} (column {target!r} needs {si} or "
            f"another unit of {UNIT_DIMENSIONS[target]})"
        ) from None
    if target == ANGLE and not any(word in str(parsed) for word in ANGLE_UNIT_WORDS):
        raise refusal(where, f"unit {unit!r} is not an angle (column {target!r} needs rad, deg or rev)")
    if float(ureg.Quantity(0.0, parsed).to(si).magnitude) != 0.0:
        raise refusal(where, f"unit {unit!r} has an offset (like degC); give a unit that starts at zero")
    divisor = 1.0 / factor
    if factor < 1.0 and divisor == round(divisor):
        # A decimal prefix: divide by the exact integer, so mm -> m is value / 1000 to the last bit.
        return lambda values: np.asarray(values, dtype=float) / round(divisor)
    return lambda values: np.asarray(values, dtype=float) * factor


def to_si(values, unit: str | None, target: str, where: str = "value") -> np.ndarray:
    """Values in `unit` converted to the SI unit of native column `target`."""
    return conversion(unit, target, where)(values)


def from_si(values, unit: str | None, target: str, where: str = "value") -> np.ndarray:
    """The inverse of :func:`to_si`: SI values of `target` in `unit`."""
    one = float(to_si(np.array([1.0]), unit, target, where)[0])
    divisor = 1.0 / one
    if one < 1.0 and divisor == round(divisor):
        return np.asarray(values, dtype=float) * round(divisor)
    return np.asarray(values, dtype=float) / one
