"""The prescribed-rack solver (parksteer.model.numeric.prescribed) and `parksteer simulate --rack-from`."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BPoly, CubicSpline, PPoly

from parksteer.cli import main
from parksteer.errors import UsageError
from parksteer.measure.io import read_measurement
from parksteer.measure.rack_spline import RackSpline, interpolate_rack
from parksteer.geometry import column_twist
from parksteer.model.numeric.prescribed import solve
from parksteer.model.numeric.simulate import prepare, simulate, static_state
from parksteer.model.symbolic.components import with_effect_quantities
from parksteer.tables import read_csv

FRICTION_OFF = "-tyre_friction,-rack_friction"


def hermite_rack(time_s, position, speed, acceleration) -> RackSpline:
    """The C2 piecewise quintic through exact rack states (position, speed and acceleration at each sample)."""
    bernstein = BPoly.from_derivatives(time_s, np.column_stack([position, speed, acceleration]))
    return RackSpline.from_ppoly(PPoly.from_bernstein_basis(bernstein))


def test_prescribed_free_simulation_rack_gives_back_its_handwheel_torque_and_angle(params):
    """Independent paths: the free (handwheel-driven) integration of the full model, and the constrained solve of
    the same equations with its rack prescribed (from its own rack states, smoothly) and the column torque solved
    for. Solved to convergence (rtol 1e-8, the free run's absolute tolerances), the solve gives back the free run's
    handwheel torque (within 1e-3 N m; they agree to about 2e-5 N m), its handwheel angle through the solved column
    twist (within 2e-5 rad) and its wheel loads (within 1 N of 2.7 kN). Converged, because the default replay
    tolerance is looser: on this rack it leaves errors up to 0.003 N m (tolerances.PRESCRIBED_RTOL)."""
    free = simulate("unladen", params=params, output_dt_s=0.005)
    model, n = free.model, free.model.n_q
    i = model.index("rack")
    c = free.columns
    acceleration = np.array([model.rhs(t, y, free.parameter_vector)[n + i] for t, y in zip(c["time_s"], free.states)])
    rack = hermite_rack(c["time_s"], free.states[:, i], free.states[:, n + i], acceleration)
    t = np.round(np.arange(0.0, c["time_s"][-1] + 1e-9, 0.01), 12)
    run = prepare("unladen", params=params)
    solution = solve(run, run.p, rack, t, rtol=1e-8, atol_factor=1.0, outputs=True)
    d = {"time_s": t, "handwheel_torque_Nm": solution.outputs["column_torque_Nm"],
         "handwheel_angle_rad": solution.handwheel[:, 0], "load_left_N": solution.outputs["load_left_N"],
         "load_right_N": solution.outputs["load_right_N"]}
    for name, tolerance in (("handwheel_torque_Nm", 1e-3), ("handwheel_angle_rad", 2e-5), ("load_left_N", 1.0),
                            ("load_right_N", 1.0)):
        expected = np.interp(d["time_s"], c["time_s"], c[name])
        assert np.max(np.abs(d[name] - expected)) < tolerance, name


def test_contributions_add_up_to_the_solved_torque(params):
    """Bookkeeping: the contribution columns sum, by construction, to the column torque of the handwheel output;
    that this equals the solved torque checks that the handwheel angle's twist solves c dtwist/dt + k twist = T."""
    t = np.linspace(0.0, 6.0, 601)
    x = 0.03 * (1.0 - np.cos(np.pi * t / 6.0)) / 2.0
    result = simulate("unladen", params=params, rack_drive=interpolate_rack(t, x), output_dt_s=0.02)
    d = result.columns
    total = sum(d[name] for name in result.contribution_names)
    assert np.max(np.abs(total - d["handwheel_torque_Nm"])) < 1e-9 * np.max(np.abs(d["handwheel_torque_Nm"]))


def test_slow_rack_without_friction_tends_to_the_quasi_static_torque(params):
    """With tyre and rack friction off, what resists the rack is elastic and gravitational (lifting, carcass,
    springs), so as the rack slows the solved torque tends to the quasi-static one: the static equilibrium of the
    free model with the handwheel held still at each angle (an independent path: Newton on the full model's
    forcing, rack free). Each fourfold slowing cuts the RMS difference by more than four (the dynamic terms go
    as speed or acceleration), and a 64 s stroke is within 2e-4 N m of the quasi-static curve."""
    run = prepare("unladen", effects=FRICTION_OFF, params=params)
    n_par = len(run.model.info["parameters"])
    i_rack = run.model.index("rack")
    racks, torques = [], []
    for angle in np.linspace(-1.0, 13.0, 57):
        p = run.p.copy()
        p[n_par:] = 0.0
        p[n_par : n_par + 3] = (1.0, 0.0, angle)  # one input piece: held at `angle` from t = 0
        y = static_state(run, p=p)
        assert np.max(np.abs(run.model.forcing(0.0, y, p))) < 1e-6  # an equilibrium indeed
        racks.append(y[i_rack])
        torques.append(run.model.evaluate_outputs(np.zeros(1), y[None, :], p)["column_torque_Nm"][0])
    quasi_static = CubicSpline(racks, torques)
    errors = []
    for duration in (4.0, 16.0, 64.0):
        t = np.linspace(0.0, duration, 2001)
        w = np.pi / duration
        rack = hermite_rack(t, 0.03 * (1 - np.cos(w * t)), 0.03 * w * np.sin(w * t), 0.03 * w * w * np.cos(w * t))
        t_out = np.linspace(0.0, duration, 401)
        x = rack.evaluate(t_out)[0]
        inside = (x > 0.005) & (x < 0.055)
        torque = solve(run, run.p, rack, t_out, rtol=1e-9, atol_factor=0.1).torque_Nm
        errors.append(np.sqrt(np.mean((torque - quasi_static(x))[inside] ** 2)))
    assert np.ptp(quasi_static(np.linspace(0.005, 0.055, 50))) > 1.0  # a torque worth tending to (N m)
    assert errors[1] < errors[0] / 4.0 and errors[2] < errors[1] / 4.0
    assert errors[2] < 2e-4


def test_column_twist_solves_its_equation_exactly_for_a_linear_torque():
    """c dtwist/dt + k twist = T with T rising linearly from rest: twist = (T - c s / k (1 - e^(-t k / c))) / k."""
    k, c, s = 1000.0, 200.0, 30.0
    t = np.linspace(0.0, 2.0, 9)
    twist, rate = column_twist(t, s * t, k, c)
    tau = c / k
    expected = (s * t - s * tau * (1.0 - np.exp(-t / tau))) / k
    assert np.max(np.abs(twist - expected)) < 1e-12
    assert np.max(np.abs(c * rate + k * twist - s * t)) < 1e-9


def test_rack_spline_rejects_bad_samples():
    """A spline through rack samples needs at least four samples at strictly increasing times."""
    with pytest.raises(UsageError):
        interpolate_rack([0.0, 1.0, 1.0, 2.0], [0.0, 0.01, 0.02, 0.03])
    with pytest.raises(UsageError):
        interpolate_rack([0.0, 1.0], [0.0, 0.01])


@pytest.fixture(scope="module")
def example_file(repo_root):
    return repo_root / "data" / "measurements" / "example_unladen.csv"


def test_simulate_rack_from_agrees_with_compare_within_the_noise_floor(example_file, params, tmp_path):
    """`parksteer simulate --rack-from` and `parksteer compare` replay the same measured rack (smoothed the same
    way) through the same solver: the two torques differ by far less than the noise floor compare reports, and
    each is as far from the measurement as the other (within a tenth of the floor). Against the measurement
    both stay within twice the floor (the excess is at the reversals, where the rack data fix the turning time
    least well); the raw 8-bit rack replayed through an interpolating spline is some thirty floors off."""
    from parksteer.diagnose.compare import compare_files
    from parksteer.diagnose.problem import load_files

    out = tmp_path / "replay.csv"
    assert main(["simulate", "--rack-from", str(example_file), "--output-dt", "0.02", "--out", str(out)]) == 0
    columns, header = read_csv(out)
    assert "smoothed" in header["drive"]
    measurement = read_measurement(example_file, params)
    simulated = np.interp(measurement.time_s, columns["time_s"], columns["handwheel_torque_Nm"])

    result = compare_files(load_files([example_file], params), params)
    compared = result.predictions[0]
    floor = result.statistics["noise_floor_Nm"]
    measured = measurement.handwheel_torque_Nm

    def rms(a):
        return float(np.sqrt(np.mean(a**2)))

    assert rms(simulated - compared) < 0.1 * floor
    assert abs(rms(simulated - measured) - rms(compared - measured)) < 0.1 * floor
    assert rms(simulated - measured) < 2.0 * floor

    raw = tmp_path / "raw.csv"
    assert main(["simulate", "--rack-from", str(example_file), "--raw-rack", "--output-dt", "0.02",
                 "--out", str(raw)]) == 0
    raw_columns, raw_header = read_csv(raw)
    assert "raw samples" in raw_header["drive"]
    assert rms(np.interp(measurement.time_s, raw_columns["time_s"], raw_columns["handwheel_torque_Nm"])
               - measured) > 10.0 * floor


def test_prescribed_rack_with_lash_gives_back_the_free_handwheel_angle(params):
    """The column's spring and damper act on the deflection g(twist) of a dead band (rack_lash, +-a = b G of twist):
    the prescribed-rack replay of a free (handwheel-driven) lash run's rack must give back its handwheel angle, the
    twist being the one whose deflection passes the solved torque. Where a flank is engaged (the free twist beyond
    the band and its smoothed corner, |twist| > a + w G) the angle is the free run's within 5e-5 rad (the linear
    column's 2e-5 of the test above, plus the corner: the torque there is small and fixes the twist less well) and
    lies a (within 5 %) beyond what the linear law c dtwist/dt + k twist = T would give, on the torque's side. Inside
    the band the hand turns with no torque, so the rack and torque fix the angle only within the band: within 2a
    there, and the whole record's RMS angle error under 5 % of the band."""
    lash_m, ratio = 0.0002, params["steering.handwheel_to_rack_ratio"]
    a, corner = lash_m * ratio, with_effect_quantities(params)["rack_lash.smoothing_width"] * ratio
    overrides = {"rack_lash.lash": lash_m}
    free = simulate("unladen", effects="+rack_lash", overrides=overrides, params=params, output_dt_s=0.005)
    model, n = free.model, free.model.n_q
    i = model.index("rack")
    c = free.columns
    acceleration = np.array([model.rhs(t, y, free.parameter_vector)[n + i] for t, y in zip(c["time_s"], free.states)])
    rack = hermite_rack(c["time_s"], free.states[:, i], free.states[:, n + i], acceleration)
    d = simulate("unladen", effects="+rack_lash", overrides=overrides, params=params, rack_drive=rack,
                 output_dt_s=0.01).columns
    expected = np.interp(d["time_s"], c["time_s"], c["handwheel_angle_rad"])
    free_twist = np.interp(d["time_s"], c["time_s"], c["handwheel_angle_rad"] - c["column_angle_rad"])
    error = d["handwheel_angle_rad"] - expected
    engaged = np.abs(free_twist) > a + corner
    assert 0.5 < np.mean(engaged) < 0.99  # both: a record that holds the flanks and crosses the band
    assert np.max(np.abs(error[engaged])) < 5e-5
    assert np.max(np.abs(error[~engaged])) < 2.0 * a
    assert np.sqrt(np.mean(error**2)) < 0.05 * 2.0 * a
    linear, _ = column_twist(d["time_s"], d["handwheel_torque_Nm"], params["steering.column_torsional_stiffness"],
                             params["steering.column_torsional_damping"])
    widened = (d["handwheel_angle_rad"] - d["column_angle_rad"] - linear)[engaged]
    held = np.abs(d["handwheel_torque_Nm"][engaged]) > 1.0
    assert np.max(np.abs(widened[held] - a * np.sign(d["handwheel_torque_Nm"][engaged][held]))) < 0.05 * a


def test_the_compiled_rack_table_is_the_spline_scipy_evaluates(params):
    """The compiled model reads the rack from a table of its polynomial pieces: at any time, inside the record
    and beyond either end (held at the end values), it gives scipy's PPoly position, speed and acceleration
    (an evaluation written independently of the C one), so the replay integrates the rack it was given."""
    from parksteer.model.numeric.prescribed import rack_table

    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0.0, 3.0, 40))
    spline = CubicSpline(t, 0.05 * np.sin(2.0 * t) + 1e-3 * rng.standard_normal(40))
    rack = RackSpline.from_ppoly(spline)
    run = prepare("unladen", params=params)
    table = rack_table(rack)
    out = np.zeros(3)
    times = np.concatenate([rng.uniform(t[0], t[-1], 200), t, [t[0] - 1.0, t[-1] + 1.0]])
    for time in times:
        run.model.lib.ps_rack(float(time), table.ctypes.data, out.ctypes.data)
        inside = min(max(time, t[0]), t[-1])
        expected = [float(spline(inside, nu)) for nu in (0, 1, 2)]
        np.testing.assert_allclose(out, expected, rtol=1e-9, atol=1e-12)


