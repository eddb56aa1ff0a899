"""Power assistance (electric at the column, pinion or rack; hydraulic): physics checks of the assist effects."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from model_helpers import DISSIPATION_OFF, first_ramp

from parksteer.errors import UsageError
from parksteer.model.numeric.simulate import simulate
from parksteer.model.symbolic.components import resolve_effects, with_effect_quantities
from parksteer.vehicle import creeping_overrides


@pytest.fixture(scope="module")
def params(params):
    """The shipped parameters, knowing the installed effects' quantities (the assists' own, read below)."""
    return with_effect_quantities(params)


ELECTRIC = ("electric_assist_column", "electric_assist_pinion", "electric_assist_rack")
K_COLUMN, C_COLUMN = "steering.column_torsional_stiffness", "steering.column_torsional_damping"
# The Hooke joint at zero angle: a straight shaft, its ratio 1 at every angle, so the column and the pinion carry
# the same torque (the closed forms' premise), in the models the package ships with the joint.
STRAIGHT = {"steering.hooke_joint_angle": 0.0}


def series_column(params, name: str) -> dict:
    """The manual column that is the assisted one's column shaft and torsion bar in series (stiffness and the
    damping that keeps the column's time constant)."""
    k_c, c_c = params[K_COLUMN], params[C_COLUMN]
    k_t = params[f"{name}.torsion_bar_stiffness"]
    k_s = k_c * k_t / (k_c + k_t)
    return {K_COLUMN: k_s, C_COLUMN: c_c * k_s / k_c}


def motor_off(name: str) -> dict:
    """A motor without inertia or friction and without a dead band (the ideal assist of the closed forms)."""
    return {f"{name}.motor_inertia": 0.0, f"{name}.motor_friction_torque": 0.0, f"{name}.dead_band": 0.0}


@pytest.fixture(scope="module")
def manual_series(params):
    """The paper's car with the column of the column assist (its torsion bar in series) and no assist."""
    return simulate("unladen", overrides=series_column(params, "electric_assist_column"), params=params)


def test_zero_gain_assist_is_the_manual_steering(params, manual_series):
    """A motor that never pushes (gain 0) and has neither inertia nor friction adds no torque: the handwheel
    torque is the manual steering's with the same column (shaft and torsion bar in series), sample for sample
    (to the integrator's tolerance: the two models are the same equations written differently)."""
    name = "electric_assist_column"
    assisted = simulate("unladen", effects=f"+{name}", overrides={**motor_off(name), f"{name}.gain": 0.0},
                        params=params)
    manual = manual_series.columns["handwheel_torque_Nm"]
    torque = assisted.columns["handwheel_torque_Nm"]
    assert np.max(np.abs(assisted.columns["motor_torque_Nm"])) == 0.0  # exactly no assist
    assert np.max(np.abs(torque - manual)) < 1e-4 * np.max(np.abs(manual))
    # and the torsion bar carries the handwheel torque (series elements carry one torque)
    assert np.array_equal(assisted.columns["torsion_bar_torque_Nm"], torque)


@pytest.mark.slow  # six cycles, one model per assist location: started early
@pytest.mark.parametrize("name", ELECTRIC)
def test_linear_boost_divides_the_driver_torque_by_one_plus_gain(params, name):
    """Quasi-statically the gear carries the road load as torsion-bar torque plus assist, T_s (1 + G) = T_road,
    so with no dead band and the motor below its limit the driver's torque on the slow steer to the right is the
    manual car's divided by 1 + G, at every point of action (the Hooke joint straight, :data:`STRAIGHT`: pinion
    and column carry the same torque)."""
    gain = 4.0
    manual = simulate("unladen", overrides={**series_column(params, name), **STRAIGHT}, params=params)
    assisted = simulate("unladen", effects=f"+{name}",
                        overrides={**motor_off(name), f"{name}.gain": gain, f"{name}.motor_torque_limit": 30.0,
                                   **STRAIGHT}, params=params)
    ramp, at = first_ramp(manual), first_ramp(assisted)
    # at the same rack position (the softer assisted column lags a little differently in time)
    manual_torque = np.interp(assisted.columns["rack_m"][at], manual.columns["rack_m"][ramp],
                              manual.columns["handwheel_torque_Nm"][ramp])
    got = assisted.columns["handwheel_torque_Nm"][at]
    assert np.max(np.abs(got * (1 + gain) / manual_torque - 1)) < 0.01
    # the rack force is the manual steering's: the gear pushes as hard, the motor taking G/(1+G) of it
    rack_manual = manual_torque * params["steering.handwheel_to_rack_ratio"]
    assert np.max(np.abs(assisted.columns["rack_force_N"][at] / rack_manual - 1)) < 0.01


