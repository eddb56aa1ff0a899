"""Today's steering on the paper's car (parksteer.figures.assist_study): the assisted driver's torque, the rack
force of a creeping car and the mechanisms' shares, each checked against the physics it stands for."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.figures.assist_study import ASSISTS, CASE, assist_study
from parksteer.figures.model import plateau_mask, until_hand_stops
from parksteer.model.numeric.simulate import simulate


@pytest.fixture(scope="module")
def study(params, repo_root):
    import yaml

    config = yaml.safe_load((repo_root / "config" / "config.yaml").read_text(encoding="utf-8"))
    return assist_study(params, config["assist"]["target_torque"])


@pytest.mark.parametrize("kind", ASSISTS)
def test_the_assist_leaves_the_driver_less_torque_outside_the_dead_band(study, params, kind):
    """A boost curve adds torque in the driver's direction whenever the torsion bar carries more than the dead
    band D, so wherever the unassisted car needs more than 2 D the assisted driver needs less, over the whole
    cycle while the hand moves (the same prescribed handwheel angle in both runs). The margin: at a reversal the
    torque sweeps through the band in a few hundredths of a second and the motor, not pushing while the torsion
    bar is within it, lets the assisted torque lag the manual one by up to D there."""
    manual = study["_results"][(None, CASE, 0.0)].columns
    assisted = study["_results"][(kind, CASE, 0.0)].columns
    band = study["assists"][kind]["assumed"]["dead_band"]["value"]
    keep = until_hand_stops(manual, params) & (np.abs(manual["handwheel_torque_Nm"]) > 2.0 * band)
    assert keep.sum() > 0.8 * len(keep)
    assert np.all(np.abs(assisted["handwheel_torque_Nm"][keep]) < np.abs(manual["handwheel_torque_Nm"][keep]))


def test_the_peak_rack_force_falls_as_the_car_creeps(study, params):
    """The turn-slip moment of a rolling tyre (MF 6.x) falls as the distance rolled per steer angle grows, so the
    peak rack force over the cycle falls with speed at every step 0, 1, 3, 5 km/h, with and without assistance;
    and at 0 km/h the rolling-tyre model is the paper's own (the limit of no rolling)."""
    for run in study["runs"].values():
        force = run["speeds"]["peak_rack_force_N"]
        assert all(a > b for a, b in zip(force, force[1:]))
    paper = simulate(CASE, params=params).columns["handwheel_torque_Nm"]
    assert study["runs"]["none"]["peak_torque_Nm"] == pytest.approx(float(np.max(np.abs(paper))), rel=1e-6)


@pytest.mark.parametrize("where", ["plateau", "near_right_lock"])
def test_the_shares_add_up_to_the_road_torque(study, where):
    """The contributions are the generalized forces on the rack referred to the handwheel, so the mechanisms'
    terms add up to the road torque (shares summing to one) and the driver and the assist split it between them;
    who supplies the torque does not change what the tyres and the rack resist (each mechanism's term within 1 %
    of the unassisted car's)."""
    manual = study["runs"]["none"]["shares"][where]
    assert manual["driver_share"] == pytest.approx(1.0, abs=1e-12)
    for kind in ("none", *ASSISTS):
        s = study["runs"][kind]["shares"][where]
        assert sum(s["mechanism_shares"].values()) == pytest.approx(1.0, abs=1e-9)
        assert s["driver_share"] + s["assist_share"] == pytest.approx(1.0, abs=1e-6)
        for name, term in s["mechanisms_Nm"].items():
            if abs(manual["mechanisms_Nm"][name]) > 0.05:
                assert term == pytest.approx(manual["mechanisms_Nm"][name], rel=0.01), name


@pytest.mark.parametrize("kind", ASSISTS)
def test_the_driver_keeps_the_boost_curves_share(study, params, kind):
    """Quasi-statically, beyond the dead band D of a boost curve of gain G below its limit, the driver carries
    (T_road + G D) / (1 + G) of the road torque (electric_assist.py); on the plateau the simulated driver's torque
    is that within 5 % (the motor's or the seals' friction and the torsion bar's twist rate make the rest)."""
    s = study["runs"][kind]["shares"]["plateau"]
    gain = study["assists"][kind]["gain"]
    band = study["assists"][kind]["assumed"]["dead_band"]["value"]
    assert s["driver_torque_Nm"] == pytest.approx((s["road_torque_Nm"] + gain * band) / (1.0 + gain), rel=0.05)
    assert study["assists"][kind]["driver_share_limit"] == pytest.approx(1.0 / (1.0 + gain))


