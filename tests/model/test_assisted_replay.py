"""The prescribed-rack solve of an assisted car (parksteer.model.numeric.assisted): a free simulation's rack gives
back its torsion-bar torque and motor current."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BPoly, PPoly

from parksteer import portable
from parksteer.boost_table import entries
from parksteer.measure.rack_spline import RackSpline
from parksteer.model.numeric.assisted import BoostLaw, solve_assisted
from parksteer.model.numeric.simulate import prepare, simulate
from parksteer.model.symbolic.components import discover_effects

CASES = [
    ("electric_assist_column", {}),
    ("electric_assist_pinion", {}),
    ("electric_assist_rack", {}),
    ("electric_assist_column", {"electric_assist_column.motor_torque_limit": 0.5}),  # saturated over the plateau
    ("hydraulic_assist", {}),
    # a progressive valve table (pressure in Pa against torsion-bar torque), the valve's straight line off
    ("hydraulic_assist", {"hydraulic_assist.valve_slope": 0.0, **{
        f"hydraulic_assist.{k}": v for k, v in entries([0.0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.5, 3.0, 3.5], None, [[
            b * 1e5 for b in (0.0, 0.0, 1.7, 6.0, 12.5, 21.0, 34.2, 50.3, 69.0)]]).items()}}),
    # creeping at the half-gain speed of a speed-dependent boost curve: the replay's law must use G(v) = G / 2
    ("electric_assist_column", {"electric_assist_column.speed_dependence": 1.0,
                                "electric_assist_column.gain_half_speed": 1.0, "run.vehicle_speed": 1.0}),
]


def exact_rack(result) -> RackSpline:
    """The C2 piecewise quintic through a free run's rack position, speed and acceleration at its samples."""
    model, n = result.model, result.model.n_q
    i = model.index("rack")
    c = result.columns
    acceleration = np.array([model.rhs(t, y, result.parameter_vector)[n + i] for t, y in zip(c["time_s"],
                                                                                            result.states)])
    bernstein = BPoly.from_derivatives(c["time_s"], np.column_stack([result.states[:, i], result.states[:, n + i],
                                                                     acceleration]))
    return RackSpline.from_ppoly(PPoly.from_bernstein_basis(bernstein))


@pytest.mark.slow  # builds a model of its own: started early, so that the workers end together
@pytest.mark.parametrize(("name", "overrides"), CASES, ids=["column", "pinion", "rack", "saturated", "hydraulic", "hydraulic_table", "speed_gain"])
def test_replayed_rack_gives_back_the_torsion_bar_torque_and_motor_current(params, name, overrides):
    """Independent paths: the free (handwheel-driven) integration of the assisted model, whose boost feeds the
    torsion-bar torque back into the load, and the boost-free solve of the same rack followed by the boost law
    inverted pointwise (T_s + A(T_s) = the road torque at the torsion bar). Their agreement checks the derivation:
    with the rack given, the model feels only the sum of the driver's and the motor's torque reduced to the rack,
    the rotor's inertia and friction being fixed by the rack's motion. Solved to convergence (rtol 1e-8), the
    replay gives the torsion-bar torque within 1e-4 N m (about 5e-6 N m found, of a 3 N m peak; 2e-5 N m of
    11 N m saturated) and the motor current within 1e-3 A (about 2e-5 A of 10-25 A); the hydraulic gear's
    pressure within 100 Pa of 3.4 MPa, its valve's progressive table read alike by the generated C and the
    replay."""
    free = simulate("unladen", effects=f"+{name}", overrides=overrides, params=params, output_dt_s=0.005, rtol=1e-8)
    c = free.columns
    t = np.round(np.arange(0.0, c["time_s"][-1] + 1e-9, 0.01), 12)
    run = prepare("unladen", f"+{name}", overrides, params=params)
    solution = solve_assisted(run, run.p, exact_rack(free), t, rtol=1e-8, atol_factor=1.0)
    expected = np.interp(t, c["time_s"], c["torsion_bar_torque_Nm"])
    assert np.max(np.abs(expected)) > 2.0  # a real load
    assert np.max(np.abs(solution.torque_Nm - expected)) < 1e-4
    if name == "hydraulic_assist":
        pressure = np.interp(t, c["time_s"], c["pressure_Pa"])
        assert np.max(np.abs(solution.motor_torque_Nm - pressure)) < 100.0
        return
    current = np.interp(t, c["time_s"], c["motor_current_A"])
    assert np.max(np.abs(current)) > 5.0
    assert np.max(np.abs(solution.motor_current_A - current)) < 1e-3
    if "electric_assist_column.motor_torque_limit" in overrides:  # saturated: the motor sits at its limit while the driver's torque rises past 10 N m
        assert np.max(np.abs(solution.motor_torque_Nm)) > 0.49 and np.max(np.abs(expected)) > 10.0


