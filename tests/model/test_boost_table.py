"""Boost tables and the back-driven gear: physics checks of the electric assist's table law and of its gear's
efficiency in both directions of power flow."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator
from scipy.integrate import cumulative_trapezoid
from scipy.optimize import brentq

from model_helpers import first_ramp

from parksteer.boost_table import BoostTableError, check_table, entries
from parksteer.model.numeric.simulate import simulate
from parksteer.model.symbolic.components import with_effect_quantities
from parksteer.model.symbolic.effects.assist_common import directional_efficiency, table_law


@pytest.fixture(scope="module")
def params(params):
    """The shipped parameters, knowing the installed effects' quantities (the assists' own, read below)."""
    return with_effect_quantities(params)


# A progressive curve, 3.9 (|T| - 0.4)^1.6 N m beyond a 0.4 N m dead band (the Polo file's).
TORQUES = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.5, 3.0, 4.0]
ASSIST = [0.0, 0.0, 0.9, 2.73, 5.22, 8.27, 12.78, 18.0, 30.3]
NAME = "electric_assist_column"


def law(values: dict, torque, speed=0.0):
    return table_law(np.asarray(torque, dtype=float), values.__getitem__, speed)


def as_overrides(values: dict, name: str = NAME) -> dict:
    """The table's scalars as overrides of `name`, the straight line's gain off."""
    return {**{f"{name}.{k}": v for k, v in values.items()}, f"{name}.gain": 0.0}


def test_table_law_takes_its_points_exactly_and_is_monotone_odd_and_zero_in_the_dead_band():
    """A calibration table is what the control unit commands at its points: the law gives each point's assist
    exactly (bit for bit), rises between them (Fritsch-Carlson), is odd (a left turn is a mirrored right turn) and
    is exactly zero inside the dead band, not merely small."""
    values = entries(TORQUES, None, [ASSIST])
    at_points = law(values, TORQUES)
    assert list(at_points) == ASSIST
    assert list(law(values, [-t for t in TORQUES])) == [-a for a in ASSIST]
    t = np.linspace(-6.0, 6.0, 24001)
    a = law(values, t)
    assert np.all(np.diff(a) >= 0.0)
    assert np.all(np.diff(a[np.abs(t) > 0.4]) > 0.0)  # strictly beyond the dead band: the inversion is sound
    assert np.array_equal(a, -law(values, -t))
    assert np.all(a[np.abs(t) <= 0.4] == 0.0)
    # the same curve as an independent monotone cubic through the mirrored points (SciPy's PCHIP)
    reference = PchipInterpolator([-x for x in TORQUES[:0:-1]] + TORQUES, [-y for y in ASSIST[:0:-1]] + ASSIST)
    inside = np.abs(t) <= TORQUES[-1]
    assert np.max(np.abs(a[inside] - reference(t[inside]))) < 1e-12


def test_the_numbers_take_one_segment_per_sample_and_give_the_piecewise_law_bit_for_bit():
    """The replay evaluates the table on numbers by finding each sample's segment; the generated C evaluates the
    piecewise form (every segment's condition in turn). On random monotone tables and torques across and beyond
    the points (the points themselves, both signs, zero) the two are the same numbers, bit for bit."""
    from parksteer.model.symbolic.effects.assist_common import MAX_POINTS, _hermite, _select

    rng = np.random.default_rng(7)
    for _ in range(50):
        knots = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 1.0, MAX_POINTS - 1))])
        assist = np.concatenate([[0.0], np.cumsum(rng.uniform(0.0, 5.0, MAX_POINTS - 1))])
        slope = rng.uniform(0.0, 5.0, MAX_POINTS)
        x = np.concatenate([rng.uniform(-1.3, 1.3, 500) * knots[-1], knots, -knots, [0.0]])
        branches = [(np.abs(x) < knots[k + 1], _hermite(np.abs(x), knots[k], knots[k + 1], assist[k], assist[k + 1],
                                                          slope[k], slope[k + 1])) for k in range(MAX_POINTS - 1)]
        half = _select(branches, assist[-1] + slope[-1] * (np.abs(x) - knots[-1]))
        piecewise = np.where(x >= 0, half, -half)
        fast = table_law(x, None, 0.0, points=(list(knots), list(assist), list(slope)))
        assert np.array_equal(fast, piecewise)


def test_one_straight_segment_is_todays_linear_law():
    """A table of two points (0, 0) and (T_1, A_1) is the straight line of gain A_1 / T_1 (no dead band), on both
    sides of zero and beyond the point."""
    values = entries([0.0, 2.0], None, [[0.0, 12.0]])
    t = np.linspace(-10.0, 10.0, 401)
    assert np.max(np.abs(law(values, t) - 6.0 * t)) < 1e-12


def test_two_row_speed_map_is_linear_in_speed():
    """A map with one row per vehicle speed is read, between the rows, as the linear interpolation in speed of the
    two rows' curves (and as the nearer row beyond them): a car creeping at 2 km/h between rows at 0 and 5 km/h gets
    60 % of the first row and 40 % of the second at every torque."""
    slow = ASSIST
    fast = [0.0, 0.0, 0.5, 1.5, 3.0, 5.0, 8.0, 11.0, 19.0]
    speeds = [0.0, 5.0 / 3.6]
    values = entries(TORQUES, speeds, [slow, fast])
    t = np.linspace(-5.0, 5.0, 1001)
    row0, row1 = law(values, t, 0.0), law(values, t, speeds[1])
    between = law(values, t, 2.0 / 3.6)
    assert np.max(np.abs(between - (0.6 * row0 + 0.4 * row1))) < 1e-12
    assert np.array_equal(law(values, t, 10.0), row1)
    assert np.array_equal(law(values, TORQUES, speeds[1]), np.array(fast))


def test_tables_that_are_not_boost_curves_are_refused():
    """A boost curve starts at (0, 0), never falls and rises strictly once it has left its dead band."""
    for torques, rows in (([0.0, 1.0, 1.0], [[0.0, 1.0, 2.0]]), ([0.0, 1.0, 2.0], [[0.0, 2.0, 1.0]]),
                          ([0.0, 1.0, 2.0], [[0.0, 1.0, 1.0]]), ([0.5, 1.0], [[0.0, 1.0]]),
                          ([0.0, 1.0], [[0.0, 0.0]])):
        with pytest.raises(BoostTableError):
            check_table(torques, None, rows)


def test_quasi_static_driver_torque_solves_t_plus_a_of_t_equals_the_road_torque(params):
    """Quasi-statically the column carries the road torque as torsion-bar torque plus assist: T + A(T) = T_road. For
    the progressive table, a lossless gear (eta_f = eta_b = 1: the motor's torque through N is the table's assist
    either way), an ideal motor and the Hooke joint straight, the driver's torque on the slow steer to the right is
    the root of that equation, solved here by hand (Brent's method on SciPy's PCHIP through the mirrored points)
    from the manual car's torque at the same rack position, within 1 %."""
    from test_assist import STRAIGHT, series_column

    manual = simulate("unladen", overrides={**series_column(params, NAME), **STRAIGHT}, params=params)
    gear = {f"{NAME}.motor_inertia": 0.0, f"{NAME}.motor_friction_torque": 0.0, f"{NAME}.efficiency": 1.0,
            f"{NAME}.back_efficiency": 1.0, f"{NAME}.motor_torque_limit": 30.0}
    assisted = simulate("unladen", effects=f"+{NAME}",
                        overrides={**gear, **as_overrides(entries(TORQUES, None, [ASSIST])), **STRAIGHT},
                        params=params)
    ramp, at = first_ramp(manual), first_ramp(assisted)
    road = np.interp(assisted.columns["rack_m"][at], manual.columns["rack_m"][ramp],
                     manual.columns["handwheel_torque_Nm"][ramp])
    curve = PchipInterpolator([-x for x in TORQUES[:0:-1]] + TORQUES, [-y for y in ASSIST[:0:-1]] + ASSIST)
    hand = np.array([brentq(lambda x, y=y: x + curve(x) - y, -10.0, 10.0) for y in road])
    got = assisted.columns["handwheel_torque_Nm"][at]
    assert np.max(np.abs(road)) > 10.0 and np.min(hand) > 0.4  # the steer reaches well into the progressive part
    assert np.max(np.abs(got / hand - 1.0)) < 0.01


def test_directional_efficiency_never_creates_power():
    """The gear delivers eta_f of the motor's power when the motor drives and asks 1 / eta_b of it from the rack
    when the rack drives the motor; through the smoothing the loss, motor power x (1 - factor), is never
    negative."""
    motor = np.linspace(-3.0, 3.0, 601)[:, None]
    speed = np.linspace(-0.05, 0.05, 401)[None, :]
    factor = directional_efficiency(motor, speed, 0.85, 0.8, 0.05, 1000.0)
    power = motor * speed  # sign of the motor's power (the rotor turns with the rack)
    assert np.all(power * (1.0 - factor) >= 0.0)
    assert directional_efficiency(3.0, 0.05, 0.85, 0.8, 0.05, 1000.0) == pytest.approx(0.85, abs=1e-3)
    assert directional_efficiency(3.0, -0.05, 0.85, 0.8, 0.05, 1000.0) == pytest.approx(1 / 0.8, abs=1e-3)


def test_over_a_closed_cycle_the_gear_dissipates_and_is_back_driven_after_each_reversal(params):
    """Energy: the gear's loss is the motor's power into it less the power it delivers at the column,
    T_m N w - A w (w the column rate). On the lock-to-lock cycle of the Polo-like progressive assist it is never
    negative at any sample and positive over the cycle, and part of the cycle is back-driven (the rack returning
    against the assist's torque after a reversal: the gear delivers more than eta_f N T_m there, up to N T_m /
    eta_b). A gear that kept eta_f both ways would create power in those samples."""
    overrides = as_overrides(entries(TORQUES, None, [ASSIST]))
    result = simulate("unladen", effects=f"+{NAME}", overrides=overrides, params=params)
    c = result.columns
    out = result.model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
    n = params[f"{NAME}.reduction_ratio"]
    rate = out["column_angle_per_rack_rad_per_m"] * c["rack_speed_m_s"]
    loss = c["motor_torque_Nm"] * n * rate - c["assist_torque_Nm"] * rate
    scale = np.max(np.abs(c["motor_torque_Nm"] * n * rate))
    assert np.min(loss) > -1e-9 * scale
    total = np.trapezoid(loss, c["time_s"])
    assert total > 0.0
    strong = np.abs(c["assist_torque_Nm"]) > 1.0
    factor = c["assist_torque_Nm"][strong] / (n * c["motor_torque_Nm"][strong])
    back = factor > 1.0
    assert 0.0 < np.mean(back) < 0.5
    constant = params[f"{NAME}.efficiency"] * n * c["motor_torque_Nm"]
    created = (c["motor_torque_Nm"] * n * rate - constant * rate)[strong][back]
    assert np.min(created) < 0.0


# The hydraulic valve's table: pressure (bar in the file, Pa in the model) against torsion-bar torque, progressive
# (the Golf IV file's shape, 9 (|T| - 0.4)^1.8 bar), read through a vehicle file as a user writes it.
HYDRAULIC = "hydraulic_assist"
VALVE_TORQUES = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.5, 3.0, 3.5]
VALVE_BAR = [0.0, 0.0, 1.7, 6.0, 12.5, 21.0, 34.2, 50.3, 69.0]


