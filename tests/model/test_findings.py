"""Findings about the reconstruction, each as a test that fails on (or documents) the earlier behaviour."""

from __future__ import annotations

import math

import numpy as np
import pytest

from parksteer.figures.model import cycle_summary
from parksteer.geometry import steer_axis
from parksteer.model.numeric.simulate import simulate

from model_helpers import column_angle_per_rack, effect_documentation


@pytest.fixture(scope="module")
def hooke_phases(params):
    """The paper's cycle (unladen) at Hooke joint phase 0 (the parameter file's choice) and pi/2."""
    runs = {}
    for phase in (0.0, math.pi / 2):
        result = simulate("unladen", overrides={"steering.hooke_joint_phase": phase}, params=params)
        runs[phase] = cycle_summary(result.columns, params)
    return runs


def test_hooke_phase_moves_the_near_lock_torque_by_its_speed_ratio(params, hooke_phases):
    """Physical fact: the joint's speed ratio multiplies every rack-side share at the handwheel. With the lock at
    two column turns, phase 0 puts the ratio's peak 1/cos(alpha) at the locks, pi/2 its trough cos(alpha), so the
    near-lock torque differs by more than 2 N m (18.27 against 15.39 N m), not a ripple shifted along the cycle;
    the ratio of the two torques follows the ratio of d(column angle)/d(rack) at the two locks (within 5 %)."""
    at0, at90 = hooke_phases[0.0], hooke_phases[math.pi / 2]
    assert at0["torque_near_right_lock_Nm"] - at90["torque_near_right_lock_Nm"] > 2.0
    assert at0["torque_near_left_lock_Nm"] - at90["torque_near_left_lock_Nm"] < -2.0  # mirror image
    # lock at two column turns: the pinion angle near lock lies close to a multiple of pi, where the ratio peaks
    lock_pinion = params["steering.handwheel_to_rack_ratio"] * at0["rack_near_right_lock_m"]
    assert abs(lock_pinion / math.pi - round(lock_pinion / math.pi)) < 0.15
    speed_ratio = {phase: column_angle_per_rack(params.with_overrides({"steering.hooke_joint_phase": phase}),
                                                at["rack_near_right_lock_m"])
                   for phase, at in hooke_phases.items()}
    expected = speed_ratio[math.pi / 2] / speed_ratio[0.0]
    measured = at0["torque_near_right_lock_Nm"] / at90["torque_near_right_lock_Nm"]
    assert expected > 1.15
    assert measured == pytest.approx(expected, rel=0.05)


def test_hooke_phase_source_says_what_it_moves(params):
    """The parameter file's provenance of the phase must not call it a ripple shift (it moves the lock torque)."""
    source = params.source("steering.hooke_joint_phase")
    assert "only shifts the ripple" not in source
    assert "near-lock" in source


def test_a_car_in_gear_leaves_the_steered_pair_free_to_roll(params):
    """Physical fact (documents the braked_wheels correction): steering turns each wheel about its own axis, and
    pure rolling of the two patches needs wheel spins equal and opposite (the left patch centre travels forward
    while the right travels back). An open differential with its carrier held by the gearbox allows exactly that
    (it fixes only the mean of the two spins), so a front-drive car in gear is the free-rolling case, not braked."""
    for case in ("unladen", "offset_68_5mm"):
        spins = []
        for side in ("left", "right"):
            axis = steer_axis(params, case, side)
            contact = axis.wheel_centre + np.array([0.0, 0.0, axis.wheel_radius_m])
            velocity = np.cross(axis.direction, contact - axis.top)  # unit steer rate about the axis
            spins.append(velocity[0] / axis.wheel_radius_m)  # rolling takes up the travel along x
        left, right = spins
        assert abs(left - right) > 0.01  # the scrub needs the wheels to turn
        assert abs(left + right) < 1e-9 * abs(left - right)  # the held carrier (the mean) does not turn
    from parksteer.model.symbolic.components import with_effect_quantities

    source = with_effect_quantities(params).source("braked_wheels.brake_fraction")
    assert "front-drive car in gear with both wheels held" not in source


def test_torque_rack_figures_end_before_the_at_rest_friction_drop(params):
    """Physical fact: the smoothed friction F tanh(beta v) vanishes when the hand stops at the cycle's end, so the
    torque falls by several N m at rack 0 (16.7 to 12.8 N m unladen) with nothing moving: a model artefact. The
    plotted part of the cycle keeps every moving sample and ends before that fall."""
    from parksteer.figures.model import until_hand_stops

    c = simulate("unladen", params=params).columns
    keep = until_hand_stops(c, params)
    torque = c["handwheel_torque_Nm"]
    assert torque[keep][-1] - torque[-1] > 3.0  # the fall lies in the dropped samples
    assert np.all(keep[c["time_s"] < c["time_s"][-1] - params["input.reversal_rounding_time"]])
    assert np.max(np.abs(np.diff(torque[keep][-20:]))) < 0.5  # what is plotted ends smoothly


def test_fig13_legend_covers_no_curve(params):
    """The loads span the whole rack travel at four levels, so a legend inside the axes hides part of a curve;
    Fig. 13's legend sits wholly below the axes."""
    from parksteer.figures.model import PLOTTERS

    runs = [("unladen", "full"), ("part_laden", "full")]
    data = {run: simulate(run[0], params=params).columns for run in runs}
    fig = PLOTTERS["fig13"](params, runs, data, {})
    fig.canvas.draw()
    ax = fig.axes[0]
    legend = ax.get_legend().get_window_extent()
    assert legend.y1 < ax.get_window_extent().y0


def _brush_twist(m):
    """Bristle twist (in units of M / k_b) of the continuous brush disc in spin carrying the moment m M: the inverse
    of f(x) = x up to 3/4, then 1 - (27/256) / x^3."""
    m = np.asarray(m, dtype=float)
    return np.where(m <= 0.75, m, np.cbrt((27.0 / 256.0) / np.maximum(1.0 - m, 1e-300)))


def test_brush_patch_states_its_rounding_as_the_rigid_sidewall_bound():
    """Physical fact: a sidewall spring in series with the brush (compliance fraction phi, same total compliance
    1/k) leaves the sliding moment M and scales the knee's extra twist over the lumped law by (1 - phi); the
    brush_patch effect, which gives all of 1/k to the bristles, is the phi = 0 limit, an upper bound on the
    rounding. Checked on the continuous brush law, and the effect's documentation (docstring and docs section) says so."""
    m = np.linspace(0.0, 0.99, 200)
    all_bristles = _brush_twist(m) - m  # phi = 0: twist k theta / M minus the lumped law's
    for phi in (0.3, 0.7):
        series = phi * m + (1.0 - phi) * _brush_twist(m) - m
        assert np.allclose(series, (1.0 - phi) * all_bristles, atol=1e-12)
        assert np.all(series <= all_bristles + 1e-12)
    doc = effect_documentation("brush_patch")
    assert "series" in doc and "upper bound" in doc


def test_model_figure_titles_do_not_carry_a_figure_number_of_their_own(params):
    """The article numbers its figures itself; a plotted title "Fig. 12: ..." under the article's "Figure 4"
    contradicts it. The titles name the source's figure they reproduce without leading with a number."""
    import re

    from parksteer.figures.model import PLOTTERS

    runs = [("unladen", "full")]
    data = {runs[0]: simulate("unladen", params=params).columns}
    for name, plot in PLOTTERS.items():
        fig = plot(params, runs, data, {})
        for ax in fig.axes:
            assert not re.match(r"\s*Fig\.\s*\d+\s*:", ax.get_title()), (name, ax.get_title())
