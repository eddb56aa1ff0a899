"""Steer-axis geometry, the Table B1 statics and the lifting torque of equation (A1).

The reference values here come from the paper's printed numbers, its Appendix A closed
forms, or an independent route (statics, virtual work), never from the code under test.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from parksteer.figures.lifting import FIGA3_CASES, lifting_curves, lifting_summary, torque_column
from parksteer.geometry import (
    SIDES,
    lifting_torque_a1,
    lock_steer_angle,
    steering_ratio,
    steer_axis,
)

TABLE_B1_CASES = ("unladen", "part_laden", "offset_12_7mm", "offset_44_5mm", "offset_68_5mm")
SPACER_CASES = ("offset_12_7mm", "offset_44_5mm", "offset_68_5mm")

# Steer angles over the whole lock range, in units of the lock angle (both ends and straight ahead included).
LOCK_FRACTIONS = np.linspace(-1.0, 1.0, 41)


def _with_geometry(params, **changes):
    """A copy of `params` with some [geometry] values replaced (the shipped file is left as it is)."""
    geometry = {**params.sections["geometry"], **changes}
    return dataclasses.replace(params, sections={**params.sections, "geometry": geometry})


def _trail_through_wheel_centre_m(params) -> float:
    """(z2 - z1) tan(castor): the trail that puts the castored axis exactly through C in side view."""
    g = params.sections["geometry"]
    return (g["wheel_centre_z"] - g["kingpin_top_z"]) * math.tan(g["castor_angle"])


@pytest.fixture(scope="module")
def exact_params(params):
    """The shipped parameters with the unrounded trail (Appendix B prints 0.00432 for 0.0043202 m)."""
    return _with_geometry(params, mechanical_trail=_trail_through_wheel_centre_m(params))


def _trail_rounding_m(params) -> float:
    return abs(params["geometry.mechanical_trail"] - _trail_through_wheel_centre_m(params))


def _paper_drop_m(side: str, d_m: float, castor: float, kpi: float, steer: np.ndarray) -> np.ndarray:
    """Appendix A's closed-form downward displacement of the wheel centre (left; right with d, kpi signs flipped)."""
    if side == "left":
        return d_m * math.cos(castor) * math.sin(kpi) - d_m * (
            np.sin(steer) * math.sin(castor) + np.cos(steer) * math.sin(kpi) * math.cos(castor)
        )
    return d_m * math.cos(castor) * math.sin(kpi) + d_m * (
        np.sin(steer) * math.sin(castor) - np.cos(steer) * math.sin(kpi) * math.cos(castor)
    )


# --- Table B1 statics -------------------------------------------------------------------------------------

_PART_LADEN_XFAIL = pytest.mark.xfail(
    strict=True,
    reason=(
        "Table B1 part laden: W_r - W_l = 146 N, statics with y_cm = 0.0201 m give 146.205 N (0.2 N off); "
        "y_cm = 0.02007 m, which prints as 0.0201, closes it (see the printed-digits test below)"
    ),
)


@pytest.mark.parametrize(
    "case",
    [pytest.param(c, marks=_PART_LADEN_XFAIL) if c == "part_laden" else c for c in TABLE_B1_CASES],
)
def test_table_b1_wheel_loads_follow_from_statics(params, case):
    """The front wheels carry the chassis weight plus the unsprung mass, and the chassis mass centre's lateral
    offset y_cm shifts load to the right wheel by M g y_cm / y2 (moments about the car's centreline, contacts
    at +-y2). Table B1's loads satisfy both within 0.1 N."""
    c = params.case(case)
    g = params["vehicle.gravity"]
    weight_N = (c["chassis_mass"] + params["vehicle.unsprung_mass"]) * g
    load_shift_N = c["chassis_mass"] * g * c["chassis_cg_y"] / c["wheel_centre_y"]
    assert c["load_left"] + c["load_right"] == pytest.approx(weight_N, abs=0.1)
    assert c["load_right"] - c["load_left"] == pytest.approx(load_shift_N, abs=0.1)


