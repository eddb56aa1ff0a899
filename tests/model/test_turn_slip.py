"""Parking while the car creeps: the turn-slip moment of a rolling wheel (MF 6.x), against its limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from parksteer.model.numeric.simulate import simulate
from parksteer.vehicle import creeping_overrides


@pytest.mark.parametrize("case, pressure_Pa", [("unladen", None), ("part_laden", None), ("unladen", 180000.0)])
def test_standstill_is_todays_torque_exactly(params, case, pressure_Pa):
    """At zero speed the wheel does not roll (infinite turn slip): the moment is equation (2)'s, so the handwheel
    torque is today's, across loads (two cases) and tyre pressures; the effect's moment is exactly zero there, and
    the two compiled models differ only in how the same sums are ordered (rounding, grown by the integration)."""
    overrides = {} if pressure_Pa is None else {"tyre.tyre_pressure": pressure_Pa}
    today = simulate(case, overrides=overrides, params=params)
    creeping = simulate(case, effects="+turn_slip", overrides={**overrides, **creeping_overrides(0.0)},
                        params=params)
    reference = today.columns["handwheel_torque_Nm"]
    assert np.max(np.abs(creeping.columns["handwheel_torque_Nm"] - reference)) < 1e-7 * np.max(np.abs(reference))  # far below the integrator tolerance
    assert np.max(np.abs(creeping.columns["contrib_turn_slip_Nm"])) == 0.0


def test_torque_falls_monotonically_with_speed(params):
    """The further the wheel rolls per radian of steer, the smaller its turn slip and its moment: the peak
    handwheel torque falls with every step of speed, towards what is left without the tyre (rack friction and
    lifting), which the air-bearing run gives."""
    peaks = []
    for speed_kmh in (0.0, 0.5, 1.0, 3.0, 5.0, 10.0):
        result = simulate("unladen", effects="+turn_slip", overrides=creeping_overrides(speed_kmh),
                          params=params)
        peaks.append(np.max(np.abs(result.columns["handwheel_torque_Nm"])))
    assert np.all(np.diff(peaks) < 0)
    floor = np.max(np.abs(simulate("unladen", surface="air_bearing", params=params).columns["handwheel_torque_Nm"]))
    assert peaks[-1] > floor and peaks[-1] - floor < 0.2 * (peaks[0] - floor)


def test_mf_standstill_moment_agrees_with_equation_2():
    """MF 6.x's standstill (infinite turn slip) moment M = QCRP1 mu_y R0 Fz sqrt(Fz / Fz0) with the published
    defaults of MF 6.1 (MFeval's default 205/60R15 at 2.2 bar: QCRP1 = 0.2, R0 = 0.3135 m, Fz0 = FNOMIN = 4000 N;
    LMP = 1) grows as Fz^1.5, as equation (2) does, and with the paper's friction coefficient (0.666 for MF's
    mu_y = PDY1 = 1.1) the two agree within 25 % over 2-6 kN at that pressure: two independent formulations of
    the parking moment, one fitted to drum tests, one derived from a contact-pressure distribution."""
    qcrp1, radius, fz0, mu = 0.2, 0.3135, 4000.0, 0.666
    p, p0, n = 220000.0, 245000.0, 0.78
    for fz in (2000.0, 4000.0, 6000.0):
        mf = qcrp1 * mu * radius * fz * math.sqrt(fz / fz0)
        eq2 = p0 ** (n - 0.5) * 2 * mu / (3 * math.sqrt(math.pi)) * fz ** 1.5 / p**n
        assert 0.75 < eq2 / mf < 1.25
    # the same exponent: the ratio does not depend on the load
    ratio = [p0 ** (n - 0.5) * 2 / (3 * math.sqrt(math.pi)) * fz ** 1.5 / p**n / (qcrp1 * radius * fz * math.sqrt(fz / fz0))
             for fz in (2000.0, 6000.0)]
    assert ratio[0] == pytest.approx(ratio[1], rel=1e-12)