@pytest.fixture(scope="module")
def golf():
    from pathlib import Path

    from parksteer.vehicle import load_vehicle

    return load_vehicle(Path(__file__).resolve().parents[2] / "data" / "vehicles" / "golf_iv.toml")


def valve_curve():
    """An independent monotone cubic through the mirrored points, in Pa (SciPy's PCHIP)."""
    pa = [b * 1e5 for b in VALVE_BAR]
    return PchipInterpolator([-x for x in VALVE_TORQUES[:0:-1]] + VALVE_TORQUES, [-y for y in pa[:0:-1]] + pa)


def test_valve_table_from_bar_takes_its_points_and_is_monotone_odd_and_zero_in_the_dead_band(golf):
    """A rotary valve's characteristic given in bar is the pressure in Pa the piston sees: the vehicle file's
    table gives each point's pressure exactly (bar x 1e5), rises between them, is odd (a left turn is a mirrored
    right one) and exactly zero inside the valve's open centre; the valve's straight line is off (slope 0); the
    replay's law (the valve below its relief) is the same curve as an independent monotone cubic, to 1e-9
    relative."""
    from parksteer.model.numeric.assisted import BoostLaw
    from parksteer.boost_table import table_keys

    values = {k: golf[f"{HYDRAULIC}.{k}"] for k in table_keys()}
    assert golf[f"{HYDRAULIC}.valve_slope"] == 0.0
    assert list(law(values, VALVE_TORQUES)) == [b * 1e5 for b in VALVE_BAR]
    t = np.linspace(-5.0, 5.0, 20001)
    p = law(values, t)
    assert np.all(np.diff(p) >= 0.0) and np.all(np.diff(p[np.abs(t) > 0.4]) > 0.0)
    assert np.array_equal(p, -law(values, -t)) and np.all(p[np.abs(t) <= 0.4] == 0.0)
    inside = np.abs(t) <= VALVE_TORQUES[-1]
    assert np.max(np.abs(p[inside] - valve_curve()(t[inside]))) < 1e-9 * 69e5
    replay = BoostLaw(HYDRAULIC, "rack", 0.0, 0.5, 0.05, 3.0e7, 5.0e4, 131.4, area=8e-4,
                      table=tuple(values[k] for k in table_keys()))
    assert np.max(np.abs(replay.motor(t[inside]) - p[inside])) < 1e-3 * 69e5  # the relief's smoothing only


