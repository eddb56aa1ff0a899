"""Static tyre rig (section 2): equations (1) and (2), the patch about an offset pin, Table 1."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import dblquad
from scipy.optimize import brentq

from parksteer.resources import data_file
from parksteer import rig
from parksteer.errors import UsageError

PRINTED_TABLE1 = data_file("table1_printed.csv")

MU = 0.666
P0_PA = 245000.0
N_INDEX = 0.78


@pytest.fixture(scope="module")
def table(params, repo_root):
    rows, _ = rig.read_printed_table1(repo_root / PRINTED_TABLE1)
    return rows, rig.table1(params, rows)


def polar_grid(radius_m: float, n_r: int = 400, n_phi: int = 720):
    """Midpoint polar grid over the disc: element centres (x, y) and areas; independent of the closed forms."""
    dr, dphi = radius_m / n_r, 2.0 * math.pi / n_phi
    r = (np.arange(n_r) + 0.5) * dr
    phi = (np.arange(n_phi) + 0.5) * dphi
    rr, pp = np.meshgrid(r, phi, indexing="ij")
    return rr * np.cos(pp), rr * np.sin(pp), rr * dr * dphi


# ---------------------------------------------------------------- friction coefficient, equations (1), (2)


def test_friction_coefficient_is_the_sliding_test_ratio(params):
    """The rig's mu is the force to slide the locked tyre over the load: 2438 N / 3660 N rounds to 0.666."""
    ratio = params["rig.friction_test_force"] / params["rig.friction_test_load"]
    assert (params["rig.friction_test_force"], params["rig.friction_test_load"]) == (2438.0, 3660.0)
    assert round(ratio, 3) == params["tyre.friction_coefficient"] == 0.666


def test_equation1_is_the_coulomb_integral_over_the_disc():
    """Equation (1) is Integral mu p r dA over the disc with pi R^2 p = W, i.e. (2/3) mu p pi R^3."""
    load_N, pressure_Pa = 3660.0, 2.45e5
    radius_m = math.sqrt(load_N / (math.pi * pressure_Pa))
    integral, _ = dblquad(lambda r, phi: MU * pressure_Pa * r * r, 0.0, 2.0 * math.pi, 0.0, radius_m)
    assert float(rig.patch_radius_m(load_N, pressure_Pa)) == pytest.approx(radius_m, rel=1e-14)
    assert float(rig.gough_torque_Nm(load_N, pressure_Pa, MU)) == pytest.approx(integral, rel=1e-10)
    assert integral == pytest.approx(2.0 / 3.0 * MU * pressure_Pa * math.pi * radius_m**3, rel=1e-10)


def test_equation2_equals_equation1_at_reference_pressure():
    """Equation (2) is built to coincide with equation (1) at p = p0, for every load."""
    loads_N = np.array([2000.0, 3660.0, 4400.0])
    eq1 = rig.gough_torque_Nm(loads_N, P0_PA, MU)
    eq2 = rig.empirical_torque_Nm(loads_N, P0_PA, MU, P0_PA, N_INDEX)
    np.testing.assert_allclose(eq2, eq1, rtol=1e-13)
    assert float(rig.pressure_correction(P0_PA, P0_PA, N_INDEX)) == 1.0


def test_both_equations_scale_as_load_to_the_power_one_and_a_half():
    """Doubling W at fixed p doubles the patch area and grows the radius by sqrt(2): T grows by 2^1.5."""
    for pressure_Pa in (1.5e5, 2.45e5, 3.0e5):
        ratio1 = rig.gough_torque_Nm(4000.0, pressure_Pa, MU) / rig.gough_torque_Nm(2000.0, pressure_Pa, MU)
        ratio2 = rig.empirical_torque_Nm(4000.0, pressure_Pa, MU, P0_PA, N_INDEX) / rig.empirical_torque_Nm(
            2000.0, pressure_Pa, MU, P0_PA, N_INDEX
        )
        assert float(ratio1) == pytest.approx(2.0**1.5, rel=1e-13)
        assert float(ratio2) == pytest.approx(2.0**1.5, rel=1e-13)