def test_the_standstill_rack_force_grows_with_the_tyre_ground_friction(study):
    """The tyre's bore torque at standstill (equation (2)) is proportional to the tyre-ground friction, and it is
    most of the standstill load: the peak rack force rises at every step of the band 0.67, 0.8, 1.0, by less than
    the friction's ratio (rack friction and lifting do not grow with it); the rack's Coulomb friction is fully
    developed where the rack slides at the peak, so without it the peak is the force less the source's 730 N; and
    each friction is below, within or above the published class range, exactly once, as its force says."""
    band = study["friction_band"]
    force = band["peak_rack_force_N"]
    assert all(a < b for a, b in zip(force, force[1:]))
    assert force[-1] / force[0] < band["friction"][-1] / band["friction"][0]
    assert band["rack_friction_force_N"] == 730.0
    assert [f - w for f, w in zip(force, band["peak_rack_force_without_rack_friction_N"])] == pytest.approx(
        [730.0] * 3, abs=1e-6)
    low, high = band["published_standstill_rack_force_N"]
    for f, x in zip(band["friction"], force):
        places = [f in band["below_published_at"], f in band["within_published_at"], f in band["above_published_at"]]
        assert places == [x < low, low <= x <= high, x > high]


def test_the_motor_sized_at_the_class_range_is_linear_in_the_rack_force(study, params):
    """Quasi-statically the column assist carries the column torque F / c' less the driver's target, through a worm
    of ratio N and efficiency eta against the rotor's friction T_f: T_m = ((F / c' - T) / N + T_f) / eta, linear in
    the rack force F. Its three points (the model's own peak and the class range's 3 and 8 kN) lie on one line whose
    slope, 1 / (c' N eta), gives back a lever c' within the gear's range at the peak (the Hooke joint moves it about
    the pinion ratio 186.47 rad/m by the joint's speed ratio, cos 0.45 = 0.90 to 1 / 0.90)."""
    load = study["class_load"]
    force, motor = np.asarray(load["rack_force_N"]), np.asarray(load["motor_torque_Nm"])
    slope = (motor[2] - motor[1]) / (force[2] - force[1])
    assert motor[0] == pytest.approx(motor[1] + slope * (force[0] - force[1]), rel=1e-9)
    assumed = study["assists"]["column"]["assumed"]
    lever = 1.0 / (slope * assumed["reduction_ratio"]["value"] * assumed["efficiency"]["value"])
    ratio = params["steering.handwheel_to_rack_ratio"]
    assert 0.89 * ratio < lever < ratio / 0.89
    assert load["rack_force_N"][1:] == study["friction_band"]["published_standstill_rack_force_N"]


def test_a_steeper_turn_slip_slope_keeps_more_of_the_tyre_moment(study):
    """The turn-slip factor 1 / sqrt(1 + y^2) has y proportional to 1 / q_Dz8: the larger q_Dz8, the less the
    rolling removes, so at every creeping speed the tyre keeps more of its standstill moment, and the peak rack
    force is larger, at the band's top than at the passenger-car tyre's 0.296 than at its foot 0.05; the 0.05 runs
    are the study's own creeping runs (the turn_slip effect's default)."""
    spin = study["spin_slope_band"]
    kept = [spin["tyre_moment_kept"][f"{q:g}"] for q in spin["q_dz8"]]
    force = [spin["peak_rack_force_N"][f"{q:g}"] for q in spin["q_dz8"]]
    for i in range(1, 4):
        assert kept[0][i] < kept[1][i] < kept[2][i] <= 1.0
        assert force[0][i] < force[1][i] < force[2][i]
    assert force[0] == pytest.approx(study["runs"]["none"]["speeds"]["peak_rack_force_N"], rel=1e-12)