def test_quasi_static_driver_torque_with_a_progressive_valve_solves_t_plus_a_of_t(golf):
    """Quasi-statically the pinion carries the road torque as torsion-bar torque plus the piston's push through the
    gear: T + a_p p(T) / G_hr = T_road (a_p the piston area, G_hr the handwheel-to-rack ratio). On the hydraulic
    Golf with its progressive valve table, seals without friction, the relief out of reach and the Hooke joint
    straight, the driver's torque on the slow steer to the right is the root of that equation, solved by hand
    (Brent's method on SciPy's PCHIP through the table's points) from the manual car's torque at the same rack
    position, within 1 %."""
    from test_assist import STRAIGHT, series_column

    manual = simulate("kerb", overrides={**series_column(golf, HYDRAULIC), **STRAIGHT}, params=golf)
    ideal = {f"{HYDRAULIC}.seal_friction_force": 0.0, f"{HYDRAULIC}.relief_pressure": 3.0e7, **STRAIGHT}
    assisted = simulate("kerb", effects=f"+{HYDRAULIC}", overrides=ideal, params=golf)
    ramp, at = first_ramp(manual), first_ramp(assisted)
    road = np.interp(assisted.columns["rack_m"][at], manual.columns["rack_m"][ramp],
                     manual.columns["handwheel_torque_Nm"][ramp])
    gain = golf[f"{HYDRAULIC}.piston_area"] / golf["steering.handwheel_to_rack_ratio"]
    curve = valve_curve()
    hand = np.array([brentq(lambda x, y=y: x + gain * curve(x) - y, -10.0, 10.0) for y in road])
    got = assisted.columns["handwheel_torque_Nm"][at]
    assert np.max(np.abs(road)) > 10.0 and np.min(hand) > 0.8  # well into the progressive part
    assert np.max(np.abs(got / hand - 1.0)) < 0.01