def test_equation2_falls_faster_with_pressure_than_equation1():
    """Doubling p scales (1) by 2^-0.5 (smaller patch) and (2) by 2^-n, steeper for n > 0.5."""
    eq1 = rig.gough_torque_Nm(3000.0, np.array([1.5e5, 3.0e5]), MU)
    eq2 = rig.empirical_torque_Nm(3000.0, np.array([1.5e5, 3.0e5]), MU, P0_PA, N_INDEX)
    assert eq1[1] / eq1[0] == pytest.approx(2.0**-0.5, rel=1e-13)
    assert eq2[1] / eq2[0] == pytest.approx(2.0**-N_INDEX, rel=1e-13)
    assert eq2[1] / eq2[0] < eq1[1] / eq1[0]
    # below p0 the correction raises the torque, above p0 it lowers it
    assert rig.pressure_correction(1.5e5, P0_PA, N_INDEX) > 1.0 > rig.pressure_correction(3.0e5, P0_PA, N_INDEX)


def test_limiting_torque_at_car_pressure_matches_reconstruction_magnitude(params):
    """Equation (2) at the car's 1.225 bar for the unladen left wheel (2698 N) is about 122 N m."""
    torque = float(rig.limiting_torque_Nm(params, params.case("unladen")["load_left"]))
    hand = 2.0 / 3.0 * 0.666 * 2698.0**1.5 / math.sqrt(math.pi * 122500.0) * 2.0**0.28
    assert torque == pytest.approx(hand, rel=1e-12)
    assert torque == pytest.approx(122.0, abs=1.0)


# ---------------------------------------------------------------- patch turning about an offset pin


def test_disc_distance_integral_known_values():
    """Integral of |r - e| over the unit disc: 2 pi/3 at the centre and 32/9 on the rim (classical results)."""
    values = rig.disc_distance_integral_m3(1.0, np.array([0.0, 1.0]))
    np.testing.assert_allclose(values, [2.0 * math.pi / 3.0, 32.0 / 9.0], rtol=1e-13)
    assert np.all(np.isfinite(values))


@pytest.mark.parametrize("offset_over_radius", [0.37, 0.93, 1.0, 1.6, 4.0])
def test_braked_torque_matches_independent_quadrature(offset_over_radius):
    """The closed form equals mu p Integral |r - e| dA summed on a polar grid, inside and outside the patch."""
    load_N, pressure_Pa = 3200.0, 2.0e5
    radius_m = math.sqrt(load_N / (math.pi * pressure_Pa))
    offset_m = offset_over_radius * radius_m
    x, y, area = polar_grid(radius_m)
    grid_Nm = MU * pressure_Pa * np.sum(np.hypot(x, y - offset_m) * area)
    closed_Nm = float(rig.braked_pin_torque_Nm(load_N, pressure_Pa, MU, offset_m))
    assert closed_Nm == pytest.approx(grid_Nm, rel=1e-5)


def test_braked_torque_at_zero_offset_is_equation1():
    """With the pin at the patch centre the braked patch spins about its centre: equation (1)."""
    loads_N = np.array([2000.0, 3800.0])
    braked = rig.braked_pin_torque_Nm(loads_N, 2.0e5, MU, 0.0)
    np.testing.assert_allclose(braked, rig.gough_torque_Nm(loads_N, 2.0e5, MU), rtol=1e-13)


def test_braked_torque_small_offset_curvature():
    """d2/de2 of Integral |r - e| dA at e = 0 is Integral x^2/r^3 dA = pi R, so T/T(0) = 1 + (3/4)(e/R)^2."""
    radius_m = float(rig.patch_radius_m(3800.0, 2.0e5))
    ratio = rig.braked_pin_torque_Nm(3800.0, 2.0e5, MU, 0.01 * radius_m) / rig.gough_torque_Nm(3800.0, 2.0e5, MU)
    assert float(ratio) - 1.0 == pytest.approx(0.75 * 0.01**2, rel=1e-3)


def test_braked_torque_grows_with_offset_and_exceeds_free_rolling():
    """Braking makes the patch slide about the pin, so the torque rises monotonically above equation (1)."""
    load_N, pressure_Pa = 3800.0, 2.0e5
    offsets_m = np.linspace(0.0, 0.3, 601)
    braked = rig.braked_pin_torque_Nm(load_N, pressure_Pa, MU, offsets_m)
    free = rig.free_rolling_pin_torque_Nm(load_N, pressure_Pa, MU, offsets_m)
    assert np.all(np.diff(braked) > 0.0)
    assert np.all(braked[1:] > free[1:])
    # and never below the net-force bound mu W e (triangle inequality on the integral)
    assert np.all(braked >= MU * load_N * offsets_m)


