"""The size search of the benchmark's hidden effects (parksteer.synthetic.size_search.strength_for_rms).

Checked against closed forms: a torque change c s^p (a power of the size, as a small effect's change
is) reaches a target RMS T at s = (T / c)^(1/p).
"""

import functools

import numpy as np
import pytest

from parksteer.synthetic.size_search import SizeSearch, strength_for_rms

SHAPE = np.sin(np.linspace(0.0, 20.0, 400))
SEARCH = SizeSearch(iterations=12, tolerance=0.05, max_lag_s=0.3)


def _torque(power, calls):
    def torque_of(s):
        calls.append(s)
        return 3.0 + s**power * SHAPE
    return torque_of


@pytest.mark.parametrize("power, most_calls", [(1.0, 3), (2.0, 4), (0.5, 4), (3.0, 5)])
def test_a_power_law_change_is_matched_in_a_few_evaluations(power, most_calls):
    """The size found gives the target within the tolerance, and (the point of secant steps in log-log over
    bisection) in a handful of evaluations: one for the reference, the probe, a linear estimate, a secant step."""
    calls = []
    target = 0.7
    rms = float(np.sqrt(np.mean(SHAPE**2)))
    found = strength_for_rms(_torque(power, calls), target, 1e-3, 100.0, SEARCH)
    exact = (target / rms) ** (1.0 / power)
    assert found**power * rms == pytest.approx(target, rel=SEARCH.tolerance)
    assert found == pytest.approx(exact, rel=SEARCH.tolerance / power + 1e-9)
    assert len(calls) <= most_calls + 1


def test_an_effect_too_weak_at_its_largest_size_is_hidden_at_that_size():
    """If the upper bound changes the torque by less than the target, the upper bound is returned."""
    calls = []
    assert strength_for_rms(_torque(1.0, calls), 1e3, 1e-3, 10.0, SEARCH) == 10.0


def test_a_threshold_effect_is_still_found():
    """A change that is zero below a threshold and linear above it (a breakaway): the search leaves the flat part
    and lands within the tolerance."""
    def torque_of(s):
        return max(s - 2.0, 0.0) * SHAPE
    rms = float(np.sqrt(np.mean(SHAPE**2)))
    found = strength_for_rms(torque_of, 0.5, 1e-3, 100.0, SEARCH)
    assert (found - 2.0) * rms == pytest.approx(0.5, rel=SEARCH.tolerance)


def test_the_change_at_the_size_found_is_the_searchs_own_run():
    """The size the search returns is one it ran: under functools.cache (as the benchmarks wrap their torque of a
    size) reading its torque again to record the change runs nothing, and gives the closed form's c s^p there."""
    calls = []
    torque_of = functools.cache(_torque(2.0, calls))
    found = strength_for_rms(torque_of, 0.7, 1e-3, 100.0, SEARCH)
    searched = len(calls)
    again = torque_of(found)
    assert len(calls) == searched and found in calls
    assert len(set(calls)) == len(calls)
    np.testing.assert_array_equal(again, 3.0 + found**2 * SHAPE)
