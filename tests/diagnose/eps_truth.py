"""A quasi-static column-EPS car written apart from the model's assist, for testing what is identified from a log.

The manual car of the vehicle file (the model without any assist) is replayed on a smooth lock-to-lock rack; on it,
at every sample, the torsion bar and a worm-gear motor share the column torque:

    T + e N k_t i(R) = y + N^2 J_m theta'' + N T_f sign(theta'),     R = round((T + o + n) / q) q,

T the bar's torque, R the control unit's reading of the sensor (offset o, white noise n, step q), i(R) the current it
commands by its own map, a power law beyond a dead band, i = a (|R| - D)^1.6 sign(R) (plus, for a record with
hysteresis, a friction-compensation current i_h sign(theta') that no map of R holds), e the worm's efficiency
(eta_f while the motor drives, 1 / eta_b when the column drives it), theta the column angle (the rack through the
ratio and the Hooke joint), T_f the motor's Coulomb friction and J_m its rotor. The bar's torque is found by
bisection; the log carries R and the current in 0.1 A steps, and the rack.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
POLO = ROOT / "data" / "vehicles" / "polo_vi.toml"


@dataclass(frozen=True)
class Truth:
    dead_band: float = 0.45  # N m
    coefficient: float = 9.0  # A / (N m)^1.6 beyond the dead band
    exponent: float = 1.6
    torque_constant: float = 0.055  # N m/A (the file says 0.05)
    efficiency: float = 0.85
    back_efficiency: float = 0.76  # the file says 0.80
    reduction: float = 18.0
    rotor_inertia: float = 3e-4  # kg m^2 (the file says 2e-4)
    motor_friction: float = 0.03  # N m at the motor
    offset: float = 0.04  # N m, the sensor's zero
    sensor_noise: float = 0.002  # N m RMS before the reading
    torque_step: float = 0.01  # N m (bus)
    current_step: float = 0.1  # A (bus)
    hysteresis_current: float = 0.0  # A, friction compensation in the direction of motion

    def current(self, reading: np.ndarray) -> np.ndarray:
        beyond = np.maximum(np.abs(reading) - self.dead_band, 0.0)
        return np.sign(reading) * self.coefficient * beyond ** self.exponent

    @property
    def product(self) -> float:
        return self.torque_constant * self.efficiency * self.reduction


def rack_cycle(params, rate_hz: float = 100.0, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A lock-to-lock cycle at parking pace: rest, out to 75 % of the right lock, a pause, across to the left, a
    pause, back to the centre, rest (cosine ramps, each turn about 1 turn of the wheel a second)."""
    lock = params["input.handwheel_lock_angle"] / params["steering.handwheel_to_rack_ratio"]
    x = 0.75 * lock
    legs = [(0.0, 1.0), (x, 3.0), (x, 0.6), (-x, 6.0), (-x, 0.6), (x, 6.0), (x, 0.6), (0.0, 3.0), (0.0, 1.0)]
    t = np.arange(0.0, sum(d for _, d in legs), 1.0 / rate_hz)
    rack = np.zeros_like(t)
    start, position = 0.0, 0.0
    for target, duration in legs:
        inside = (t >= start) & (t < start + duration)
        s = (t[inside] - start) / duration
        rack[inside] = position + (target - position) * (1 - np.cos(np.pi * s)) / 2
        start, position = start + duration, target
    rack[t >= start] = position
    return t, rack