def test_a_strided_time_axis_gives_the_replay_of_its_copy(params):
    """A decimated record's times are a strided view (every tenth sample); the compiled model reads the output
    times by address, so the replay on the view must be the replay on a contiguous copy, sample for sample."""
    t = np.linspace(0.0, 2.0, 401)
    rack = interpolate_rack(t, 0.03 * np.sin(1.5 * t))
    run = prepare("unladen", params=params)
    strided = t[::10]
    assert not strided.flags["C_CONTIGUOUS"]
    on_view = solve(run, run.p, rack, strided).torque_Nm
    on_copy = solve(run, run.p, rack, strided.copy()).torque_Nm
    np.testing.assert_array_equal(on_view, on_copy)


def _lsoda_torque(run, p, rack, t, rtol, atol_factor):
    """The prescribed-rack torque from scipy's LSODA (odeint, an integrator written independently of the generated
    one) calling back the compiled model's reduced right-hand side and Jacobian, then its per-sample solve."""
    from scipy.integrate import odeint

    from parksteer.model.numeric.prescribed import jacobian_parameters, rack_table
    from parksteer.model.numeric.tolerances import absolute_tolerances

    model, lib = run.model, run.model.lib
    n, i_rack = model.n_q, model.index("rack")
    others = [i for i in range(n) if i != i_rack]
    n_o = len(others)
    table, zdot, J = rack_table(rack), np.zeros(2 * n_o), np.zeros((2 * n_o, 2 * n_o))
    p_jac = jacobian_parameters(run, p)

    def rhs(z, time):
        assert lib.ps_prescribed_rhs(time, np.ascontiguousarray(z).ctypes.data, p.ctypes.data, table.ctypes.data,
                                     zdot.ctypes.data) == 0
        return zdot

    def jacobian(z, time):
        assert lib.ps_prescribed_jac(time, np.ascontiguousarray(z).ctypes.data, p.ctypes.data, p_jac.ctypes.data,
                                     table.ctypes.data, J.ctypes.data) == 0
        return J

    start = np.zeros(3)
    lib.ps_rack(float(t[0]), table.ctypes.data, start.ctypes.data)
    y = static_state(run, fixed={"rack": start[0]}, p=p)
    atol = absolute_tolerances([model.info["coordinate_units"][i] for i in others], atol_factor)
    z = np.ascontiguousarray(odeint(rhs, np.concatenate([y[others], np.zeros(n_o)]), t, Dfun=jacobian, rtol=rtol,
                                    atol=atol, mxstep=100_000))
    full, accelerations, torque = np.empty((len(t), 2 * n)), np.empty((len(t), n)), np.empty(len(t))
    assert lib.ps_prescribed_samples(len(t), t.ctypes.data, z.ctypes.data, p.ctypes.data, table.ctypes.data,
                                     full.ctypes.data, accelerations.ctypes.data, torque.ctypes.data) == 0
    return torque