@pytest.mark.parametrize("case", TABLE_B1_CASES)
def test_table_b1_lateral_mass_centre_agrees_to_printed_digits(params, case):
    """The lateral mass-centre offset implied by the Table B1 loads by moments about the centreline,
    y_cm = (W_r - W_l) y2 / (M g), rounds to the y_cm printed in Table B1 (4 decimals, so within 0.05 mm)."""
    c = params.case(case)
    implied_cg_y_m = (c["load_right"] - c["load_left"]) * c["wheel_centre_y"] / (
        c["chassis_mass"] * params["vehicle.gravity"]
    )
    assert abs(implied_cg_y_m - c["chassis_cg_y"]) <= 0.5e-4


# --- Steer axis -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("side", SIDES)
@pytest.mark.parametrize("case", TABLE_B1_CASES)
def test_steer_axis_passes_through_wheel_centre_in_side_view(params, case, side):
    """In side view the castored king-pin axis passes through the wheel centre C (the mechanical trail is
    (z2 - z1) tan(castor)): the perpendicular AC from C to the axis has no component along the axis frame's
    X2 (fore-aft) direction, only along -Y2 on the left and +Y2 on the right (Appendix A: AC' = (d sin delta,
    -d cos delta, 0) in X2, Y2, Z2 at delta = 0). The printed trail (0.00432 m) is rounded to 10 um,
    which bounds the fore-aft miss."""
    axis = steer_axis(params, case, side)
    x2, y2, _ = axis.axis_frame.T
    ac = axis.wheel_centre - axis.foot
    assert abs(np.dot(ac, x2)) <= 0.5e-5
    inboard_sign = -1.0 if side == "left" else 1.0
    assert np.dot(ac, y2) == pytest.approx(inboard_sign * axis.offset_d_m, rel=1e-9)
    # The axis height at C's fore-aft station, as seen from the side: x of the axis at z = z2 equals x of C.
    t = (axis.wheel_centre[2] - axis.top[2]) / axis.direction[2]
    assert abs(axis.top[0] + t * axis.direction[0] - axis.wheel_centre[0]) <= 0.5e-5


@pytest.mark.parametrize("case", TABLE_B1_CASES)
def test_offset_d_closed_form(params, case):
    """Perpendicular distance from C to the axis, from the Appendix B points by hand: with the axis through C
    in side view, d = (y2 - y1) cos(kpi) - (z2 - z1) sin(kpi) / cos(castor). It is the same on both sides."""
    g = params.sections["geometry"]
    c = params.case(case)
    chi, eps = g["kingpin_inclination"], g["castor_angle"]
    d_hand_m = (c["wheel_centre_y"] - g["kingpin_top_y"]) * math.cos(chi) - (
        g["wheel_centre_z"] - g["kingpin_top_z"]
    ) * math.sin(chi) / math.cos(eps)
    for side in SIDES:
        assert steer_axis(params, case, side).offset_d_m == pytest.approx(d_hand_m, abs=1e-9)


def test_offset_d_standard_and_with_spacers(params):
    """d = 0.0595 m for the standard car (reconstruction notes), and a spacer of thickness s moves the wheel
    centre outboard by s, so d grows by s cos(kpi): 0.0719, 0.1029, 0.1264 m for 12.7, 44.5, 68.5 mm (the
    notes print 0.1030 for 44.5 mm, but 0.0595108 + 0.0445 cos(0.219) = 0.102948)."""
    chi = params["geometry.kingpin_inclination"]
    d_standard_m = steer_axis(params, "unladen", "left").offset_d_m
    assert d_standard_m == pytest.approx(0.0595, abs=0.5e-4)
    for case, d_printed_m in zip(SPACER_CASES, (0.0719, 0.1029, 0.1264)):
        spacer_m = params.case(case)["extra_offset"]
        d_m = steer_axis(params, case, "left").offset_d_m
        assert d_m - d_standard_m == pytest.approx(spacer_m * math.cos(chi), abs=1e-10)
        assert d_m == pytest.approx(d_printed_m, abs=0.5e-4)