def test_over_a_closed_cycle_the_valve_adds_no_net_work_to_a_lossless_car(golf):
    """Energy: without friction or dampers (air bearings, seals without friction) the driver's work plus the
    piston's (the pump's) equals the change of kinetic and potential energy at every instant, with the valve's
    table as its law; and the valve, whose pressure is a function of the torsion-bar torque alone, can put no net
    work into a car that stores all it is given: over the closed lock-to-lock cycle (back at the centre at 18 s)
    the pump's net work is below 0.1 % of the work it moves in and out."""
    from model_helpers import DISSIPATION_OFF

    overrides = {**DISSIPATION_OFF, f"{HYDRAULIC}.seal_friction_force": 0.0}
    result = simulate("kerb", effects=f"+{HYDRAULIC}", overrides=overrides, surface="air_bearing", params=golf,
                      output_dt_s=0.002, rtol=1e-10)
    c = result.columns
    out = result.model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
    energy = out["kinetic_energy_J"] + out["potential_energy_J"] + out["column_energy_J"]
    power = c["assist_force_N"] * c["rack_speed_m_s"]
    driver = cumulative_trapezoid(c["handwheel_torque_Nm"] * c["handwheel_rate_rad_s"], c["time_s"], initial=0.0)
    pump = cumulative_trapezoid(power, c["time_s"], initial=0.0)
    gross = np.trapezoid(np.abs(power), c["time_s"])
    assert c["time_s"][-1] >= 18.0 and abs(c["rack_m"][-1]) < 1e-3 * np.max(np.abs(c["rack_m"]))
    assert np.max(np.abs(c["pressure_Pa"])) > 2e5  # the valve opens into its table
    assert np.max(np.abs(driver + pump - (energy - energy[0]))) < 1e-4 * gross
    assert abs(pump[-1]) < 1e-3 * gross


