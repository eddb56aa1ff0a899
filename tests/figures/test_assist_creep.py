"""Creeping over speed and tyre (parksteer.figures.assist_creep): the rolling tyre's share of the parking torque
over the turn-slip slope q_Dz8 at 1, 3 and 5 km/h, each number checked against the turn-slip law it comes from."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.cli import main
from parksteer.figures.assist_creep import CREEP_SPEEDS_KMH, crossover, creep_study, plateau_terms
from parksteer.figures.assist_study import CASE, SPIN_SLOPE_KEY
from parksteer.model.numeric.simulate import simulate
from parksteer.vehicle import CREEPING_EFFECTS, creeping_overrides


@pytest.fixture(scope="module")
def creep(params):
    return creep_study(params)


def _kept(params, q: float, speed_kmh: float, standstill_Nm: float) -> float:
    run = simulate(CASE, effects=CREEPING_EFFECTS, params=params,
                   overrides={**creeping_overrides(speed_kmh), SPIN_SLOPE_KEY: q})
    return plateau_terms(run, params)["tyre_Nm"] / standstill_Nm


def test_the_tyre_keeps_more_with_a_steeper_slope_and_less_the_faster_it_rolls(creep):
    """The turn-slip factor 1 / sqrt(1 + y^2) has y proportional to V / q_Dz8: at every speed the share of its
    standstill moment the rolling tyre keeps rises with q_Dz8 and stays below 1, and at every q_Dz8 it falls from
    1 to 3 to 5 km/h; the rack friction, a constant force, loses share of the road torque as the tyre's term grows."""
    kept = [np.asarray(creep["kept"][f"{v:g}"]) for v in CREEP_SPEEDS_KMH]
    for k in kept:
        assert np.all(np.diff(k) > 0.0) and np.all(k < 1.0) and np.all(k > 0.0)
    assert np.all(kept[0] > kept[1]) and np.all(kept[1] > kept[2])
    for v in CREEP_SPEEDS_KMH:
        assert np.all(np.diff(creep["rack_friction_share"][f"{v:g}"]) < 0.0)


def test_only_speed_over_slope_matters(creep, params):
    """y = V (1 - eps) c sqrt(W) / (q_Dz8 R0^2 |psi'|): scaling the speed and q_Dz8 by one factor leaves y, and so the
    whole run, unchanged. The tyre's kept share at (q, 1 km/h) equals the one at (3 q, 3 km/h) and (5 q, 5 km/h)
    within the integrator's tolerance."""
    standstill = creep["standstill"]["tyre_Nm"]
    for q in (0.02, 0.1):
        at_1 = _kept(params, q, 1.0, standstill)
        assert _kept(params, 3.0 * q, 3.0, standstill) == pytest.approx(at_1, rel=1e-5)
        assert _kept(params, 5.0 * q, 5.0, standstill) == pytest.approx(at_1, rel=1e-5)


def test_the_crossover_is_where_tyre_and_rack_friction_carry_alike(creep, params):
    """Where the study puts the crossover the tyre's share of the plateau's road torque equals the rack friction's
    (within 1e-4 of the road torque, the bisection's last bracket); by the similarity law above it grows in
    proportion to the speed (q*(3 km/h) = 3 q*(1 km/h)), and where it would pass the range's top, 1, there is none."""
    crossings = creep["crossover_q_dz8"]
    first = crossings[f"{CREEP_SPEEDS_KMH[0]:g}"]
    assert first is not None
    for v in CREEP_SPEEDS_KMH:
        q = crossings[f"{v:g}"]
        expected = first * v / CREEP_SPEEDS_KMH[0]
        if expected > 1.0:
            assert q is None
            continue
        assert q == pytest.approx(expected, rel=1e-4)
        run = simulate(CASE, effects=CREEPING_EFFECTS, params=params,
                       overrides={**creeping_overrides(v), SPIN_SLOPE_KEY: q})
        terms = plateau_terms(run, params)
        assert terms["tyre_share"] == pytest.approx(terms["rack_friction_share"], abs=1e-4)


def test_the_conclusion_follows_from_the_band_and_the_crossover(creep):
    """At each speed the band's verdict is the side of the crossover its ends lie on: "conditional" when the
    crossover falls inside the band, "tyre_below" when it lies above the band's top (or is absent with the tyre below
    at the top), "tyre_above" when it lies below the band's foot; and the passenger-car tyre's side is its slope
    against the crossover."""
    low, high = creep["band"]["q_dz8"]
    car = creep["band"]["passenger_car"]
    assert low < car < high
    for v in CREEP_SPEEDS_KMH:
        q = creep["crossover_q_dz8"][f"{v:g}"]
        verdict = creep["conclusion"][f"{v:g}"]
        top_below = creep["at"][f"{v:g}"][f"{high:g}"]["tyre_below_rack_friction"]
        if q is None:
            assert verdict["band"] == ("tyre_below" if top_below else "tyre_above")
            continue
        assert verdict["band"] == ("conditional" if low < q < high else "tyre_below" if q >= high else "tyre_above")
        assert verdict["passenger_car_tyre_below"] == (car < q)


def test_the_bisection_finds_a_known_root_and_none_without_a_sign_change():
    """On a margin with a known root, log(q / 0.3), the bisection in log q returns 0.3 to within its last bracket
    (a factor exp(log(100) / 2^20)); a margin of one sign over the range has no crossover."""
    assert crossover(lambda q: np.log(q / 0.3)) == pytest.approx(0.3, rel=1e-5)
    assert crossover(lambda q: q + 1.0) is None
    assert crossover(lambda q: -q) is None


def test_the_command_prints_the_study_and_refuses_an_unknown_case(creep, capsys):
    """`parksteer assist creep` prints, for the paper's car, the same crossovers and verdicts as the study (the
    first at 1 km/h, to the printed three decimals), and an unknown load case is refused in one line, status 2."""
    assert main(["assist", "creep"]) == 0
    out = capsys.readouterr().out
    first = creep["crossover_q_dz8"][f"{CREEP_SPEEDS_KMH[0]:g}"]
    assert f"1 km/h: tyre and rack friction carry alike at q_Dz8 {first:.3f}" in out
    assert main(["assist", "creep", "--case", "no_such_case"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--case no_such_case" in err[0]