def test_scrub_radius_standard_car(params):
    """The standard car's king-pin axis meets the ground about 6 mm outboard of the contact centre (negative
    scrub, reconstruction notes); by hand, the axis is at y1 + (z3 - z1) tan(kpi) / cos(castor) = 0.7358 m at
    the ground against y2 = 0.73 m. Each spacer moves the contact, not the axis, outboard by its thickness."""
    g = params.sections["geometry"]
    axis_at_ground_y_m = g["kingpin_top_y"] + (g["ground_z"] - g["kingpin_top_z"]) * math.tan(
        g["kingpin_inclination"]
    ) / math.cos(g["castor_angle"])
    scrub_hand_m = params.case("unladen")["wheel_centre_y"] - axis_at_ground_y_m
    for side in SIDES:
        assert steer_axis(params, "unladen", side).scrub_radius_m() == pytest.approx(scrub_hand_m, abs=1e-6)
    assert scrub_hand_m == pytest.approx(-0.006, abs=0.5e-3)
    for case in SPACER_CASES:
        assert steer_axis(params, case, "right").scrub_radius_m() == pytest.approx(
            scrub_hand_m + params.case(case)["extra_offset"], abs=1e-6
        )


# --- Wheel drop ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("side", SIDES)
@pytest.mark.parametrize("case", TABLE_B1_CASES)
def test_wheel_drop_matches_appendix_a_closed_form(params, exact_params, case, side):
    """Rotating C about the king-pin axis (Rodrigues) lowers it by Appendix A's closed form: left
    d cos(e) sin(c) - d (sin(delta) sin(e) + cos(delta) sin(c) cos(e)), right
    d cos(e) sin(c) + d (sin(delta) sin(e) - cos(delta) sin(c) cos(e)), over the whole lock range.
    With the axis exactly through C in side view the two agree to rounding (1e-12 m). With the printed trail,
    the axis misses C fore-aft by the rounding D (0.17 um); that offset, turned by delta, changes the height
    by at most D (sin(castor) + sin(kpi)), 4e-8 m."""
    steer = LOCK_FRACTIONS * lock_steer_angle(params)
    g = params.sections["geometry"]
    for p, tolerance_m in (
        (exact_params, 1e-12),
        (params, _trail_rounding_m(params) * (math.sin(g["castor_angle"]) + math.sin(g["kingpin_inclination"]))),
    ):
        axis = steer_axis(p, case, side)
        expected = _paper_drop_m(side, axis.offset_d_m, g["castor_angle"], g["kingpin_inclination"], steer)
        np.testing.assert_allclose(axis.wheel_drop_m(steer), expected, rtol=0, atol=tolerance_m)


def test_body_rises_when_steered_either_way(params):
    """King-pin inclination lifts the body whichever way the wheels turn: the two contact points together go
    down relative to the body for any steer away from straight ahead, by 2 d cos(castor) sin(kpi)
    (1 - cos(delta)) (the sum of Appendix A's two closed forms; castor lowers one as much as it raises the
    other)."""
    d = steer_axis(params, "unladen", "left").offset_d_m
    eps, chi = params["geometry.castor_angle"], params["geometry.kingpin_inclination"]
    steer = LOCK_FRACTIONS * lock_steer_angle(params)
    total = sum(steer_axis(params, "unladen", side).wheel_drop_m(steer) for side in SIDES)
    assert np.all(total[steer != 0.0] > 0.0)
    at_lock_m = 2 * 0.0595 * math.cos(0.0108) * math.sin(0.219) * (1 - math.cos(lock_steer_angle(params)))
    assert total[-1] == pytest.approx(at_lock_m, rel=0.5e-4 / 0.0595)  # d printed to 0.1 mm
    np.testing.assert_allclose(total, 2 * d * math.cos(eps) * math.sin(chi) * (1 - np.cos(steer)), atol=1e-7)


# --- Equation (A1) -----------------------------------------------------------------------------------------


def _virtual_work_torque_Nm(params, case: str, steer: np.ndarray, step_rad: float = 1e-4) -> np.ndarray:
    """Handwheel torque from virtual work: d/d(delta) of W_l drop_l + W_r drop_r, by central differences, / G."""
    c = params.case(case)
    left, right = steer_axis(params, case, "left"), steer_axis(params, case, "right")

    def work_J(s):
        return c["load_left"] * left.wheel_drop_m(s) + c["load_right"] * right.wheel_drop_m(s)

    return (work_J(steer + step_rad) - work_J(steer - step_rad)) / (2 * step_rad) / steering_ratio(params)