def test_a_production_sized_map_of_17_points_and_5_speeds_drives_the_motor_as_the_map_says(params):
    """A control unit's map carries more points than a hand-written curve: 17 torsion-bar torques (a 0.4 N m dead
    band, then a progressive rise to 6.4 N m) and 5 vehicle-speed rows (the assist falling with speed). Simulated on
    the paper's car at 1.5 m/s, between the rows at 1 and 2 m/s, the commanded motor torque against the torsion-bar
    torque is the two rows' monotone cubics (SciPy's PCHIP through each row's mirrored points) mixed half and half,
    over eta N, within 1 % wherever the motor gives more than 0.05 N m; the steer reaches past the tenth point."""
    from test_assist import series_column

    torques = [0.4 * k for k in range(17)]
    speeds = [0.0, 0.5, 1.0, 2.0, 3.0]
    scales = [1.0, 0.95, 0.85, 0.7, 0.6]
    rows = [[0.0] + [scale * 1.5 * (t - 0.4) ** 1.6 for t in torques[1:]] for scale in scales]
    gear = {f"{NAME}.motor_torque_limit": 30.0, "run.vehicle_speed": 1.5}
    result = simulate("unladen", effects=f"+{NAME}",
                      overrides={**series_column(params, NAME), **gear, **as_overrides(entries(torques, speeds, rows))},
                      params=params)
    c = result.columns

    def pchip(row):
        return PchipInterpolator([-x for x in torques[:0:-1]] + torques, [-y for y in row[:0:-1]] + row)

    sensor = c["torsion_bar_torque_Nm"]
    expected = 0.5 * (pchip(rows[2])(sensor) + pchip(rows[3])(sensor))
    scale = params[f"{NAME}.efficiency"] * params[f"{NAME}.reduction_ratio"]
    used = np.abs(expected / scale) > 0.05
    assert np.max(np.abs(sensor)) > torques[10]
    assert np.max(np.abs(c["motor_torque_Nm"][used] * scale / expected[used] - 1.0)) < 0.01


def test_the_slope_the_jacobian_takes_is_the_laws_derivative():
    """The generated C's Jacobian takes the table law's torque derivative from table_slope (the Hermite segment's
    derivative in closed form): on a 17-point, 5-row map at a speed between rows it is the law's central
    difference within 1e-5 (the difference's own error) across the dead band, the points and beyond the last."""
    from parksteer.model.symbolic.effects.assist_common import table_slope

    torques = [0.4 * k for k in range(17)]
    rows = [[0.0] + [s * 1.5 * (t - 0.4) ** 1.6 for t in torques[1:]] for s in (1.0, 0.95, 0.85, 0.7, 0.6)]
    values = entries(torques, [0.0, 0.5, 1.0, 2.0, 3.0], rows)
    t = np.linspace(-8.0, 8.0, 3201) + 1e-3  # off the points, where the cubic's second derivative jumps
    h = 1e-6
    difference = (law(values, t + h, 1.5) - law(values, t - h, 1.5)) / (2 * h)
    assert np.max(np.abs(difference - table_slope(t, values.__getitem__, 1.5))) < 1e-5


def test_the_replays_boost_law_reads_its_table_as_table_law_does_bit_for_bit(golf):
    """The replay's boost law reads its table from points found once per table and speed (shared by every replay
    of a diagnosis) and evaluated without table_law's per-call check for symbols: at torques across and beyond
    the table, at a vehicle speed between rows, its motor demand is table_law's (plus the straight line), bit for
    bit, and a second law of the same table and speed shares the first one's points."""
    from parksteer.boost_table import table_keys
    from parksteer.model.numeric.assisted import BoostLaw
    from parksteer.model.numeric.boost_numeric import points_at_speed
    from parksteer.model.symbolic.effects.assist_common import clamp

    values = {k: golf[f"{HYDRAULIC}.{k}"] for k in table_keys()}
    table = tuple(values[k] for k in table_keys())
    t = np.concatenate([np.linspace(-6.0, 6.0, 4001), VALVE_TORQUES, [-x for x in VALVE_TORQUES]])
    for speed in (0.0, 0.7):
        first = BoostLaw(HYDRAULIC, "rack", 0.0, 0.5, 0.05, 3.0e7, 5.0e4, 131.4, area=8e-4, table=table, speed=speed)
        second = BoostLaw(HYDRAULIC, "rack", 0.0, 0.5, 0.05, 3.0e7, 5.0e4, 131.4, area=8e-4, table=table, speed=speed)
        first._table_points  # noqa: B018 (read: the points of this table and speed cached)
        hits = points_at_speed.cache_info().hits
        second._table_points  # noqa: B018 (another law of the same table and speed)
        assert points_at_speed.cache_info().hits == hits + 1
        opening = np.zeros_like(t)  # valve slope 0: the table alone
        expected = clamp(opening + 1.0 * table_law(t, values.__getitem__, speed), first.limit, first.limit_width)
        assert np.asarray(first.motor(t)).tobytes() == np.asarray(expected).tobytes()