def test_saturated_assist_leaves_the_unassisted_slope(params, manual_series):
    """At its torque limit the motor gives a constant eta N T_max at the column: the driver's torque is the manual
    torque less that constant, so it rises and falls with the road load at the unassisted slope (wherever the
    motor is saturated)."""
    name = "electric_assist_column"
    limit = 0.5
    assisted = simulate("unladen", effects=f"+{name}",
                        overrides={**motor_off(name), f"{name}.gain": 20.0, f"{name}.motor_torque_limit": limit},
                        params=params)
    c, m = assisted.columns, manual_series.columns
    at, ramp = first_ramp(assisted), first_ramp(manual_series)
    assert np.all(np.abs(c["motor_torque_Nm"][at]) > 0.99 * limit)  # the motor is at its limit throughout
    offset = params[f"{name}.efficiency"] * params[f"{name}.reduction_ratio"] * limit
    # at the same rack position (the two columns twist by different amounts for the same handwheel angle)
    manual_torque = np.interp(c["rack_m"][at], m["rack_m"][ramp], m["handwheel_torque_Nm"][ramp])
    difference = manual_torque - c["handwheel_torque_Nm"][at]
    assert np.max(np.abs(difference - offset)) < 0.01 * offset
    # so the slopes against the rack are the same
    slope_assisted = np.polyfit(c["rack_m"][at], c["handwheel_torque_Nm"][at], 1)[0]
    slope_manual = np.polyfit(m["rack_m"][ramp], m["handwheel_torque_Nm"][ramp], 1)[0]
    assert abs(slope_assisted - slope_manual) < 0.02 * abs(slope_manual)


@pytest.mark.parametrize("name", ("electric_assist_column", "electric_assist_rack"))
def test_energy_balance_with_the_motor_as_a_source(params, name):
    """Without friction and dampers (air bearings), the driver's work at the handwheel plus the work the motor
    delivers through its gear (eta T_m times the rotor speed: the assist at its point of action times that
    point's speed) equals the change of kinetic energy (rotor included) and potential energy (the torsion bar in
    the column spring's energy); the motor's own loss (1 - eta) of its work is outside the mechanical system."""
    overrides = {**DISSIPATION_OFF, **motor_off(name), f"{name}.gain": 3.0, f"{name}.motor_inertia": 3e-4}
    result = simulate("unladen", effects=f"+{name}", overrides=overrides, surface="air_bearing", params=params,
                      t_end_s=3.0, output_dt_s=0.0005, rtol=1e-10)
    c = result.columns
    out = result.model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
    energy = out["kinetic_energy_J"] + out["potential_energy_J"] + out["column_energy_J"]
    if name.endswith("rack"):
        assist_power = c["assist_force_N"] * c["rack_speed_m_s"]
    else:
        assist_power = c["assist_torque_Nm"] * out["column_angle_per_rack_rad_per_m"] * c["rack_speed_m_s"]
    driver = cumulative_trapezoid(c["handwheel_torque_Nm"] * c["handwheel_rate_rad_s"], c["time_s"], initial=0.0)
    motor = cumulative_trapezoid(assist_power, c["time_s"], initial=0.0)
    assert motor[-1] > 0.5 * driver[-1] > 0  # the motor does a real share of the lifting
    assert np.max(np.abs(driver + motor - (energy - energy[0]))) < 1e-4 * (driver[-1] + motor[-1])


def test_a_prescribed_rack_cannot_drive_an_assisted_car(params):
    """The rack-driven solve takes the column torque as its unknown, linear in the equations; an assist feeds that
    torque back through its boost curve, so the solve is refused in one line instead of solving the wrong
    equations (an assisted car is driven by its handwheel angle)."""
    from parksteer.measure.rack_spline import interpolate_rack

    t = np.linspace(0.0, 2.0, 21)
    with pytest.raises(UsageError, match="a prescribed rack cannot drive the effects .*electric_assist_column"):
        simulate("unladen", effects="+electric_assist_column", params=params,
                 rack_drive=interpolate_rack(t, 0.01 * t))