def test_boost_law_inverse_is_exact_where_the_closed_form_holds(params):
    """Closed form: with no dead band and the motor far below its limit, T_s + G T_s = y, so T_s = y / (1 + G)
    (the inverse is found by bisection, which knows nothing of this)."""
    from parksteer.model.numeric.assisted import boost_law

    name = "electric_assist_column"
    # a lossless gear (eta_f = eta_b = 1) delivers N T_m whichever way the power flows, so the law is the same at
    # rest and in motion
    run = prepare("unladen", f"+{name}", {f"{name}.dead_band": 0.0, f"{name}.motor_torque_limit": 30.0,
                                          f"{name}.efficiency": 1.0, f"{name}.back_efficiency": 1.0}, params=params)
    law = boost_law(run, run.p)
    y = np.linspace(-20.0, 20.0, 41)
    gain = law.gain
    # the clamp's smoothing leaves a relative error of about (w / 2L)^2 far inside the limit; the dead band's
    # smoothing at D = 0 adds w^2 / (8 |T|) -> a tolerance of 1e-3 N m over these torques
    assert np.max(np.abs(law.torsion_bar(y) - y / (1 + gain))) < 1e-3


def test_boost_law_inverse_balances_the_column_at_the_corners_of_the_law(params):
    """The torsion bar carries what the assist does not: T_s + f A(T_s) = y, at every sample, also where the law
    bends hardest (the dead band's corner, the motor's limit, the gear's power turning from driving to back-driven
    as the rack reverses) and for motors delivering 0 to 2 times what the law commands. Checked against a plain
    bisection of the same balance (an independent root finder: halve the bracket 200 times)."""
    from parksteer.model.numeric.assisted import boost_law

    name = "electric_assist_column"
    run = prepare("unladen", f"+{name}", {f"{name}.back_efficiency": 0.6}, params=params)
    law = boost_law(run, run.p)
    rng = np.random.default_rng(7)
    y = np.concatenate([rng.uniform(-30.0, 30.0, 400), law.dead_band + rng.uniform(-0.2, 0.2, 200), [0.0]])
    speed = rng.choice([-0.02, -1e-4, 0.0, 1e-4, 0.02], size=y.size)
    factor = rng.choice([0.0, 0.5, 1.0, 2.0], size=y.size)
    t_s = law.torsion_bar(y, factor, speed)
    assert np.max(np.abs(t_s + factor * law.assist(t_s, speed) - y)) < 1e-9
    low, high = y - 100.0, y + 100.0
    for _ in range(200):
        mid = 0.5 * (low + high)
        above = mid + factor * law.assist(mid, speed) > y
        low, high = np.where(above, low, mid), np.where(above, mid, high)
    assert np.max(np.abs(t_s - 0.5 * (low + high))) < 1e-11


def _sweep(params, effects: str, overrides: dict):
    """The assisted replay of a smooth steer to the right and back (no free run needed: the candidates act in the
    replay), at rtol 1e-8."""
    from parksteer.measure.rack_spline import interpolate_rack

    t = np.linspace(0.0, 6.0, 601)
    rack = interpolate_rack(t, 0.03 * np.sin(np.pi * t / 6.0))
    run = prepare("unladen", effects, overrides, params=params)
    return solve_assisted(run, run.p, rack, t[::5], rtol=1e-8, atol_factor=1.0)


