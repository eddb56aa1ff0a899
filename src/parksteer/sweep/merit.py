"""Figures of merit of one lock-to-lock cycle, as a steering engineer quotes them.

All are taken from the simulated time history (columns as `simulate` writes them); the right-going stroke runs from
the start to the first maximum of the rack travel (right lock), and the rack's reference speed is the median rack
speed over it. Torques in N m:

* peak torque: the largest |handwheel torque| anywhere in the cycle;
* plateau torque: the mean handwheel torque over the sliding part of the right-going stroke (the rack at least half
  its reference speed, and on both sides the tread ring turning relative to the body at least half as fast as the
  wheel steers), cut at its lock end to a whole number of Hooke-joint ripple periods (half a column turn) so that
  the ripple averages out;
* share of a mechanism: the mean of its contribution column over that window over the plateau torque (the shares
  sum to one);
* torque at lock: at the last sample before right lock where the rack still moves at half its reference speed;
* drop at reversal: that torque less the torque at the first sample after right lock where the rack returns at half
  its reference speed (the rack friction reversed, the carcass hardly unwound).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from .. import portable as pm
from ..geometry import steer_axis
from ..names import SIDES, TORQUE
from ..rig import disc_distance_integral_m3, patch_radius_m, pressure_correction

MOVING_FRACTION = 0.5  # of the reference speed, for "moving", "arriving at lock" and "returning"
SLIDING_FRACTION = 0.5  # tread turning at least this fraction of the wheel's steer rate
RIPPLE_PERIOD_RAD = math.pi  # Hooke joint: two torque cycles per column revolution
REQUIRED = ("time_s", "rack_m", TORQUE, "column_angle_rad", "steer_left_rad", "steer_right_rad")


class TraceError(ValueError):
    """A time history that has no right-going stroke (or lacks a needed column)."""


def _nan_merits(contributions: list[str]) -> dict:
    return {"plateau_torque_Nm": math.nan, **{f"share_{c}": math.nan for c in contributions}}


def figures_of_merit(columns: Mapping[str, np.ndarray], torque_column: str = TORQUE) -> dict:
    """The figures of merit of one cycle (see the module docstring); NaN where a quantity does not exist."""
    missing = [c for c in REQUIRED if c not in columns]
    if missing:
        raise TraceError(f"time history lacks column {missing[0]!r}")
    t = np.asarray(columns["time_s"], dtype=float)
    rack = np.asarray(columns["rack_m"], dtype=float)
    torque = np.asarray(columns[torque_column], dtype=float)
    i_lock = int(np.argmax(rack))
    if i_lock < 3 or rack[i_lock] <= rack[0]:
        raise TraceError("time history has no right-going stroke (the rack never moves right)")
    speed = np.gradient(rack, t)
    stroke = slice(0, i_lock + 1)
    reference_speed = float(np.median(speed[stroke]))
    if reference_speed <= 0:
        raise TraceError("time history has no right-going stroke (median rack speed not positive)")
    threshold = MOVING_FRACTION * reference_speed
    moving = np.zeros(len(t), dtype=bool)
    moving[stroke] = speed[stroke] >= threshold

    sliding = moving.copy()
    for side in SIDES:
        steer = np.asarray(columns[f"steer_{side}_rad"], dtype=float)
        twist = np.asarray(columns.get(f"twist_{side}_rad", np.zeros(len(t))), dtype=float)
        steer_rate = np.gradient(steer, t)
        tread_rate = np.gradient(steer + twist, t)  # the ring turns by steer + twist relative to the body
        sliding &= tread_rate * steer_rate >= SLIDING_FRACTION * steer_rate**2

    contributions = [c for c in columns if c.startswith("contrib_")]
    out: dict = {
        "peak_torque_Nm": float(np.max(np.abs(torque))),
        "peak_time_s": float(t[int(np.argmax(np.abs(torque)))]),
        "lock_rack_m": float(rack[i_lock]),
        "reference_rack_speed_m_s": reference_speed,
    }
    arriving = np.flatnonzero(moving[stroke])
    i_arrive = int(arriving[-1]) if len(arriving) else None
    out["lock_torque_Nm"] = float(torque[i_arrive]) if i_arrive is not None else math.nan
    returning = np.flatnonzero(speed[i_lock:] <= -threshold)
    i_leave = i_lock + int(returning[0]) if len(returning) else None
    out["reversal_drop_Nm"] = (float(torque[i_arrive] - torque[i_leave])
                               if i_arrive is not None and i_leave is not None else math.nan)
    out["reversal_rack_travel_m"] = (float(rack[i_arrive] - rack[i_leave])
                                     if i_arrive is not None and i_leave is not None else math.nan)

    window = np.flatnonzero(sliding)
    out["sliding_fraction"] = float(len(window) / max(int(np.count_nonzero(moving)), 1))
    if len(window) == 0:
        out.update(_nan_merits(contributions))
        out.update(sliding_start_rack_m=math.nan, plateau_rack_range_m=[math.nan, math.nan], ripple_periods=0)
        return out
    out["sliding_start_rack_m"] = float(rack[window[0]])
    column = np.asarray(columns["column_angle_rad"], dtype=float)[window]
    periods = int(math.floor((column.max() - column.min()) / RIPPLE_PERIOD_RAD))
    if periods >= 1:
        window = window[column <= column.min() + periods * RIPPLE_PERIOD_RAD]
    plateau = float(np.mean(torque[window]))
    out["plateau_torque_Nm"] = plateau
    out["plateau_rack_range_m"] = [float(rack[window].min()), float(rack[window].max())]
    out["ripple_periods"] = periods
    for c in contributions:
        out[f"share_{c}"] = float(np.mean(np.asarray(columns[c], dtype=float)[window]) / plateau)
    return out


# ---------------------------------------------------------------------------- braked wheels (rig theory)


def ground_offset_m(params, case: str, side: str) -> float:
    """Distance in the ground plane from the contact centre to where the steer axis meets the ground."""
    axis = steer_axis(params, case, side)
    contact = axis.wheel_centre + np.array([0.0, 0.0, axis.wheel_radius_m])
    return pm.hypot(*(axis.ground_intercept() - contact)[:2])


def braked_factor(params, case: str, pressure_Pa: float) -> float:
    """Ratio of the braked to the free-rolling tyre moment about the steer axis, both wheels together.

    Rig theory (parksteer.rig): a wheel free to roll needs only the spin moment of its patch,
    equation (1); a braked wheel drags the patch rigidly round the axis's ground point at
    offset e, mu p Integral |r - e| dA. As in parksteer.rig.pin_torques_Nm, only the spin part
    carries the pressure correction (p0/p)^(n - 1/2) of equation (2), so the drag part's share
    f - 1 is divided by it. The two wheels are weighted by their spin moments (W^1.5).
    """
    scale = float(pressure_correction(pressure_Pa, params["tyre.reference_pressure"], params["tyre.pressure_index"]))
    loads = {side: params.case(case)[f"load_{side}"] for side in SIDES}
    weighted = total = 0.0
    for side in SIDES:
        radius = float(patch_radius_m(loads[side], pressure_Pa))
        ratio = float(disc_distance_integral_m3(radius, ground_offset_m(params, case, side))) / (
            2.0 * math.pi * (radius * radius * radius) / 3.0)
        weight = loads[side] * math.sqrt(loads[side])
        weighted += weight * (1.0 + (ratio - 1.0) / scale)
        total += weight
    return weighted / total


def braked_columns(columns: Mapping[str, np.ndarray], factor: float) -> dict[str, np.ndarray]:
    """The time history with the tyre friction contribution scaled by `factor` (and the torque with it)."""
    out = dict(columns)
    tyre = np.asarray(columns["contrib_tyre_friction_Nm"], dtype=float)
    out["contrib_tyre_friction_Nm"] = tyre * factor
    out[TORQUE] = np.asarray(columns[TORQUE], dtype=float) + (factor - 1.0) * tyre
    return out