def test_bad_combinations_are_refused_in_one_line():
    """Two assists in one set, or an assist with the rack lash (both shape the column's spring), are refused."""
    with pytest.raises(UsageError, match="both fill the slot column_deflection"):
        resolve_effects("+electric_assist_column,+electric_assist_rack")
    with pytest.raises(UsageError, match="both fill the slot column_deflection"):
        resolve_effects("+electric_assist_pinion,+rack_lash")


HYDRAULIC = "hydraulic_assist"
VALVE_IDEAL = {f"{HYDRAULIC}.seal_friction_force": 0.0, f"{HYDRAULIC}.dead_band": 0.0}


def test_closed_valve_is_the_manual_steering(params):
    """A valve that never builds pressure (slope 0) and seals without friction add no torque: the handwheel
    torque is the manual steering's with the valve's torsion bar in series with the column."""
    manual = simulate("unladen", overrides=series_column(params, HYDRAULIC), params=params)
    assisted = simulate("unladen", effects=f"+{HYDRAULIC}",
                        overrides={**VALVE_IDEAL, f"{HYDRAULIC}.valve_slope": 0.0}, params=params)
    assert np.max(np.abs(assisted.columns["pressure_Pa"])) == 0.0
    reference = manual.columns["handwheel_torque_Nm"]
    assert np.max(np.abs(assisted.columns["handwheel_torque_Nm"] - reference)) < 1e-4 * np.max(np.abs(reference))


def test_valve_slope_divides_the_driver_torque_by_one_plus_its_gain(params):
    """In the valve's linear range the piston adds A k_v T_s on the rack, a pinion torque A k_v T_s / G_hr: the
    driver's torque is the manual one divided by 1 + A k_v / G_hr (the Hooke joint straight)."""
    slope = 1.0e6
    gain = params[f"{HYDRAULIC}.piston_area"] * slope / params["steering.handwheel_to_rack_ratio"]
    manual = simulate("unladen", overrides={**series_column(params, HYDRAULIC), **STRAIGHT}, params=params)
    assisted = simulate("unladen", effects=f"+{HYDRAULIC}",
                        overrides={**VALVE_IDEAL, f"{HYDRAULIC}.valve_slope": slope,
                                   f"{HYDRAULIC}.relief_pressure": 3.0e7, **STRAIGHT}, params=params)
    ramp, at = first_ramp(manual), first_ramp(assisted)
    manual_torque = np.interp(assisted.columns["rack_m"][at], manual.columns["rack_m"][ramp],
                              manual.columns["handwheel_torque_Nm"][ramp])
    assert 2.0 < gain < 6.0  # a real division
    assert np.max(np.abs(assisted.columns["handwheel_torque_Nm"][at] * (1 + gain) / manual_torque - 1)) < 0.01


def test_relief_pressure_leaves_the_unassisted_slope(params):
    """At the relief pressure the piston pushes A p_relief, a constant pinion torque A p_relief / G_hr: the
    driver's torque is the manual one less that constant, at the unassisted slope."""
    relief = 1.0e6
    manual = simulate("unladen", overrides={**series_column(params, HYDRAULIC), **STRAIGHT}, params=params)
    assisted = simulate("unladen", effects=f"+{HYDRAULIC}",
                        overrides={**VALVE_IDEAL, f"{HYDRAULIC}.valve_slope": 2.0e7,
                                   f"{HYDRAULIC}.relief_pressure": relief, **STRAIGHT}, params=params)
    c, m = assisted.columns, manual.columns
    at, ramp = first_ramp(assisted), first_ramp(manual)
    assert np.all(c["pressure_Pa"][at] > 0.99 * relief)
    offset = params[f"{HYDRAULIC}.piston_area"] * relief / params["steering.handwheel_to_rack_ratio"]
    manual_torque = np.interp(c["rack_m"][at], m["rack_m"][ramp], m["handwheel_torque_Nm"][ramp])
    assert np.max(np.abs(manual_torque - c["handwheel_torque_Nm"][at] - offset)) < 0.01 * offset