@pytest.mark.slow  # builds a model of its own: started early, so that the workers end together
def test_motor_friction_at_a_column_assist_is_a_column_friction_of_n_times_it(params):
    """Independent effects, one load: extra friction T_e on the rotor of a column assist turning at N times the
    column is a torque N T_e on the column above the intermediate shaft, smoothed over the same rack-equivalent
    speed as the column friction effect's (a candidate's drag has the car-wide friction shape); so
    +assist_motor_friction at T_e and +column_friction at N T_e give the same torsion-bar torque (within 1e-6 N m),
    and strength 0 gives the assist alone exactly. The assist's own motor friction changes over on the assist's own
    band of rotor speed: moving that band from its default to the car-wide smoothing's width (N G_hr / beta) moves
    the torque about the reversal (by more than 1e-3 N m)."""
    name = "electric_assist_column"
    n = next(q.default for q in discover_effects()[name].quantities if q.key == f"{name}.reduction_ratio")
    motor = _sweep(params, f"+{name},+assist_motor_friction", {"assist_motor_friction.friction_torque": 0.05})
    column = _sweep(params, f"+{name},+column_friction", {"column_friction.friction_torque": n * 0.05})
    plain = _sweep(params, f"+{name}", {})
    absent = _sweep(params, f"+{name},+assist_motor_friction", {"assist_motor_friction.friction_torque": 0.0})
    assert np.max(np.abs(motor.torque_Nm - plain.torque_Nm)) > 0.05  # a real change
    assert np.max(np.abs(motor.torque_Nm - column.torque_Nm)) < 1e-6
    assert np.max(np.abs(absent.torque_Nm - plain.torque_Nm)) < 1e-9
    wide = _sweep(params, f"+{name}", {f"{name}.friction_speed": n * params["steering.handwheel_to_rack_ratio"]
                                       / params["steering.friction_smoothing"]})
    assert np.max(np.abs(wide.torque_Nm - plain.torque_Nm)) > 1e-3


def test_sensor_offset_and_gain_error_follow_the_linear_law(params):
    """Closed forms in the boost's linear range (no dead band, motor far from its limit): T_s (1 + G) = y. A sensor
    offset o read by the law and the log moves the reading to (y + o) / (1 + G); a gain G (1 + e) gives
    y / (1 + G (1 + e)); the current is G S / (eta N k_t) of the reading S in both. Checked on the replay against
    the boost-free road torque (within 1e-9 N m)."""
    name = "electric_assist_column"
    # a lossless gear (eta_f = eta_b = 1): no change of law where the rack reverses and the gear is back-driven
    ideal = {f"{name}.dead_band": 0.0, f"{name}.motor_torque_limit": 30.0, f"{name}.efficiency": 1.0,
             f"{name}.back_efficiency": 1.0}
    base = _sweep(params, f"+{name}", ideal)
    gain = 6.0  # the assist's default (Polo and paper's car alike)
    y = base.road_torque_Nm
    offset = _sweep(params, f"+{name},+torsion_bar_offset", {**ideal, "torsion_bar_offset.strength": 0.3})
    error = _sweep(params, f"+{name},+boost_gain_error", {**ideal, "boost_gain_error.strength": 0.25})
    # the smoothing of the dead band's corners at D = 0 is exact (ramp(x) - ramp(-x) = x); the clamp's leaves a
    # relative error of (w / 2 L)^2 ~ 3e-6 far inside the limit
    assert np.max(np.abs(offset.torque_Nm - (y + 0.3) / (1 + gain))) < 1e-4
    assert np.max(np.abs(error.torque_Nm - y / (1 + gain * 1.25))) < 1e-4
    assert np.max(np.abs(offset.road_torque_Nm - y)) < 1e-9  # law-side: the mechanics do not move


def test_worm_direction_changes_over_on_the_assists_own_band():
    """A worm passes from driving (eta_f of the motor's torque delivered) to back-driven (1 / eta_b) as the rotor
    reverses, over the assist's own band of rotor speed (``friction_speed``), not the car-wide friction smoothing: at
    three bands either side the factor is the data sheet's within 1 %, and at a tenth of a band, the rotor nearly at
    rest, it has moved less than a fifth of the way from 1 (a worm at rest loses no power)."""
    eta_f, eta_b, band = 0.85, 0.80, 0.5
    law = BoostLaw("electric_assist_column", "column", 6.0, 0.5, 0.05, 4.0, 0.05, 125.0, 18.0, eta_f, 0.05,
                   back_efficiency=eta_b, direction_width=0.05, friction_speed=band)
    assert float(law.delivered(1.0, 3 * band)) == pytest.approx(eta_f, rel=0.01)
    assert float(law.delivered(1.0, -3 * band)) == pytest.approx(1 / eta_b, rel=0.01)
    assert abs(float(law.delivered(1.0, band / 10)) - 1.0) < 0.2 * (1 - eta_f)
    assert abs(float(law.delivered(1.0, -band / 10)) - 1.0) < 0.2 * (1 / eta_b - 1)
    wider = BoostLaw("electric_assist_column", "column", 6.0, 0.5, 0.05, 4.0, 0.05, 125.0, 18.0, eta_f, 0.05,
                     back_efficiency=eta_b, direction_width=0.05, friction_speed=10 * band)
    assert abs(float(wider.delivered(1.0, 3 * band)) - 1.0) < 0.5 * (1 - eta_f)  # the same speed, not yet over


