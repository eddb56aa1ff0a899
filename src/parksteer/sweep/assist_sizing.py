"""Assist sizing: the rack force a car needs at standstill and creeping, and the motor (or pressure) that keeps
the driver's torque under a target over the lock-to-lock cycle.

For each speed the car runs the cycle without assistance, the tyre rolling at that speed (the turn_slip effect).
The rack force (N) is the handwheel torque through the gear; the assist carries the excess of the column torque
over the target, and its motor torque (N m) and current (A), or the hydraulic pressure (Pa), follow quasi-statically
through the gear and against the assist's own friction. The check runs the cycle again with the assist so sized
(limit or relief pressure 10 % above the demand, the gain that meets the target at the peak beyond the dead band)
and gives the driver's peak torque. A speed-dependent boost curve is one assist for every speed, its parking gain
sized at the study's lowest speed. The standstill cycle runs again over the tyre-ground friction band
(FRICTION_BAND), with and without the rack's own friction; a vehicle file whose linkage ratio rises toward lock
adds the linkage_nonlinearity effect to every run (with_linkage); the motor is also sized for the ends of the
published class range (PUBLISHED_STANDSTILL_RACK_FORCE_N, size_for_rack_force), whose sources are in
``parksteer/data/published_loads.toml``. The assist's values are the vehicle file's ``[assist]``, else the assumed
defaults of a column assist. The formulas: docs/assist_sizing.md, "The demand and the gain".
"""

from __future__ import annotations

import dataclasses
import functools
import tomllib
from types import MappingProxyType

import numpy as np

from ..errors import UsageError
from ..model.numeric.assist import check_assist, table_off
from ..model.numeric.simulate import SimulationResult, simulate
from ..model.symbolic.components import with_effect_quantities
from ..parameters import Parameters
from ..resources import data_file
from ..vehicle import ASSIST_EFFECTS, ASSISTED_EFFECTS, CREEPING_EFFECTS, creeping_overrides
from ..names import TORQUE

SPEEDS_KMH = (0.0, 1.0, 3.0, 5.0)
MARGIN = 1.1  # the sized motor limit or relief pressure over the quasi-static demand
LINKAGE_EFFECT = "linkage_nonlinearity"  # the linkage ratio rising toward lock, where the vehicle file gives it

def _read_only(value):
    """`value` (a TOML document) with every table read-only and every array a tuple."""
    if isinstance(value, dict):
        return MappingProxyType({key: _read_only(item) for key, item in value.items()})
    if isinstance(value, list):
        return tuple(_read_only(item) for item in value)
    return value


@functools.cache
def published_loads() -> MappingProxyType:
    """The published loads, tyre coefficients and friction values of ``parksteer/data/published_loads.toml``, each
    with its source and how it was read (the file's header), read-only (one copy serves every caller)."""
    return _read_only(tomllib.loads(data_file("published_loads.toml").read_text(encoding="utf-8")))


# The tyre-ground friction the standstill rack force is reported over (tyre.friction_coefficient, which scales the
# bore torque of equation (2)): an assumption, its ends and their regimes in the data file.
FRICTION_BAND = tuple(published_loads()["tyre_ground_friction"]["band"])
# The class range of standstill rack forces of small and medium cars (second hand, in the data file): the force is
# reported against its lower end, and the motor sized at both ends beside the model's own load.
PUBLISHED_STANDSTILL_RACK_FORCE_N = tuple(published_loads()["class_rack_force"]["value"])


@dataclasses.dataclass
class FrictionRow:
    """The standstill cycle without assistance at one tyre-ground friction: its peak rack force and the motor
    torque and current the sized gear would need for the target there (electric)."""

    friction: float
    peak_rack_force_N: float
    peak_rack_force_without_rack_friction_N: float  # the linkage's load alone: the rack's own friction taken out
    motor_torque_Nm: float  # NaN for hydraulic
    motor_current_A: float  # NaN for hydraulic