def test_braked_torque_tends_to_force_times_arm_far_from_the_patch():
    """For e >> R all sliding is nearly parallel: T -> mu W e (within 1% at e = 20 R, and closer at 1000 R)."""
    load_N, pressure_Pa = 3800.0, 2.0e5
    radius_m = float(rig.patch_radius_m(load_N, pressure_Pa))
    for multiple in (20.0, 1000.0):
        offset_m = multiple * radius_m
        ratio = float(rig.braked_pin_torque_Nm(load_N, pressure_Pa, MU, offset_m)) / (MU * load_N * offset_m)
        assert 1.0 < ratio < 1.01
    # continuous where the computation changes method (R/e = 0.02)
    around = radius_m / 0.02 * np.array([1.0 - 1e-9, 1.0 + 1e-9])
    near, far = rig.braked_pin_torque_Nm(load_N, pressure_Pa, MU, around)
    assert far / near == pytest.approx(1.0, abs=1e-8)


def test_free_rolling_equilibrium_is_pure_rolling_and_flat():
    """A wheel free to roll takes zero net longitudinal friction: on a grid the equilibrium rolling speed is
    omega e (spin/steer = e / rolling radius) and the torque about the pin is equation (1), for any offset."""
    load_N, pressure_Pa, omega = 3200.0, 2.0e5, 1.0
    radius_m = float(rig.patch_radius_m(load_N, pressure_Pa))
    x, y, area = polar_grid(radius_m, 200, 360)
    for offset_m in (0.03, 0.06, 0.105):
        def friction_on_plate(rolling_speed):
            # plate turns about the pin; the tread moves along x at the rolling speed
            vx, vy = omega * (offset_m - y) - rolling_speed, omega * x
            speed = np.hypot(vx, vy)
            return -MU * pressure_Pa * area * vx / speed, -MU * pressure_Pa * area * vy / speed

        def net_fx(rolling_speed):
            return np.sum(friction_on_plate(rolling_speed)[0])

        span = 10.0 * omega * (offset_m + radius_m)
        rolling_speed = brentq(net_fx, -span, span, xtol=1e-12)
        fx, fy = friction_on_plate(rolling_speed)
        torque_about_pin = abs(np.sum(x * fy - (y - offset_m) * fx))
        assert rolling_speed == pytest.approx(omega * offset_m, rel=1e-6)
        model = float(rig.free_rolling_pin_torque_Nm(load_N, pressure_Pa, MU, offset_m))
        assert model == pytest.approx(torque_about_pin, rel=1e-4)
    free = rig.free_rolling_pin_torque_Nm(load_N, pressure_Pa, MU, np.linspace(0.0, 0.12, 7))
    np.testing.assert_allclose(free, rig.gough_torque_Nm(load_N, pressure_Pa, MU), rtol=1e-14)


def test_pin_torques_carry_the_rig_pressure_correction(params):
    """The spin part of both pin-offset limits is scaled by eq (2)/eq (1), so at zero offset both equal
    equation (2); the braked curve's drag part (braked integral minus equation (1)) is not scaled."""
    for pressure_Pa in params["rig.fig4_pressures"]:
        torques = rig.pin_torques_Nm(params, 3800.0, pressure_Pa, np.array([0.0, 0.05]))
        eq2 = float(rig.limiting_torque_Nm(params, 3800.0, pressure_Pa))
        assert torques.free_rolling_Nm[0] == pytest.approx(eq2, rel=1e-13)
        assert torques.braked_Nm[0] == pytest.approx(eq2, rel=1e-13)
        assert torques.free_rolling_Nm[1] == pytest.approx(eq2, rel=1e-13)
        mu = params["tyre.friction_coefficient"]
        drag = rig.braked_pin_torque_Nm(3800.0, pressure_Pa, mu, 0.05) - rig.gough_torque_Nm(3800.0, pressure_Pa, mu)
        assert torques.braked_Nm[1] - torques.free_rolling_Nm[1] == pytest.approx(float(drag), rel=1e-12)


def test_braked_pin_torque_never_beats_the_net_sliding_force_bound(params):
    """Physical fact: the friction of a sliding patch can never sum to more than mu W, so the braked torque about
    the pin is at most mu W e (the net force on the arm) plus the spin moment of the free-rolling wheel, and
    tends to mu W e as e grows, whatever the pressure distribution (the rig's (p0/p)^(n - 0.5) acts on the spin
    part only). At 1.5 bar, scaling the whole braked curve by 1.147 broke both, at every Fig. 4 load."""
    mu = params["tyre.friction_coefficient"]
    offsets_m = np.concatenate([np.linspace(0.0, 0.12, 121), [0.5, 2.0, 10.0, 50.0]])
    for pressure_Pa in params["rig.fig4_pressures"]:
        for load_N in params["rig.loads"]:
            torques = rig.pin_torques_Nm(params, load_N, pressure_Pa, offsets_m)
            bound = mu * load_N * offsets_m + torques.free_rolling_Nm
            assert np.all(torques.braked_Nm <= bound * (1.0 + 1e-12))
            # the departure from mu W e stays within the spin moment, so the ratio tends to 1 as 1/e
            far = offsets_m > 0.4
            arm = mu * load_N * offsets_m[far]
            assert np.all(np.abs(torques.braked_Nm[far] - arm) <= torques.free_rolling_Nm[far])
            assert abs(torques.braked_Nm[-1] / arm[-1] - 1.0) < 1e-3


