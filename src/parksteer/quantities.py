"""The quantities of the parameter file (src/parksteer/data/parameters.toml): what a quantity is
(:class:`Quantity`: key, SI unit, physical bounds) and the table of the file's (:data:`SCHEMA`) and of a Table B1
case's (:data:`CASE_SCHEMA`), the one home of each key's unit and bounds; the keys of earlier versions
(:data:`RENAMED`). Effects declare their own quantities; a :class:`~parksteer.parameters.Parameters` carries
those of the effects it is used with."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from .errors import UsageError

INF = math.inf


class ParameterError(UsageError):
    """A parameter file that does not satisfy the schema; the message is one line."""


@dataclass(frozen=True)
class Quantity:
    """One quantity of the pipeline: its key, SI unit and physical bounds.

    ``key`` is ``section.name`` of the parameter file (``tyre.tyre_pressure``), ``case.<name>`` for a
    value of the active Table B1 case, or ``<effect>.<name>`` for a quantity only that effect has.
    ``default`` and ``source`` are given only by quantities declared in code (an effect's own, on the effect's
    class); every other quantity takes its value and source from the parameter file.

    ``free`` marks an effect's own strength as one a diagnosis fits, within the bounds, together with the calibrated
    parameters whenever the effect is in the model (``--effects=+FILE.py``), starting from its value (the default,
    or ``--set``); a quantity not free keeps the value it is given.
    """

    key: str
    unit: str
    lower: float = 0.0
    upper: float = INF
    lower_inclusive: bool = False  # most physical quantities here must be strictly positive
    upper_inclusive: bool = True
    is_list: bool = False
    description: str = ""
    why: str = ""  # the range of real cars behind the bounds, given with a refusal
    default: float | None = None
    source: str = ""
    free: bool = False

    @property
    def section(self) -> str:
        return self.key.partition(".")[0]

    @property
    def name(self) -> str:
        return self.key.partition(".")[2]

    def bounds_text(self) -> str:
        low = "[" if self.lower_inclusive else "("
        high = "]" if self.upper_inclusive else ")"
        return f"{low}{self.lower:g}, {self.upper:g}{high}"

    def within(self, value: float) -> bool:
        below = value < self.lower if self.lower_inclusive else value <= self.lower
        above = value > self.upper if self.upper_inclusive else value >= self.upper
        return not (below or above)

    def check(self, value: Any, where: str | None = None) -> float:
        """`value` as a float if it is a finite number within the bounds; else one-line ParameterError."""
        where = where or self.key
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(f"{where}: value {value!r} is not a number")
        value = float(value)
        if not math.isfinite(value):
            raise ParameterError(f"{where}: value {value} is not finite")
        if not self.within(value):
            why = f"; {self.why}" if self.why else ""
            raise ParameterError(
                f"{where}: value {value:g} {self.unit} is non-physical (allowed {self.bounds_text()}{why})"
            )
        return value


def _q(unit: str, lower: float = 0.0, upper: float = INF, **kw: Any) -> dict[str, Any]:
    return dict(unit=unit, lower=lower, upper=upper, **kw)


def _pos(unit: str, **kw: Any) -> dict[str, Any]:
    return _q(unit, **kw)


def _nonneg(unit: str, **kw: Any) -> dict[str, Any]:
    return _q(unit, lower_inclusive=True, **kw)


def _range(unit: str, lower: float, upper: float) -> dict[str, Any]:
    return _q(unit, lower, upper, lower_inclusive=True)


def _any(unit: str) -> dict[str, Any]:
    return _q(unit, -INF, INF, lower_inclusive=True)


# Unit and physical bounds of every key of the parameter file: the one home of both. The file must hold
# every key listed here, in the unit given here.
# Masses, inertias, stiffnesses and dampings have upper (and masses and inertias lower) bounds a road car cannot
# leave, each about ten times beyond the range of cars (the reason beside each): a value beyond is a wrong unit or
# a typo, and it is refused up front, naming file and key, instead of making the model too stiff to integrate
# (a tyre's radial stiffness of 1e15 N/m stops the integrator at 0.19 s) or meaningless.
ASSEMBLY_INERTIA = "a wheel, hub, brake and strut about its axes: 0.3-3 kg m^2"
_SCHEMA: dict[str, dict[str, dict[str, Any]]] = {
    "vehicle": {
        "gravity": _pos("m/s^2"),
        "unsprung_mass": _q("kg", 1.0, 2000.0,
            why="a front end's moving parts: 50-250 kg"),
        "chassis_roll_inertia": _q("kg m^2", 1.0, 1.0e5,
            why="a car body about its roll axis: 100-1000 kg m^2"),
        "chassis_roll_stiffness": _q("N m/rad", 0.0, 1.0e8,
            why="a road car's roll stiffness: 2e4-2e6 N m/rad"),
        "chassis_roll_damping": _q("N m s/rad", 0.0, 1.0e6, lower_inclusive=True,
            why="a car's roll damping: 1e3-1e5 N m s/rad"),
        "chassis_cg_z": _any("m"),
        "roll_axis_z": _any("m"),
    },
    "steering": {
        "rack_mass": _q("kg", 0.1, 100.0,
            why="a rack with its piston: 2-15 kg"),
        "rack_roll_inertia": _q("kg m^2", 0.0, 10.0, lower_inclusive=True,
            why="a rack about its axis: ~0.01 kg m^2"),
        "rack_friction_force": _range("N", 0.0, 1.0e5),
        "handwheel_to_rack_ratio": _pos("rad/m"),
        "roadwheel_to_rack_ratio": _pos("rad/m"),
        "column_torsional_stiffness": _q(
            "N m/rad", 0.0, 1.0e6, why="an EPS torsion bar is 100-3000 N m/rad, a plain column shaft 1e4-1e5"),
        "column_torsional_damping": _q("N m s/rad", 0.0, 1.0e5, lower_inclusive=True,
            why="Appendix B gives 200 N m s/rad"),
        "hooke_joint_angle": _range("rad", 0.0, 1.2),
        "hooke_joint_phase": _range("rad", -10.0, 10.0),
        "steering_assembly_cg_outboard": _any("m"),
        "steering_assembly_mass": _q("kg", 1.0, 500.0,
            why="wheel, hub, brake and strut: 20-80 kg"),
        "steering_assembly_inertia_x": _q("kg m^2", 1.0e-3, 100.0, why=ASSEMBLY_INERTIA),
        "steering_assembly_inertia_y": _q("kg m^2", 1.0e-3, 100.0, why=ASSEMBLY_INERTIA),
        "steering_assembly_inertia_z": _q("kg m^2", 1.0e-3, 100.0, why=ASSEMBLY_INERTIA),
        "rack_axis_z": _range("m", -2.0, 2.0),
        "friction_smoothing": _range("s/m", 1.0, 1.0e6),
    },
    "geometry": {
        "castor_angle": _range("rad", -0.5, 0.5),
        "kingpin_inclination": _range("rad", -0.5, 0.5),
        "mechanical_trail": _any("m"),
        "kingpin_top_y": _pos("m"),
        "kingpin_top_z": _any("m"),
        "wheel_centre_z": _any("m"),
        "ground_z": _any("m"),
    },
    "tyre": {
        # a car tyre's inflation pressure: 0.1 to 10 bar (gauge); below, the tyre is flat and equation (2) fails
        "tyre_pressure": _range("Pa", 1.0e4, 1.0e6),
        "friction_coefficient": _range("1", 0.0, 3.0),
        "reference_pressure": _range("Pa", 1.0e4, 1.0e6),
        "pressure_index": _range("1", 0.0, 3.0),
        "radial_stiffness": _q("N/m", 1.0e4, 1.0e7, why="a car tyre's vertical stiffness is 1.5e5-4e5 N/m, a "
                                                           "truck's about 1e6 N/m"),
        "radial_damping": _q("N s/m", 0.0, 1.0e6, lower_inclusive=True,
            why="Appendix B's 1e5 is already heavy"),
        "carcass_torsional_stiffness": _range("N m/rad", 1.0, 1.0e6),
        "carcass_torsional_damping": _range("N m s/rad", 0.0, 1.0e4),
        "tread_ring_mass": _q("kg", 0.01, 100.0,
            why="a tyre's tread and belts: 2-10 kg"),
        "tread_ring_yaw_inertia": _q("kg m^2", 1.0e-3, 100.0,
            why="the same about the steer axis: 0.1-1 kg m^2"),
    },
    "rig": {
        "friction_test_force": _pos("N"),
        "friction_test_load": _pos("N"),
        "rolling_radius": _pos("m"),
        "loads": _pos("N", is_list=True),
        "fig4_pressures": _pos("Pa", is_list=True),
        "fig3_pressure_range": _pos("Pa", is_list=True),
        "fig4_offset_range": _nonneg("m", is_list=True),
    },
    "input": {
        "handwheel_lock_angle": _pos("rad"),
        "time_to_right_lock": _pos("s"),
        "time_right_to_left_lock": _pos("s"),
        "time_left_lock_to_centre": _pos("s"),
        "reversal_rounding_time": _nonneg("s"),
    },
    "spacers": {
        "extra_offsets": _pos("m", is_list=True),
    },
    "synthetic": {
        "sample_rate": _pos("Hz"),
        "logger_bits": _range("1", 1.0, 24.0),
        "full_scale_handwheel_angle": _pos("rad"),
        "full_scale_rack": _pos("m"),
        "full_scale_torque": _pos("N m"),
        "full_scale_load": _pos("N"),
        "noise_handwheel_angle": _nonneg("rad"),
        "noise_rack": _nonneg("m"),
        "noise_torque": _nonneg("N m"),
        "noise_load": _nonneg("N"),
        "logger_seed": _nonneg("1"),
        "hand_speed_variation": _range("1", 0.0, 0.9),
        "hand_components": _range("1", 0.0, 20.0),
        "hand_frequency_range": _pos("Hz", is_list=True),
        "hand_knots_per_stroke": _pos("1", upper=8.0),
        "hand_seed": _nonneg("1"),
    },
}

_CASE_SCHEMA: dict[str, dict[str, Any]] = {
    "chassis_mass": _q("kg", 10.0, 2.0e4,
        why="the front axle's share of a body: 300-1500 kg for a car"),
    "chassis_cg_y": _any("m"),
    "wheel_centre_y": _pos("m"),
    "load_left": _pos("N"),
    "load_right": _pos("N"),
    "extra_offset": _nonneg("m"),
}

CASE = "case"  # the override section of the active case's values (``case.load_left``)

SCHEMA: dict[str, dict[str, Quantity]] = {
    section: {name: Quantity(f"{section}.{name}", **spec) for name, spec in entries.items()}
    for section, entries in _SCHEMA.items()
}
CASE_SCHEMA: dict[str, Quantity] = {name: Quantity(f"{CASE}.{name}", **spec) for name, spec in _CASE_SCHEMA.items()}

# Keys of earlier versions, each now one quantity of the file: refused with a pointer to the key.
RENAMED: dict[str, str] = {
    "tyre_friction.friction_coefficient": "tyre.friction_coefficient",
    "tyre_friction.tyre_pressure": "tyre.tyre_pressure",
    "tyre_friction.reference_pressure": "tyre.reference_pressure",
    "tyre_friction.pressure_index": "tyre.pressure_index",
    "tyre_friction.smoothing": "steering.friction_smoothing",
    "rack_friction.friction_force": "steering.rack_friction_force",
    "rack_friction.smoothing": "steering.friction_smoothing",
    "carcass_compliance.torsional_stiffness": "tyre.carcass_torsional_stiffness",
    "carcass_compliance.torsional_damping": "tyre.carcass_torsional_damping",
    "hooke_joint.joint_angle": "steering.hooke_joint_angle",
    "hooke_joint.phase": "steering.hooke_joint_phase",
    "column_friction.smoothing": "steering.friction_smoothing",
    "kingpin_friction.smoothing": "steering.friction_smoothing",
    "rack_stiction.smoothing": "steering.friction_smoothing",
    "turn_slip.vehicle_speed": "run.vehicle_speed",
}


# The parameter file's keys and ``case.*`` (fixed at import, looked up for every value).
FILE_AND_CASE_KEYS: Mapping[str, Quantity] = MappingProxyType(
    {**{q.key: q for table in SCHEMA.values() for q in table.values()}, **{q.key: q for q in CASE_SCHEMA.values()}})
