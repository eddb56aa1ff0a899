"""The assisted truth's column-EPS layer over the manual road (:mod:`parksteer.synthetic.assisted_truth`), solved
quasi-statically at every instant of the fine grid.

The pinion follows the rack and the column the pinion through the Hooke joint
(:func:`~parksteer.synthetic.assisted_truth.column_of_pinion`); the torsion bar carries T_s (N m), read by its sensor
as S = T_s + o on the logger's converter; the control unit asks its map
(:class:`~parksteer.synthetic.assisted_truth.TruthMap`, a progressive power law or an exponential family beyond a
dead band, odd in S, neither the model's cubic table), times 1 + e (a gain error), for the current
I = A_map / (eta_f N k_t) (A), clipped at the limit; the motor's torque less its rotor's inertia and Coulomb friction
(saturated linearly below ``friction_speed_rad_s``) reaches the column as eta_f N o driving and N o / eta_b
back-driven, passing linearly through 1 at rest. T_s is where T_s + D(o(T_s)) first reaches the manual replay's
column torque T_road; inside a sensor step's jump it sits at the step's edge and the unit dithers between the two
levels. The loop does not see the logged noise. The handwheel angle is the column's plus the torsion bar's twist in
series with the column shaft (:func:`parksteer.geometry.column_twist`). The truth and its numbers:
docs/assist_diagnosis.md, "An independent truth of an assisted car".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import portable as pm
from ..geometry import column_twist
from ..measure.converter import quantisation_step
from ..parameters import Parameters
from .assisted_truth import BISECTION_STEPS, Hidden, Road, TruthGear, TruthLogger, TruthMap
from ..names import TORQUE


def _factor(o, rate, gear: TruthGear):
    """What the worm delivers to the column per rotor-side torque, over N: eta_f when the motor drives (o with the
    column's rate), 1 / eta_b back-driven (o against it), moving linearly from 1 at rest to these as the rotor's
    speed reaches ``direction_speed_rad_s`` (the worm's friction passing through its static band at a reversal).
    Driving it is at most 1 and back-driven at least 1: the gear never gives more power than it takes."""
    along = np.where(o * rate > 0.0, gear.efficiency, 1.0 / gear.back_efficiency)
    if gear.direction_speed_rad_s <= 0.0:
        reached = np.where(rate != 0.0, 1.0, 0.0)
    else:
        reached = np.minimum(np.abs(gear.reduction * rate) / gear.direction_speed_rad_s, 1.0)
    return 1.0 + (along - 1.0) * reached


def _delivered(o, rate, gear: TruthGear):
    """The torque the worm gives the column for the rotor-side torque o (:func:`_factor`); it rises with o."""
    return gear.reduction * o * _factor(o, rate, gear)


def _undelivered(delivered, rate, gear: TruthGear):
    """The rotor-side torque o that delivers `delivered` (the inverse of :func:`_delivered`: o has the sign of
    what it delivers, so the factor is read from that sign)."""
    return delivered / (gear.reduction * _factor(delivered, rate, gear))


@dataclass
class TruthSolution:
    torsion_bar_Nm: np.ndarray
    current_A: np.ndarray
    delivered_Nm: np.ndarray


def eps_layer(road: Road, boost: TruthMap, gear: TruthGear, step_Nm: float, full_scale_Nm: float,
              hidden: Hidden = Hidden()) -> TruthSolution:
    """The torsion-bar torque, the motor current and the delivered assist over `road` (module docstring), the
    control unit reading its sensor in steps of `step_Nm` (the converter of ``full_scale_Nm`` with that step)."""
    y = road.torque_Nm + hidden.rack_friction_N * (road.per_rack_friction if hidden.rack_friction_N else 0.0)
    n = gear.reduction
    rotor_rate = n * road.column_rate
    speed = np.clip(rotor_rate / gear.friction_speed_rad_s, -1.0, 1.0)
    coulomb = (gear.motor_friction_Nm + hidden.motor_friction_Nm) * speed
    load = gear.motor_inertia_kg_m2 * n * road.column_accel + coulomb
    if hidden.cogging_Nm:
        load = load + hidden.cogging_Nm * pm.sin(hidden.cogging_periods * n * road.column_rad)
    bits = max(1, round(math.log2(2.0 * full_scale_Nm / step_Nm + 1.0)))
    gain = (1.0 + hidden.gain_error) / (gear.efficiency * n * gear.torque_constant_Nm_per_A)

    # the control unit's current at each level of its reading (it reads nothing between the levels)
    step = quantisation_step(full_scale_Nm, bits)
    levels = -full_scale_Nm + step * np.arange(2**bits)
    table = np.clip(gain * boost(levels), -gear.current_limit_A, gear.current_limit_A)

    def current(reading):
        level = np.clip(np.rint((np.asarray(reading, dtype=float) + full_scale_Nm) / step), 0, 2**bits - 1)
        return table[level.astype(int)]

    def rotor(i):
        em = gear.torque_constant_Nm_per_A * i
        return em - hidden.current_friction * np.abs(em) * speed - load

    def solve(readings_of, y_, rate_):
        """T_s with T_s + D(o) first reaching y_ (bisection; readings_of(T_s) the control unit's input)."""
        width = n * gear.torque_constant_Nm_per_A * gear.current_limit_A / gear.back_efficiency + 10.0
        low, high = y_ - width, y_ + width
        for _ in range(BISECTION_STEPS):
            mid = 0.5 * (low + high)
            above = mid + _delivered(rotor_current(readings_of(mid)), rate_, gear) >= y_
            high, low = np.where(above, mid, high), np.where(above, low, mid)
        return high

    def rotor_current(reading):
        return rotor(current(reading))

    if hidden.hysteresis_Nm:
        ts = _solve_play(y, road.column_rate, hidden.sensor_offset_Nm, hidden.hysteresis_Nm,
                         lambda readings_of: solve(readings_of, y, road.column_rate), current, gear, load, speed,
                         hidden.current_friction)
    else:
        ts = solve(lambda t_s: t_s + hidden.sensor_offset_Nm, y, road.column_rate)
    delivered = y - ts
    o = _undelivered(delivered, road.column_rate, gear)
    # the mean current that delivers it (o = k_t I - mu |k_t I| sign - load, I of the sign of o + load)
    em = o + load
    em = em / (1.0 - hidden.current_friction * np.sign(em) * speed) if hidden.current_friction else em
    amps = em / gear.torque_constant_Nm_per_A
    if hidden.backlash_rad:
        ts, amps, delivered = _backlash(road, y, ts, amps, o, hidden, gear, current, rotor)
    return TruthSolution(ts, amps, delivered)


def _solve_play(y, rate, offset, half_width, solve, current, gear, load, speed, current_friction):
    """The torsion-bar torque when the control unit reads its sensor through a play of `half_width` (the map's
    hysteresis): the play's output r = clip(r_prev, S - h, S + h) feeds the map. At each sample either r holds
    (the map's input fixed: T_s = T_road less what r's current delivers, if its reading stays within r +- h), or
    r is pushed by the reading (r = S -+ h, the balance monotone in T_s: solved for every sample at once by
    `solve` beforehand)."""
    rising = solve(lambda t_s: t_s + offset - half_width)
    falling = solve(lambda t_s: t_s + offset + half_width)
    ts = np.empty(len(y))
    r = 0.0
    k_t = gear.torque_constant_Nm_per_A
    for k in range(len(y)):
        em = k_t * float(current(r))
        o = em - current_friction * abs(em) * speed[k] - load[k]
        delivered = gear.reduction * (o / gear.back_efficiency if o * rate[k] < 0.0 else gear.efficiency * o)
        held = y[k] - delivered
        s = held + offset
        if s > r + half_width:
            ts[k] = rising[k]
            r = rising[k] + offset - half_width
        elif s < r - half_width:
            ts[k] = falling[k]
            r = falling[k] + offset + half_width
        else:
            ts[k] = held
    return ts


def _backlash(road, y, ts, amps, o, hidden, gear, current, rotor):
    """Gaps of the assist where the worm's torque o reverses: the rotor crosses the lash b unloaded, for
    sqrt(2 J_m b / |o_free|) with o_free its torque with the column carrying all (T_s = T_road), during which
    the column gets no assist."""
    ts, amps = ts.copy(), amps.copy()
    t = road.time_s
    flips = np.nonzero(np.sign(o[1:]) * np.sign(o[:-1]) < 0)[0] + 1
    free = gear.torque_constant_Nm_per_A * current(y + hidden.sensor_offset_Nm)
    for k in flips:
        o_free = max(abs(float(free[k])), 1e-6)
        gap = math.sqrt(2.0 * gear.motor_inertia_kg_m2 * hidden.backlash_rad / o_free)
        inside = (t >= t[k]) & (t < t[k] + gap)
        ts[inside] = y[inside]
        amps[inside] = current(y[inside] + hidden.sensor_offset_Nm)
    return ts, amps, y - ts


def truth_clean(road: Road, boost: TruthMap, gear: TruthGear, logger: TruthLogger, hidden: Hidden = Hidden(),
                params: Parameters | None = None) -> dict[str, np.ndarray]:
    """The clean channels of the truth over `road`: time, rack, the sensor's reading (T_s + offset), current and,
    with `params` (its column), the handwheel angle."""
    solution = eps_layer(road, boost, gear, logger.torque_step, logger.torque_full_scale_Nm, hidden)
    out = {"time_s": road.time_s, "rack_m": road.rack_m,
           TORQUE: solution.torsion_bar_Nm + hidden.sensor_offset_Nm,
           "motor_current_A": solution.current_A}
    if params is not None:
        out["handwheel_angle_rad"] = handwheel_angle(road, solution.torsion_bar_Nm, gear, params)
    return out


def handwheel_angle(road: Road, torsion_bar_Nm: np.ndarray, gear: TruthGear, params: Parameters) -> np.ndarray:
    """The handwheel's angle over `road`: the column's plus the twist of the torsion bar and the column in series
    (the car's column stiffness and damping from `params`) under the torsion-bar torque."""
    s = params.sections["steering"]
    k, c = s["column_torsional_stiffness"], s["column_torsional_damping"]
    series = k * gear.torsion_bar_stiffness / (k + gear.torsion_bar_stiffness)
    twist, _ = column_twist(road.time_s, torsion_bar_Nm, series, c * series / k)
    return road.column_rad + twist