@pytest.mark.parametrize("case", TABLE_B1_CASES)
def test_a1_is_the_virtual_work_of_the_wheel_loads(params, exact_params, case):
    """With the body fixed and a lossless steering system, the handwheel torque times G is the rate at which
    steering lowers the contact points against the static loads: tau = d/d(delta)[W_l drop_l + W_r drop_r] / G.
    Differentiating the Rodrigues wheel drop numerically reproduces equation (A1) to 1e-6 relative at every
    steer angle (including straight ahead, where only the small castor term remains). With the printed trail
    the fore-aft miss D adds at most (W_l + W_r) D (sin(castor) + sin(kpi)) / G (1e-5 N m)."""
    steer = LOCK_FRACTIONS * lock_steer_angle(params)
    np.testing.assert_allclose(
        _virtual_work_torque_Nm(exact_params, case, steer), lifting_torque_a1(exact_params, case, steer), rtol=1e-6
    )
    c = params.case(case)
    g = params.sections["geometry"]
    bound_Nm = (
        (c["load_left"] + c["load_right"])
        * _trail_rounding_m(params)
        * (math.sin(g["castor_angle"]) + math.sin(g["kingpin_inclination"]))
        / steering_ratio(params)
    )
    np.testing.assert_allclose(
        _virtual_work_torque_Nm(params, case, steer), lifting_torque_a1(params, case, steer), rtol=0, atol=bound_Nm
    )


def test_a1_parity(params):
    """The first term of (A1) is even in the steer angle and comes only from the load difference between the
    wheels (castor lowers one side as it raises the other); the second is odd. So with equal wheel loads
    steering left costs exactly the opposite of steering right, and with the Table B1 loads the even part is
    d (W_r - W_l) sin(castor) cos(delta) / G: 0.0052 N m straight ahead, by hand from the printed numbers."""
    steer = LOCK_FRACTIONS[LOCK_FRACTIONS > 0] * lock_steer_angle(params)
    c = params.case("unladen")
    mean_N = 0.5 * (c["load_left"] + c["load_right"])
    equal = dataclasses.replace(
        params, cases={**params.cases, "unladen": {**c, "load_left": mean_N, "load_right": mean_N}}
    )
    np.testing.assert_allclose(
        lifting_torque_a1(equal, "unladen", steer), -lifting_torque_a1(equal, "unladen", -steer), rtol=1e-14
    )
    ratio = 186.47 / 8.3682
    straight_ahead_Nm = 0.0595 * (2878 - 2698) * math.sin(0.0108) / ratio
    even_Nm = 0.5 * (lifting_torque_a1(params, "unladen", steer) + lifting_torque_a1(params, "unladen", -steer))
    d_rounding = 0.5e-4 / 0.0595  # d printed to 0.1 mm
    np.testing.assert_allclose(even_Nm, straight_ahead_Nm * np.cos(steer), rtol=d_rounding)
    assert lifting_torque_a1(params, "unladen", 0.0) == pytest.approx(straight_ahead_Nm, rel=d_rounding)


@pytest.mark.parametrize(
    ("case", "d_printed_m", "load_left_N", "load_right_N", "quoted_Nm"),
    [
        ("unladen", 0.0595, 2698.0, 2878.0, 1.7),
        ("offset_12_7mm", 0.0719, 2699.5, 2876.5, 2.1),
        ("offset_44_5mm", 0.1029, 2703.2, 2872.8, 3.0),
        ("offset_68_5mm", 0.1264, 2705.7, 2870.3, 3.7),
    ],
)
def test_a1_at_full_lock_by_hand(params, case, d_printed_m, load_left_N, load_right_N, quoted_Nm):
    """Equation (A1) at full right lock (four handwheel turns lock to lock: 12.566 rad, so
    delta = 12.566 / (186.47 / 8.3682) = 0.564 rad) worked by hand from the printed numbers: about 1.7 N m at
    the handwheel for the standard car, 2.1, 3.0 and 3.7 N m with the spacers. d is printed to 0.1 mm, which
    sets the tolerance (half a unit of its last digit, relative)."""
    ratio = 186.47 / 8.3682
    lock = 12.566 / ratio
    hand_Nm = (
        d_printed_m
        * (
            (load_right_N - load_left_N) * math.sin(0.0108) * math.cos(lock)
            + (load_right_N + load_left_N) * math.cos(0.0108) * math.sin(0.219) * math.sin(lock)
        )
        / ratio
    )
    code_Nm = lifting_torque_a1(params, case, lock_steer_angle(params))
    assert code_Nm == pytest.approx(hand_Nm, rel=0.5e-4 / d_printed_m)
    assert round(hand_Nm, 1) == quoted_Nm