def test_energy_balance_with_the_pump_as_a_source(params):
    """Without friction and dampers (air bearings), the driver's work plus the piston's (A dp times the rack
    speed, the pump's hydraulic work) equals the change of kinetic and potential energy."""
    overrides = {**DISSIPATION_OFF, **VALVE_IDEAL}
    result = simulate("unladen", effects=f"+{HYDRAULIC}", overrides=overrides, surface="air_bearing", params=params,
                      t_end_s=3.0, output_dt_s=0.0005, rtol=1e-10)
    c = result.columns
    out = result.model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
    energy = out["kinetic_energy_J"] + out["potential_energy_J"] + out["column_energy_J"]
    driver = cumulative_trapezoid(c["handwheel_torque_Nm"] * c["handwheel_rate_rad_s"], c["time_s"], initial=0.0)
    pump = cumulative_trapezoid(c["assist_force_N"] * c["rack_speed_m_s"], c["time_s"], initial=0.0)
    assert pump[-1] > 0.5 * driver[-1] > 0
    assert np.max(np.abs(driver + pump - (energy - energy[0]))) < 1e-4 * (driver[-1] + pump[-1])


COLUMN = "electric_assist_column"


def test_speed_dependent_gain_at_standstill_is_todays_boost_exactly(params):
    """A speed-sensitive boost curve gives its full (parking) gain at standstill: at v = 0 the curve with the
    speed dependence on is today's speed-independent one, and with it off the speed changes nothing, sample for
    sample and bit for bit (the falloff term is 0 exactly, 1 + 0 = 1)."""
    base = {f"{COLUMN}.gain_half_speed": 0.5}  # a steep fall, so a slip of the speed would show at once
    today = simulate("unladen", effects=f"+{COLUMN}", overrides=base, params=params)
    at_rest = simulate("unladen", effects=f"+{COLUMN}",
                       overrides={**base, f"{COLUMN}.speed_dependence": 1.0, **creeping_overrides(0.0)}, params=params)
    moving_off = simulate("unladen", effects=f"+{COLUMN}", overrides={**base, **creeping_overrides(5.0)}, params=params)
    for column in ("handwheel_torque_Nm", "motor_torque_Nm", "rack_m"):
        assert np.array_equal(at_rest.columns[column], today.columns[column])
        assert np.array_equal(moving_off.columns[column], today.columns[column])


def test_gain_at_the_half_speed_halves_the_assist_ratio(params):
    """At v = v_half the boost curve's gain is half the parking gain: below the motor's limit and without a dead
    band the motor gives G/2 times the torsion-bar torque, and quasi-statically the driver's torque is the road
    torque over 1 + G/2 (the manual car with the same column), against 1 + G at standstill. The model holds no
    rolling tyre here (no turn_slip), so the road torque is the same at both speeds and only the gain moves."""
    gain, half_speed = 6.0, 1.5  # m/s
    ideal = {**motor_off(COLUMN), f"{COLUMN}.gain": gain, f"{COLUMN}.motor_torque_limit": 30.0,
             f"{COLUMN}.speed_dependence": 1.0, f"{COLUMN}.gain_half_speed": half_speed}
    manual = simulate("unladen", overrides={**series_column(params, COLUMN), **STRAIGHT}, params=params)
    ramp = first_ramp(manual)
    for speed, expected_gain in ((0.0, gain), (half_speed, gain / 2)):
        assisted = simulate("unladen", effects=f"+{COLUMN}",
                            overrides={**ideal, "run.vehicle_speed": speed, **STRAIGHT}, params=params)
        c, at = assisted.columns, first_ramp(assisted)
        ratio = c["assist_torque_Nm"][at] / c["torsion_bar_torque_Nm"][at]
        assert np.max(np.abs(ratio / expected_gain - 1)) < 1e-3
        road = np.interp(c["rack_m"][at], manual.columns["rack_m"][ramp], manual.columns["handwheel_torque_Nm"][ramp])
        assert np.max(np.abs(c["handwheel_torque_Nm"][at] * (1 + expected_gain) / road - 1)) < 0.01