def _plain_torsion_bar(law, y, factor=1.0, rotor_speed=0.0):
    """The inversion of BoostLaw.torsion_bar written plainly: every sample's bracket kept in full-length arrays,
    the open ones gathered and scattered back at each step, the law evaluated through BoostLaw.assist. Returns the
    root and the number of samples whose bracket had to be widened."""
    y = np.asarray(y, dtype=float)
    speed = np.broadcast_to(np.asarray(rotor_speed, dtype=float), y.shape)
    gain = np.broadcast_to(np.asarray(factor, dtype=float), y.shape)

    def excess(x, rows):
        return x + gain[rows] * law.assist(x, speed[rows]) - y[rows]

    low, high = np.minimum(y, 0.0), np.maximum(y, 0.0)
    f_low, f_high = excess(low, slice(None)), excess(high, slice(None))
    wide = np.flatnonzero((f_low > 0.0) | (f_high < 0.0))
    if wide.size:
        width = law.bound() * float(np.max(factor)) + 1.0
        low[wide], high[wide] = y[wide] - width, y[wide] + width
        f_low[wide], f_high[wide] = excess(low[wide], wide), excess(high[wide], wide)
    low = np.where(f_high == 0.0, high, low)
    high = np.where(f_low == 0.0, low, high)
    side = np.zeros(y.shape, dtype=np.int8)
    open_ = np.flatnonzero(high - low > 1e-12)
    for _ in range(200):
        if open_.size == 0:
            break
        lo, hi, flo, fhi = low[open_], high[open_], f_low[open_], f_high[open_]
        with np.errstate(divide="ignore", invalid="ignore"):
            x = lo - flo * (hi - lo) / (fhi - flo)
        x = np.where((x > lo) & (x < hi), x, 0.5 * (lo + hi))
        fx = excess(x, open_)
        above = fx > 0.0
        last = side[open_]
        flo = np.where(above & (last == 1), 0.5 * flo, flo)
        fhi = np.where(~above & (last == -1), 0.5 * fhi, fhi)
        low[open_], f_low[open_] = np.where(above, lo, x), np.where(above, flo, fx)
        high[open_], f_high[open_] = np.where(above, x, hi), np.where(above, fx, fhi)
        side[open_] = np.where(above, 1, -1)
        exact = fx == 0.0
        low[open_[exact]] = high[open_[exact]] = x[exact]
        open_ = open_[high[open_] - low[open_] > 1e-12]
    return 0.5 * (low + high), wide.size


def _table(scale: float = 1.0) -> tuple:
    """A two-row boost table (0 and 2 m/s; the second row 0.8 of the first), in table_keys order."""
    from parksteer.boost_table import table_keys

    torques = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.5, 3.0, 4.0]
    row = [0.0, 0.0, 0.9, 2.73, 5.22, 8.27, 12.78, 18.0, 30.3]
    values = entries(torques, [0.0, 2.0], [[scale * a for a in row], [0.8 * scale * a for a in row]])
    return tuple(float(values.get(k, 0.0)) for k in table_keys())