def _solve(truth: Truth, rhs: np.ndarray, rate: np.ndarray, noise: np.ndarray, hysteresis: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """The bar's torque T with T + e N k_t i(R(T)) = rhs (bisection: the left side never falls in T), and the
    reading. Where the rounded reading jumps over the balance, no torque balances it exactly: the bar's torque
    sits at the level's edge and the sensor's noise picks the level the control unit reads (a quantised loop
    dithers about the balance), so that the balance holds on average, not always from one side."""
    def total(T, reading):
        motor = truth.torque_constant * (truth.current(reading) + hysteresis)
        e = np.where(motor * rate >= 0.0, truth.efficiency, 1.0 / truth.back_efficiency)
        return T + e * truth.reduction * motor

    def rounded(T, n):
        return np.round((T + truth.offset + n) / truth.torque_step) * truth.torque_step

    low, high = rhs - 60.0, rhs + 60.0
    for _ in range(80):
        mid = 0.5 * (low + high)
        above = total(mid, rounded(mid, 0.0)) > rhs
        high, low = np.where(above, mid, high), np.where(above, low, mid)
    return high, rounded(high, noise)


def truth_record(truth: Truth, path: Path, seed: int = 1, case: str = "kerb", angle_only: bool = False) -> Path:
    """Write the truth's record of the Polo's kerb cycle to `path` (native CSV, torsion-bar torque and current; the
    rack, or with `angle_only` the handwheel angle instead, as a car's bus has it: the column angle plus the twist of
    the column shaft and torsion bar in series, in 0.1 deg steps)."""
    from parksteer.diagnose.engine import ReplayEngine
    from parksteer.diagnose.problem import Problem, prepare_file
    from parksteer.measure.io import Measurement, write_measurement
    from parksteer.model.symbolic.components import resolve_effects
    from parksteer.vehicle import load_vehicle

    params = load_vehicle(POLO)
    t, rack = rack_cycle(params)
    clean = Measurement(None, {"time_s": t, "rack_m": rack, "handwheel_torque_Nm": np.zeros_like(t)},
                        {"case": case, "surface": "ground"})
    f = prepare_file(clean)
    engine = ReplayEngine(1)
    try:
        y = engine.replay(Problem([f], params), resolve_effects(None), 0).torque()
    finally:
        engine.close()
    from scipy.interpolate import CubicSpline

    from parksteer.geometry import pinion_angle_from_column

    # the column angle through the intermediate shaft's Hooke joint (the pinion's angle inverted on a fine grid)
    s = params.sections["steering"]
    joint = (s["hooke_joint_angle"], s["hooke_joint_phase"])
    grid = np.linspace(-1.2, 1.2, 20001) * params["input.handwheel_lock_angle"]
    column = np.interp(s["handwheel_to_rack_ratio"] * rack, pinion_angle_from_column(grid, *joint), grid)
    spline = CubicSpline(t, column)
    column_rate = spline(t, 1)
    column_accel = spline(t, 2)
    n = truth.reduction
    rhs = (y + n * n * truth.rotor_inertia * column_accel
           + n * truth.motor_friction * np.tanh(column_rate / 0.02))
    rng = np.random.default_rng(seed)
    noise = rng.normal(0.0, truth.sensor_noise, t.size)
    hysteresis = truth.hysteresis_current * np.tanh(column_rate / 0.05)
    bar, reading = _solve(truth, rhs, column_rate, noise, hysteresis)
    current = truth.current(reading) + hysteresis
    logged_current = np.round(current / truth.current_step) * truth.current_step
    position = {"rack_m": np.round(rack / 1e-5) * 1e-5}
    position_logger = {"bits_rack_m": "14", "full_scale_rack_m": f"{1e-5 * 16383 / 2:g}"}
    if angle_only:
        from parksteer.geometry import column_twist

        k_c, c_c = s["column_torsional_stiffness"], s["column_torsional_damping"]
        k_t = params["electric_assist_column.torsion_bar_stiffness"]
        series = k_c * k_t / (k_c + k_t)
        twist, _ = column_twist(t, bar, series, c_c * series / k_c)
        step = np.radians(0.1)
        position = {"handwheel_angle_rad": np.round((column + twist) / step) * step}
        position_logger = {"bits_handwheel_angle_rad": "16",
                           "full_scale_handwheel_angle_rad": f"{step * 65535 / 2:.9g}"}
    record = Measurement(None, {"time_s": t, **position,
                                "handwheel_torque_Nm": reading, "motor_current_A": logged_current},
                         {"case": case, "surface": "ground", "torque_sensor": "torsion_bar", "synthetic": "true",
                          "source": "tests/diagnose/eps_truth.py: a quasi-static column EPS over the manual replay",
                          # 0.01 N m and 0.1 A steps: 2 full_scale / (2**bits - 1)
                          "bits": "12", "full_scale_handwheel_torque_Nm": f"{truth.torque_step * 4095 / 2:g}",
                          "bits_motor_current_A": "12", "full_scale_motor_current_A":
                              f"{truth.current_step * 4095 / 2:g}", **position_logger})
    if angle_only:  # the native writer checks for a rack; the reader derives it from the angle
        from parksteer.measure.io import format_measurement

        path.write_text(format_measurement(record), encoding="utf-8")
    else:
        write_measurement(path, record, params)
    return path