@pytest.mark.parametrize("effects", [None, "+kingpin_friction"])
def test_the_generated_integrator_gives_lsodas_prescribed_rack_torque(example_file, params, effects):
    """The prescribed-rack solve runs in the generated integrator (ps_integrate_prescribed); scipy's LSODA on the
    same compiled equations is an independent check of the integration. Converged (rtol 1e-10, a hundredth of the
    absolute tolerances), the two give one torque to 1e-6 N m over the example record's smoothed rack; at the
    replay's own tolerances the generated integrator stays within 0.004 N m of it (2 % of an 8-bit converter
    step, the bound tolerances.PRESCRIBED_RTOL states)."""
    from parksteer.diagnose.problem import load_files
    from parksteer.model.symbolic.components import resolve_effects

    record = load_files([example_file], params)[0]
    t = np.ascontiguousarray(record.measurement.time_s)
    run = prepare(record.case, resolve_effects(effects), surface=record.surface, params=params)
    reference = _lsoda_torque(run, run.p, record.rack, t, 1e-10, 0.01)
    converged = solve(run, run.p, record.rack, t, rtol=1e-10, atol_factor=0.01).torque_Nm
    assert np.max(np.abs(converged - reference)) < 1e-6
    assert np.max(np.abs(solve(run, run.p, record.rack, t).torque_Nm - reference)) < 0.004