def test_lifting_is_proportional_to_d(params):
    """The lifting torque is proportional to d (Appendix A): the four offset cases carry the same total load,
    so A1 / d differs between them only through the castor term's load difference, by at most
    |delta(W_r - W_l)| sin(castor) / G, while d itself more than doubles from the standard car to 68.5 mm."""
    steer = LOCK_FRACTIONS * lock_steer_angle(params)
    eps = params["geometry.castor_angle"]
    standard = params.case("unladen")
    d_standard_m = steer_axis(params, "unladen", "left").offset_d_m
    per_d_standard = lifting_torque_a1(params, "unladen", steer) / d_standard_m
    for case in SPACER_CASES:
        c = params.case(case)
        assert c["load_left"] + c["load_right"] == pytest.approx(standard["load_left"] + standard["load_right"])
        d_m = steer_axis(params, case, "left").offset_d_m
        load_difference_change_N = (c["load_right"] - c["load_left"]) - (standard["load_right"] - standard["load_left"])
        bound = abs(load_difference_change_N) * math.sin(eps) / steering_ratio(params) + 1e-12
        assert np.max(np.abs(lifting_torque_a1(params, case, steer) / d_m - per_d_standard)) <= bound
    assert steer_axis(params, "offset_68_5mm", "left").offset_d_m > 2 * d_standard_m


# --- Fig. A3 data -----------------------------------------------------------------------------------------


def test_fig_a3_data_spans_lock_to_lock_on_the_linear_linkage(params):
    """Fig. A3 runs from full left to full right lock (rack +-12.566 / 186.47 = +-67.4 mm) with the road-wheel
    angle 8.3682 rad per metre of rack, and its torque columns are (A1) for the standard car and the three
    spacers, negative at left lock and positive at right lock."""
    columns = lifting_curves(params)
    lock_rack_m = 12.566 / 186.47
    assert columns["rack_m"][0] == pytest.approx(-lock_rack_m, rel=1e-12)
    assert columns["rack_m"][-1] == pytest.approx(lock_rack_m, rel=1e-12)
    np.testing.assert_allclose(columns["steer_rad"], 8.3682 * columns["rack_m"], rtol=1e-12)
    assert np.any(columns["rack_m"] == 0.0)
    assert FIGA3_CASES == ("unladen", *SPACER_CASES)
    for case in FIGA3_CASES:
        torque = columns[torque_column(case)]
        assert torque[0] < 0.0 < torque[-1]


def test_fig_a3_summary_first_term_negligible(params):
    """The paper: the first (castor, load difference) term of (A1) makes a negligible contribution. At full lock
    its share is about (W_r - W_l) tan(castor) / ((W_r + W_l) sin(kpi) tan(delta)), by hand 0.25 % for the
    standard car; the summary reports it per case, with the lock torques 1.7 / 2.1 / 3.0 / 3.7 N m."""
    summary = lifting_summary(params)
    lock = 12.566 / (186.47 / 8.3682)
    first = (2878 - 2698) * math.sin(0.0108) * math.cos(lock)
    share_hand = first / (first + (2878 + 2698) * math.cos(0.0108) * math.sin(0.219) * math.sin(lock))
    assert summary["cases"]["unladen"]["first_term_share_at_right_lock"] == pytest.approx(share_hand, rel=1e-3)
    for case, quoted_Nm in zip(FIGA3_CASES, (1.7, 2.1, 3.0, 3.7)):
        entry = summary["cases"][case]
        assert 0.0 < entry["first_term_share_at_right_lock"] < 0.01
        assert round(entry["torque_at_right_lock_Nm"], 1) == quoted_Nm