@dataclasses.dataclass
class ClassLoadRow:
    """The assist that keeps the driver at the target against a given standstill rack force (the class range's
    ends), quasi-statically, through the car's gear at its standstill peak (module docstring's demand)."""

    rack_force_N: float
    demand: float  # at the point of action: N m (column, pinion) or N (rack, hydraulic)
    motor_torque_Nm: float  # NaN for hydraulic
    motor_current_A: float  # NaN for hydraulic
    pressure_Pa: float  # NaN for electric


@dataclasses.dataclass
class SizingRow:
    speed_kmh: float
    peak_rack_force_N: float
    peak_handwheel_manual_Nm: float
    demand: float  # the peak assist at its point of action: N m (column, pinion) or N (rack, hydraulic)
    motor_torque_Nm: float  # electric; NaN for hydraulic
    motor_current_A: float  # electric; NaN for hydraulic
    pressure_Pa: float  # hydraulic; NaN for electric
    gain: float  # the boost gain G(v) (electric) or the valve's equivalent gain A k_v / G_hr (hydraulic) of the check
    peak_handwheel_assisted_Nm: float
    check_motor_torque_Nm: float  # electric: the peak motor torque of the check run; NaN for hydraulic
    check_pressure_Pa: float  # hydraulic: the peak pressure of the check run; NaN for electric


@dataclasses.dataclass
class SizingStudy:
    assist: str
    case: str
    target_torque_Nm: float
    rows: list[SizingRow]
    standstill_manual: SimulationResult
    standstill_assisted: SimulationResult
    friction_band: list[FrictionRow] = dataclasses.field(default_factory=list)
    class_load: list[ClassLoadRow] = dataclasses.field(default_factory=list)

    def below_published(self) -> list[FrictionRow]:
        """The rows of the friction band whose standstill rack force is below the published forces of current
        small and medium cars (PUBLISHED_STANDSTILL_RACK_FORCE_N)."""
        return [r for r in self.friction_band if r.peak_rack_force_N < PUBLISHED_STANDSTILL_RACK_FORCE_N[0]]

    def columns(self) -> dict[str, np.ndarray]:
        return {f.name: np.array([getattr(r, f.name) for r in self.rows]) for f in dataclasses.fields(SizingRow)}


def _peak(values: np.ndarray) -> float:
    return float(np.max(np.abs(values)))


def demand_at_action(name: str, params: Parameters, torque_Nm: np.ndarray, per_rack: np.ndarray,
                     target_Nm: float) -> np.ndarray:
    """The assist at its point of action that leaves the driver `target_Nm` (module docstring), per sample."""
    excess = np.maximum(np.abs(torque_Nm) - target_Nm, 0.0)
    if name == ASSIST_EFFECTS["column"]:
        return excess
    if name == ASSIST_EFFECTS["pinion"]:
        return excess * per_rack / params["steering.handwheel_to_rack_ratio"]
    return excess * per_rack  # a force on the rack: rack motor or piston


def friction_at_column_Nm(name: str, params: Parameters, per_rack: float) -> float:
    """The assist's own Coulomb friction as a torque at the column, `per_rack` = d(theta_c)/d(rack) (module
    docstring): the motor's bearings through the reduction, or the piston's seals."""
    if name == ASSIST_EFFECTS["hydraulic"]:
        return float(params[f"{name}.seal_friction_force"]) / per_rack
    at_action = float(params[f"{name}.reduction_ratio"]) * float(params[f"{name}.motor_friction_torque"])
    if name == ASSIST_EFFECTS["column"]:
        return at_action
    if name == ASSIST_EFFECTS["pinion"]:
        return at_action * float(params["steering.handwheel_to_rack_ratio"]) / per_rack
    return at_action / per_rack  # a force on the rack


