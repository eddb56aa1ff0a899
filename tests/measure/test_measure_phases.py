"""Cycle phases found on synthetic cycles whose phase boundaries are known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure.converter import quantise
from parksteer.measure.phases import find_phases, local_linear_fit

SPEED_M_S = 0.015  # rack speed at 2.8 rad/s of handwheel (about 15 mm/s)
LOCK_M = 0.06
RACK_SHARE_NM = 4.0  # rack friction at the handwheel: the torque needed before the rack moves
REVERSAL_DROP_NM = 8.0  # twice the rack share
PLATEAU_NM = 15.0
WINDUP_M = 0.02  # rack travel to twist the carcasses from straight ahead to sliding

# Known boundaries of the cycle built below (s). The wind-up ends where the torque has covered 90 %
# of its change: after 0.9 * 20 mm from rest, after 0.9 * 40 mm after a reversal (the carcass
# unwinds and winds up the other way), at 15 mm/s.
REST_S = 1.0
T_RIGHT_LOCK = REST_S + LOCK_M / SPEED_M_S  # 5 s
T_LEFT_LOCK = T_RIGHT_LOCK + 2 * LOCK_M / SPEED_M_S  # 13 s
T_CENTRE = T_LEFT_LOCK + LOCK_M / SPEED_M_S  # 17 s
WINDUP_ENDS = (
    REST_S + 0.9 * WINDUP_M / SPEED_M_S,  # 2.2 s
    T_RIGHT_LOCK + 0.9 * 2 * WINDUP_M / SPEED_M_S,  # 7.4 s
    T_LEFT_LOCK + 0.9 * 2 * WINDUP_M / SPEED_M_S,  # 15.4 s
)


def cycle(time_s: np.ndarray, ground: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Rack and torque of an idealised cycle: rest, right lock, left lock, back to centre, rest.

    At rest the hand winds the torque up to the rack friction; each stroke starts at the rack
    share (plus the carcass moment left from the previous stroke) and rises linearly with rack
    travel until the carcasses slide, then stays flat. On air bearings only the rack share is left.
    """
    t = np.asarray(time_s)
    rack = np.interp(t, [0, REST_S, T_RIGHT_LOCK, T_LEFT_LOCK, T_CENTRE, 20.0], [0, 0, LOCK_M, -LOCK_M, 0, 0])
    tyre = PLATEAU_NM - RACK_SHARE_NM
    torque = np.empty_like(t)
    rest = t < REST_S
    torque[rest] = RACK_SHARE_NM * t[rest] / REST_S
    s1 = (t >= REST_S) & (t < T_RIGHT_LOCK)
    travel = SPEED_M_S * (t[s1] - REST_S)
    torque[s1] = RACK_SHARE_NM + tyre * np.minimum(travel / WINDUP_M, 1.0)
    s2 = (t >= T_RIGHT_LOCK) & (t < T_LEFT_LOCK)
    travel = SPEED_M_S * (t[s2] - T_RIGHT_LOCK)
    torque[s2] = -RACK_SHARE_NM + tyre - 2 * tyre * np.minimum(travel / (2 * WINDUP_M), 1.0)
    s3 = t >= T_LEFT_LOCK
    travel = SPEED_M_S * (np.minimum(t[s3], T_CENTRE) - T_LEFT_LOCK)
    torque[s3] = RACK_SHARE_NM - tyre + 2 * tyre * np.minimum(travel / (2 * WINDUP_M), 1.0)
    if not ground:
        torque = np.where(rest, torque, np.sign(torque) * RACK_SHARE_NM)
        torque[s2] = -RACK_SHARE_NM
        torque[s3] = RACK_SHARE_NM
    return rack, torque


def logged(t, rack, torque, seed=0, torque_noise=0.15, rack_noise=2e-4):
    """The logger's view: analog noise, then 8 bits over +-0.1 m and +-25 N m."""
    rng = np.random.default_rng(seed)
    return (
        quantise(rack + rng.normal(0.0, rack_noise, t.size), 0.1),
        quantise(torque + rng.normal(0.0, torque_noise, t.size), 25.0),
    )


TIME_50HZ = np.arange(0.0, 18.0 + 1e-9, 0.02)
GROUND_SEQUENCE = [
    "initial_rise",
    *("wind_up", "plateau", "reversal"),
    *("wind_up", "plateau", "reversal"),
    *("wind_up", "return"),
]


def boundaries(phases, name):
    return [s.start_s for s in phases.segments if s.phase == name]