def test_the_inversion_gives_the_plain_inversions_bits():
    """The same arithmetic, so the same bits: the inversion as shipped (the open samples' brackets packed, the
    gear's direction and the table's segments read once per call) returns, bit for bit, what the plain form of
    the same regula falsi (above: full-length brackets, the law through BoostLaw.assist) returns, for column,
    pinion and rack gears and a hydraulic valve, with and without a table read between its speed rows, motors
    delivering 0-2 times the law, rotor speeds of either sign, and torques of 1e-15 N m, where the valve's
    smoothed dead band rounds to the wrong sign and the root's bracket is widened."""
    table = _table()
    cases = [
        BoostLaw("electric_assist_column", "column", 6.0, 0.5, 0.05, 4.0, 0.05, 125.0, 18.0, 0.85, 0.05,
                 back_efficiency=0.6, direction_width=0.05, friction_speed=0.5),
        BoostLaw("electric_assist_pinion", "pinion", 0.0, 0.0, 0.05, 3.0, 0.02, 125.0, 20.0, 0.8, 0.05, table=table,
                 speed=0.7, table_scale=1.1, back_efficiency=0.75, direction_width=0.05, friction_speed=1.5),
        BoostLaw("electric_assist_rack", "rack", 5.0, 0.8, 0.01, 5.0, 0.05, 150.0, 2500.0, 0.9, 0.05, table=table,
                 back_efficiency=0.85, direction_width=0.05, friction_speed=0.3),
        BoostLaw("hydraulic_assist", "rack", 4e5, 0.3, 0.05, 7e6, 1e5, 150.0, area=8e-4),
        BoostLaw("hydraulic_assist", "rack", 0.0, 0.3, 0.05, 7e6, 1e5, 150.0, area=8e-4, table=_table(scale=1e5),
                 speed=3.0),
    ]
    rng = np.random.default_rng(11)
    wide_taken = 0
    for law in cases:
        for trial in range(3):
            y = np.concatenate([rng.uniform(-40.0, 40.0, 300), rng.uniform(-1.0, 1.0, 100),
                                rng.uniform(-1e-15, 1e-15, 100), [0.0, -0.0, 1e-13]])
            speed = (0.0, rng.choice([-0.02, -1e-4, 0.0, 1e-4, 0.02, 3.0], size=y.size), 0.7)[trial]
            factor = (1.0, 0.5, rng.choice([0.0, 0.5, 1.0, 2.0], size=y.size))[trial]
            plain, widened = _plain_torsion_bar(law, y, factor, speed)
            assert law.torsion_bar(y, factor, speed).tobytes() == plain.tobytes()
            wide_taken += widened
    assert wide_taken > 0


def test_the_replays_law_is_assist_commons_law_bit_for_bit():
    """The replay evaluates the boost law's pieces on numbers without assist_common's check for sympy expressions
    (whose first call imports sympy): its ramp, dead band, clamp, gear direction and table read at a speed are
    assist_common's, bit for bit, at values across the corners (and at -0.0), and at vehicle speeds below, on,
    between and beyond the table's rows."""
    from parksteer.boost_table import table_keys
    from parksteer.model.numeric import boost_numeric
    from parksteer.model.symbolic.effects import assist_common

    rng = np.random.default_rng(5)
    x = np.concatenate([rng.uniform(-10.0, 10.0, 2000), rng.uniform(-0.6, 0.6, 500), [0.0, -0.0, 0.5, -0.5]])
    for band, width in ((0.5, 0.05), (0.0, 0.05), (0.3, 0.0)):
        assert (boost_numeric.deadband(x, band, width).tobytes()
                == assist_common.deadband(x, band, width).tobytes())
        assert boost_numeric.clamp(x, 4.0 + band, width).tobytes() == assist_common.clamp(x, 4.0 + band, width).tobytes()
    speed = rng.uniform(-3.0, 3.0, x.size)
    for sharpness in (2.0, 1000.0):
        expected = assist_common.directional_efficiency(x, speed, 0.85, 0.8, 0.05, sharpness)
        assert (boost_numeric.directional_efficiency(x, portable.tanh(sharpness * speed), 0.85, 0.8, 0.05).tobytes()
                == expected.tobytes())
    values = dict(zip(table_keys(), _table()))
    for v in (0.0, 0.7, 2.0, 5.0, -1.0):
        numeric = boost_numeric.table_points_numeric(values.__getitem__, v)
        expected = assist_common.table_points(values.__getitem__, v)
        assert [np.float64(a).tobytes() for part in numeric for a in part] == [
            np.asarray(a, dtype=float).tobytes() for part in expected for a in part]


def test_an_assisted_replays_law_imports_no_sympy():
    """A replay runs compiled models, so its process never needs sympy (a second of every assisted diagnosis to
    import): the boost law of a table read between its speed rows, inverted, its motor torque and assist
    evaluated, in a fresh interpreter, leave sympy unimported."""
    import subprocess
    import sys

    code = ("import sys, numpy as np\n"
            "from parksteer.model.numeric.assisted import BoostLaw\n"
            f"law = BoostLaw('electric_assist_column', 'column', 6.0, 0.5, 0.05, 4.0, 0.05, 125.0, 18.0, 0.85, 0.05,"
            f" table={_table()!r}, speed=0.7, back_efficiency=0.8, direction_width=0.05, friction_speed=0.5)\n"
            "t = law.torsion_bar(np.linspace(-20.0, 20.0, 101), 1.0, 0.01)\n"
            "law.motor(t), law.assist(t, 0.01)\n"
            "print('sympy' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