def test_a_rack_whose_acceleration_jumps_is_integrated_across_its_corner(params):
    """A rack made of two parabolas (constant acceleration +a, then -a: the speed continuous, the acceleration
    jumping at the join) has a corner there, which the solve finds (a cubic spline's joins are none) and stops
    and restarts at: at the replay's own tolerances its torque stays within 0.004 N m of LSODA's converged one
    (_lsoda_torque, which crosses the jump by its error control alone) before, at and after the corner."""
    from parksteer.model.numeric.prescribed import rack_corners

    a, t_join, t_end = 0.02, 1.0, 2.0
    first = [0.5 * a, 0.0, 0.0]  # x = a t^2 / 2, highest power first
    second = [-0.5 * a, a * t_join, 0.5 * a * t_join**2]  # then decelerating to rest at t_end
    rack = RackSpline(np.array([0.0, t_join, t_end]), np.column_stack([first, second]))
    assert rack_corners(rack, 0.0, t_end).tolist() == [t_join]
    smooth = RackSpline.from_ppoly(CubicSpline([0.0, 0.5, 1.0, 2.0], [0.0, 0.01, 0.0, 0.02]))
    assert rack_corners(smooth, 0.0, 2.0).size == 0
    run = prepare("unladen", params=params)
    t = np.linspace(0.0, t_end, 201)
    reference = _lsoda_torque(run, run.p, rack, t, 1e-10, 0.01)
    assert np.max(np.abs(solve(run, run.p, rack, t).torque_Nm - reference)) < 0.004