def size_assist(params: Parameters, case: str, target_torque_Nm: float, speeds_kmh=SPEEDS_KMH,
                assist: str | None = None) -> SizingStudy:
    """The sizing study of the car of `params` in load case `case` (module docstring)."""
    if not target_torque_Nm > 0:
        raise UsageError(f"--target-torque {target_torque_Nm:g}: must be positive (N m)")
    params = with_effect_quantities(params)  # the assists' own quantities, with their assumed defaults
    name = assist or check_assist(params) or ASSIST_EFFECTS["column"]
    v = lambda key: float(params[f"{name}.{key}"])  # noqa: E731
    hydraulic = name == ASSIST_EFFECTS["hydraulic"]
    band = v("dead_band")
    if not target_torque_Nm > band:
        raise UsageError(f"--target-torque {target_torque_Nm:g}: must exceed the assist's dead band {band:g} N m")
    ratio = float(params["steering.handwheel_to_rack_ratio"])
    kind = next(k for k, e in ASSIST_EFFECTS.items() if e == name)
    falloff = 0.0 if hydraulic else v("speed_dependence")

    def gain_factor(speed_kmh: float) -> float:
        """G(v) / G of the boost curve (1 exactly without speed dependence)."""
        return 1.0 / (1.0 + falloff * (speed_kmh / 3.6 / v("gain_half_speed")) ** 2) if falloff else 1.0

    manual_runs, demands, gains, motors = [], [], [], []
    for speed in speeds_kmh:
        manual = simulate(case, effects=with_linkage(CREEPING_EFFECTS, params), overrides=creeping_overrides(speed),
                          params=params)
        per_rack = manual.outputs()["column_angle_per_rack_rad_per_m"]
        torque = manual.columns[TORQUE]
        demand = float(np.max(demand_at_action(name, params, torque, per_rack, target_torque_Nm)))
        manual_runs.append((manual, torque, per_rack))
        demands.append(demand)
        # the boost gain that meets the target at the peak: T = (T_peak + T_f,col + G D) / (1 + G)
        peak = int(np.argmax(np.abs(torque)))
        road = _peak(torque) + friction_at_column_Nm(name, params, float(np.abs(per_rack[peak])))
        gains.append(max(road - target_torque_Nm, 0.0) / (target_torque_Nm - band))
        if not hydraulic:
            motors.append((demand / v("reduction_ratio") + v("motor_friction_torque")) / v("efficiency"))
    if falloff:  # one assist: the parking gain met at the lowest speed, the motor for the largest demand
        low = int(np.argmin(speeds_kmh))
        parking_gain = gains[low] / gain_factor(speeds_kmh[low])
        gains = [parking_gain * gain_factor(speed) for speed in speeds_kmh]
        one_assist = {f"{name}.gain": parking_gain, f"{name}.motor_torque_limit": MARGIN * max(motors),
                      **table_off(name)}
    rows, manual0, assisted0 = [], None, None
    for i, speed in enumerate(speeds_kmh):
        manual, torque, per_rack = manual_runs[i]
        demand, gain = demands[i], gains[i]
        if hydraulic:
            motor = current = float("nan")
            pressure = (demand + v("seal_friction_force")) / v("piston_area")
            # the sized valve is the straight line of the sized gain: a table of the file is switched off
            sized = {f"{name}.valve_slope": gain * ratio / v("piston_area"),
                     f"{name}.relief_pressure": max(MARGIN * pressure, 1.0e5), **table_off(name)}
        else:
            pressure = float("nan")
            motor = motors[i]
            current = motor / v("torque_constant")
            # the sized assist is the straight line of the sized gain: a table of the file is switched off
            sized = one_assist if falloff else {f"{name}.gain": gain, f"{name}.motor_torque_limit": MARGIN * motor,
                                                **table_off(name)}
        assisted = simulate(case, effects=with_linkage(ASSISTED_EFFECTS[kind], params), overrides={**creeping_overrides(speed), **sized},
                            params=params)
        c = assisted.columns
        rows.append(SizingRow(speed, _peak(torque * per_rack), _peak(torque), demand, motor, current, pressure, gain,
                              _peak(c[TORQUE]),
                              float("nan") if hydraulic else _peak(c["motor_torque_Nm"]),
                              _peak(c["pressure_Pa"]) if hydraulic else float("nan")))
        if manual0 is None:
            manual0, assisted0 = manual, assisted
    band_rows = friction_band(params, case, name, target_torque_Nm)
    c0 = manual0.columns
    per_rack0 = manual0.outputs()["column_angle_per_rack_rad_per_m"]
    at_peak = float(np.abs(per_rack0[int(np.argmax(np.abs(c0[TORQUE] * per_rack0)))]))
    class_rows = [size_for_rack_force(name, params, force, at_peak, target_torque_Nm)
                  for force in PUBLISHED_STANDSTILL_RACK_FORCE_N]
    return SizingStudy(name, case, target_torque_Nm, rows, manual0, assisted0, band_rows, class_rows)