@pytest.mark.parametrize("torque_noise, seed", [(0.0, 0), (0.15, 1), (0.15, 2), (0.4, 3)])
def test_noisy_quantised_cycle_gives_the_known_phases(torque_noise, seed):
    """Initial rise until the rack moves at 1 s; wind-ups end at 90 % of the torque change (2.2, 7.4, 15.4 s);

    the reversals at 5 s and 13 s hold the friction drop; the final stroke is the return."""
    rack, torque = cycle(TIME_50HZ)
    rack_q, torque_q = logged(TIME_50HZ, rack, torque, seed, torque_noise)
    phases = find_phases(TIME_50HZ, rack_q, torque_q)
    assert [s.phase for s in phases.segments] == GROUND_SEQUENCE
    np.testing.assert_allclose(phases.reversal_times_s, [T_RIGHT_LOCK, T_LEFT_LOCK], atol=0.05)
    first_stroke = phases.segments[1].start_s
    assert first_stroke == pytest.approx(REST_S, abs=0.15)
    ends = [s.stop_s for s in phases.segments if s.phase == "wind_up"]
    np.testing.assert_allclose(ends, WINDUP_ENDS, atol=0.2)
    for seg in phases.segments:
        if seg.phase == "reversal":
            t_turn = T_RIGHT_LOCK if seg.start_s < 9 else T_LEFT_LOCK
            assert seg.start_s <= t_turn - 0.2 and seg.stop_s >= t_turn + 0.2, "the drop lies inside"
            assert seg.stop_s - seg.start_s < 1.0, "a short window"
    plateau_torques = [s.plateau_torque_Nm for s in phases.strokes]
    np.testing.assert_allclose(plateau_torques, [PLATEAU_NM, -PLATEAU_NM, PLATEAU_NM], atol=0.3)


def test_hooke_joint_ripple_does_not_move_the_wind_up_ends_much():
    """A +-10 % torque ripple at 0.9 Hz (Hooke joint at 0.45 rad, 2.8 rad/s) shifts each 90 % crossing by

    at most the ripple amplitude over the wind-up slope: 1.5 N m / (11 N m per 1.33 s) = 0.18 s."""
    rack, torque = cycle(TIME_50HZ)
    torque = torque * (1.0 + 0.1 * np.sin(2 * np.pi * 0.9 * TIME_50HZ))
    phases = find_phases(TIME_50HZ, *logged(TIME_50HZ, rack, torque, seed=4))
    assert [s.phase for s in phases.segments] == GROUND_SEQUENCE
    np.testing.assert_allclose([s.stop_s for s in phases.segments if s.phase == "wind_up"], WINDUP_ENDS, atol=0.3)


def test_uneven_sampling_gives_the_same_phases():
    """Dropping a random tenth of the samples (a logger that missed some) changes no boundary materially."""
    keep = np.random.default_rng(6).uniform(size=TIME_50HZ.size) > 0.1
    t = TIME_50HZ[keep]
    rack, torque = cycle(t)
    phases = find_phases(t, *logged(t, rack, torque, seed=6))
    assert [s.phase for s in phases.segments] == GROUND_SEQUENCE
    np.testing.assert_allclose([s.stop_s for s in phases.segments if s.phase == "wind_up"], WINDUP_ENDS, atol=0.25)


def test_air_bearings_have_no_carcass_wind_up():
    """On air bearings the tyres turn freely: after the initial rise the torque is at once the rack share."""
    rack, torque = cycle(TIME_50HZ, ground=False)
    phases = find_phases(TIME_50HZ, *logged(TIME_50HZ, rack, torque, seed=7), surface="air_bearing")
    sequence = [s.phase for s in phases.segments]
    assert sequence == ["initial_rise", "plateau", "reversal", "plateau", "reversal", "return"]


def test_a_pause_of_the_hand_is_not_a_reversal():
    """The hand stopping for 0.6 s mid-stroke leaves the rack still, not reversed: still two reversals."""
    t = TIME_50HZ
    pause = (9.0, 9.6)
    t_shifted = np.where(t < pause[0], t, np.where(t < pause[1], pause[0], t - (pause[1] - pause[0])))
    rack, torque = cycle(t_shifted)
    phases = find_phases(t, *logged(t, rack, torque, seed=8))
    assert len(phases.reversal_times_s) == 2 and len(phases.strokes) == 3


def test_local_linear_fit_is_exact_for_a_line_and_a_rack_at_rest_is_refused():
    """A least-squares line through a straight line is that line; a record with no motion has no cycle."""
    t = np.sort(np.random.default_rng(1).uniform(0, 5, 300))
    value, slope = local_linear_fit(t, 0.015 * t - 0.01, 0.5)
    np.testing.assert_allclose(slope, 0.015, rtol=1e-9)
    np.testing.assert_allclose(value, 0.015 * t - 0.01, atol=1e-12)
    with pytest.raises(UsageError, match="never moves"):
        find_phases(t, np.zeros_like(t), np.ones_like(t))
    with pytest.raises(UsageError, match="unknown surface"):
        find_phases(t, t, t, surface="ice")