# ---------------------------------------------------------------- Table 1


def test_table1_pure_rolling_ratio_is_offset_over_rolling_radius(table):
    """A wheel rolling without slip turns by e / r_roll per unit steer (r_roll = 263 mm): the printed column
    is reproduced to its last printed digit (0.1141, 0.2281, 0.3992)."""
    rows, columns = table
    for row, recomputed in zip(rows, columns["pure_rolling_ratio"]):
        decimals = len(row["pure_rolling_ratio"].split(".")[1])
        assert f"{recomputed:.{decimals}f}" == row["pure_rolling_ratio"]
    assert list(columns["pure_rolling_ratio_disagrees"]) == [0, 0, 0]


def test_table1_percentages_use_the_printed_ratio(table):
    """(measured - pure rolling) / pure rolling with the printed spin/steer ratio gives -15.0, -3.2, +0.5 as
    printed; with the quotient of the printed angles the 30 mm and 105 mm rows would read -15.1 and +0.4."""
    rows, columns = table
    for row, recomputed in zip(rows, columns["percentage_difference"]):
        assert f"{recomputed:+.1f}" == f"{float(row['percentage_difference']):+.1f}"
    assert list(columns["percentage_difference_disagrees"]) == [0, 0, 0]
    from_quotient = [f"{v:+.1f}" for v in columns["percentage_difference_from_quotient"]]
    assert from_quotient == ["-15.1", "-3.2", "+0.4"]


def test_table1_ratio_discrepancies_are_flagged(table):
    """0.883/4.00 = 0.22075 (printed 0.2209) and 4.08/10.18 = 0.40079 (printed 0.4012) differ beyond the
    ratio's last digit; 1.083/11.18 = 0.0969 rounds to the printed 0.097. All three are consistent once the
    angles themselves are allowed their printed rounding, so the ratio came from unrounded angles."""
    _, columns = table
    np.testing.assert_allclose(columns["spin_steer_quotient"], [1.083 / 11.18, 0.883 / 4.00, 4.08 / 10.18])
    assert list(columns["spin_steer_ratio_disagrees"]) == [0, 1, 1]
    assert list(columns["spin_steer_ratio_consistent_with_rounding"]) == [1, 1, 1]
    assert columns["spin_steer_quotient_low"][1] == pytest.approx(0.8825 / 4.005)
    assert columns["spin_steer_quotient_high"][1] == pytest.approx(0.8835 / 3.995)


def test_table1_measured_spin_approaches_pure_rolling_with_offset(table):
    """The rig's finding: the wheel spins more per unit steer as the offset grows, nearing pure rolling."""
    _, columns = table
    assert np.all(np.diff(columns["printed_spin_steer_ratio"]) > 0.0)
    assert np.all(np.diff(np.abs(columns["percentage_difference"])) < 0.0)


def test_printed_half_unit_reads_the_printed_rounding():
    """A printed number is exact to half a unit in its last digit: '4.00' to 0.005, '+0.5' to 0.05, '30' to 0.5."""
    assert rig.printed_half_unit("4.00") == pytest.approx(0.005)
    assert rig.printed_half_unit("+0.5") == pytest.approx(0.05)
    assert rig.printed_half_unit("30") == pytest.approx(0.5)


def test_malformed_printed_table_is_a_one_line_usage_error(tmp_path, repo_root):
    """A printed table with a missing column or a non-number is refused with one line naming the file."""
    bad = tmp_path / "table1.csv"
    bad.write_text("offset_mm,steer_deg\n30,11.18\n", encoding="utf-8")
    with pytest.raises(UsageError, match="table1.csv: expected columns") as info:
        rig.read_printed_table1(bad)
    assert "\n" not in str(info.value)
    text = (repo_root / PRINTED_TABLE1).read_text(encoding="utf-8").replace("0.883", "O.883")
    bad.write_text(text, encoding="utf-8")
    with pytest.raises(UsageError, match="row 2, spin_deg"):
        rig.read_printed_table1(bad)
