"""A column EPS whose gear, saturation, corner and sensor filtering have forms of their own: the assisted car the
model does not fit.

Beside :mod:`.assisted_truth` (whose map, road, gear data, hidden changes and logger this reuses), the layer over the
manual replay differs from both that truth and the model's assist
(:mod:`parksteer.model.symbolic.effects.electric_assist`) in four places, each a form a real unit may have:

- the worm's back-driven factor (:func:`worm_factor`): from ``eta_f`` driving to ``1 / eta_b`` back-driven through
  the sign of the power, passing through 1 at rest along ``1 - exp(-(omega / omega_0)^2)`` of the rotor's speed
  (the model's onset is tanh, the other truth's linear);
- the saturation (:func:`soft_limit`): the asked current limited by ``I / (1 + (|I| / I_max)^4)^(1/4)`` (the model's
  is a hyperbola, the other truth's a clip);
- the corner: the other truth's exponential map ``c (exp((|S| - d) / w) - 1)`` beyond the dead band, or its power law;
- the sensor's filtering: a first-order low-pass of ``sensor_time_constant_s`` on the torsion-bar sensor's output,
  which the bus carries (the control unit reads ahead of it).

``eta_b`` is drawn from its published band (:func:`drawn_back_efficiency`: 0.75-0.85, the Polo file's provenance of
``back_efficiency``). Hidden changes and cogging are :class:`~parksteer.synthetic.assisted_truth.Hidden`'s.
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
from .column_eps_layer import handwheel_angle
from ..names import TORQUE

BACK_EFFICIENCY_BAND = (0.75, 0.85)  # data/vehicles/polo_vi.toml, back_efficiency's source


@dataclass(frozen=True)
class EpsQuirk:
    """The forms of the quirk's unit: the onset speed of the worm's factor (rad/s of the rotor), the sensor's
    filter time constant (s)."""

    onset_speed_rad_s: float = 1.5
    sensor_time_constant_s: float = 0.008


def drawn_back_efficiency(seed: int) -> float:
    """eta_b drawn uniformly from :data:`BACK_EFFICIENCY_BAND` with `seed`."""
    low, high = BACK_EFFICIENCY_BAND
    return float(np.random.default_rng(seed).uniform(low, high))


def worm_factor(o, rate, gear: TruthGear, quirk: EpsQuirk):
    """What the worm delivers to the column per rotor-side torque, over N: eta_f with the power flowing from the
    motor (o with the column's rate), 1 / eta_b against it, from 1 at rest with a Gaussian onset in the rotor's
    speed. Never more power out than in."""
    along = np.where(o * rate > 0.0, gear.efficiency, 1.0 / gear.back_efficiency)
    speed = gear.reduction * rate / quirk.onset_speed_rad_s
    return 1.0 + (along - 1.0) * (1.0 - pm.exp(-(speed * speed)))


def soft_limit(current, limit: float):
    """The current limited with a knee: I / (1 + (|I| / limit)^4)^(1/4) (sqrt only: exact on every machine)."""
    u = np.asarray(current, dtype=float) / limit
    return current / np.sqrt(np.sqrt(1.0 + u**4))


def sensor_filtered(time_s: np.ndarray, signal: np.ndarray, tau_s: float) -> np.ndarray:
    """A first-order low-pass from rest at the signal's start (exact for a signal linear between samples)."""
    if tau_s <= 0.0:
        return np.asarray(signal, dtype=float)
    return column_twist(time_s, np.asarray(signal, dtype=float), 1.0, tau_s)[0]


@dataclass
class QuirkSolution:
    torsion_bar_Nm: np.ndarray
    current_A: np.ndarray


def quirk_layer(road: Road, boost: TruthMap, gear: TruthGear, quirk: EpsQuirk, step_Nm: float, full_scale_Nm: float,
                hidden: Hidden = Hidden()) -> QuirkSolution:
    """The torsion-bar torque T_s and the motor's current over `road`: T_s + N o w(o) = T_road, o = k_t I - loads,
    I the soft-limited current the map asks for at the sensor's reading (T_s + offset, on the converter's levels
    of `step_Nm`), solved by bisection at every sample (the left side rises with T_s)."""
    y = road.torque_Nm + hidden.rack_friction_N * (road.per_rack_friction if hidden.rack_friction_N else 0.0)
    n, k_t = gear.reduction, gear.torque_constant_Nm_per_A
    speed = np.clip(n * road.column_rate / gear.friction_speed_rad_s, -1.0, 1.0)
    load = gear.motor_inertia_kg_m2 * n * road.column_accel \
        + (gear.motor_friction_Nm + hidden.motor_friction_Nm) * speed
    if hidden.cogging_Nm:
        load = load + hidden.cogging_Nm * pm.sin(hidden.cogging_periods * n * road.column_rad)
    bits = max(1, round(math.log2(2.0 * full_scale_Nm / step_Nm + 1.0)))
    step = quantisation_step(full_scale_Nm, bits)
    levels = -full_scale_Nm + step * np.arange(2**bits)
    gain = (1.0 + hidden.gain_error) / (gear.efficiency * n * k_t)
    table = soft_limit(gain * boost(levels), gear.current_limit_A)

    def rotor(t_s):
        level = np.clip(np.rint((t_s + hidden.sensor_offset_Nm + full_scale_Nm) / step), 0, 2**bits - 1)
        return k_t * table[level.astype(int)] - load

    width = n * k_t * gear.current_limit_A / gear.back_efficiency + 10.0
    low, high = y - width, y + width
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (low + high)
        o = rotor(mid)
        above = mid + n * o * worm_factor(o, road.column_rate, gear, quirk) >= y
        high, low = np.where(above, mid, high), np.where(above, low, mid)
    ts = high
    delivered = y - ts
    # the rotor-side torque that delivers it: the factor read from the sign of what it delivers
    o = delivered / (n * worm_factor(delivered, road.column_rate, gear, quirk))
    return QuirkSolution(ts, (o + load) / k_t)


def quirk_eps_clean(road: Road, boost: TruthMap, gear: TruthGear, quirk: EpsQuirk, logger: TruthLogger,
                    hidden: Hidden = Hidden(), params: Parameters | None = None) -> dict[str, np.ndarray]:
    """The clean channels over `road` (as :func:`parksteer.synthetic.column_eps_layer.truth_clean` gives them, for
    :func:`~parksteer.synthetic.assisted_truth.truth_record`): the torsion-bar channel through the sensor's filter,
    and with `params` the handwheel angle (the column's plus the twist of the torsion bar and the column)."""
    solution = quirk_layer(road, boost, gear, quirk, logger.torque_step, logger.torque_full_scale_Nm, hidden)
    reading = sensor_filtered(road.time_s, solution.torsion_bar_Nm + hidden.sensor_offset_Nm,
                              quirk.sensor_time_constant_s)
    out = {"time_s": road.time_s, "rack_m": road.rack_m, TORQUE: reading,
           "motor_current_A": solution.current_A}
    if params is not None:
        out["handwheel_angle_rad"] = handwheel_angle(road, solution.torsion_bar_Nm, gear, params)
    return out


__all__ = ["BACK_EFFICIENCY_BAND", "EpsQuirk", "QuirkSolution", "drawn_back_efficiency", "quirk_eps_clean",
           "quirk_layer", "sensor_filtered", "soft_limit", "worm_factor"]