def size_for_rack_force(name: str, params: Parameters, force_N: float, per_rack: float,
                        target_torque_Nm: float) -> ClassLoadRow:
    """The assist that leaves the driver `target_torque_Nm` against a rack force `force_N`, quasi-statically: the
    column torque F / c' (c' = d(theta_c)/d(rack) = `per_rack`), its excess over the target at the point of action,
    and the motor torque and current (electric) or the pressure (hydraulic) that give it (module docstring)."""
    v = lambda key: float(params[f"{name}.{key}"])  # noqa: E731
    torque = np.array([force_N / per_rack])
    demand = float(demand_at_action(name, params, torque, np.array([per_rack]), target_torque_Nm)[0])
    if name == ASSIST_EFFECTS["hydraulic"]:
        return ClassLoadRow(force_N, demand, float("nan"), float("nan"),
                            (demand + v("seal_friction_force")) / v("piston_area"))
    motor = (demand / v("reduction_ratio") + v("motor_friction_torque")) / v("efficiency")
    return ClassLoadRow(force_N, demand, motor, motor / v("torque_constant"), float("nan"))


def with_linkage(effects: str, params: Parameters) -> str:
    """`effects` with the linkage ratio rising toward lock (the linkage_nonlinearity effect) when the vehicle file
    gives its coefficient (``[linkage_nonlinearity] cubic_coefficient`` > 0); unchanged for a linear linkage."""
    if float(params[f"{LINKAGE_EFFECT}.cubic_coefficient"]) > 0.0:
        return f"{effects},+{LINKAGE_EFFECT}"
    return effects


def rack_force_without_rack_friction_N(result: SimulationResult) -> np.ndarray:
    """The force on the rack less the rack's own friction, per sample: the handwheel torque less the rack friction's
    term (its contribution output), through the gear. What the tie rods carry, quasi-statically."""
    c = result.columns
    per_rack = result.outputs()["column_angle_per_rack_rad_per_m"]
    return (c[TORQUE] - c.get("contrib_rack_friction_Nm", 0.0)) * per_rack


def friction_band(params: Parameters, case: str, name: str, target_torque_Nm: float,
                  frictions=FRICTION_BAND) -> list[FrictionRow]:
    """The standstill cycle without assistance at each tyre-ground friction of `frictions`: its peak rack force
    and, for an electric assist, the motor torque and current that keep the driver at the target (module
    docstring's quasi-static demand)."""
    hydraulic = name == ASSIST_EFFECTS["hydraulic"]
    out = []
    for friction in frictions:
        manual = simulate(case, effects=with_linkage(CREEPING_EFFECTS, params), params=params,
                          overrides={**creeping_overrides(0.0), "tyre.friction_coefficient": friction})
        per_rack = manual.outputs()["column_angle_per_rack_rad_per_m"]
        torque = manual.columns[TORQUE]
        motor = current = float("nan")
        if not hydraulic:
            demand = float(np.max(demand_at_action(name, params, torque, per_rack, target_torque_Nm)))
            v = lambda key: float(params[f"{name}.{key}"])  # noqa: E731
            motor = (demand / v("reduction_ratio") + v("motor_friction_torque")) / v("efficiency")
            current = motor / v("torque_constant")
        out.append(FrictionRow(friction, _peak(torque * per_rack), _peak(rack_force_without_rack_friction_N(manual)),
                               motor, current))
    return out
