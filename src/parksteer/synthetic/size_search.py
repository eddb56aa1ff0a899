"""The size of a hidden thing that changes a data set's torque by a given RMS (:func:`strength_for_rms`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import portable as pm


def rms_difference(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


@dataclass(frozen=True)
class SizeSearch:
    """How the size of a hidden thing is found: evaluations of the search beyond its probe (the setting keeps its
    historical name, bisection_iterations, in the configuration), accepted relative error of the RMS change, and
    the largest lag of the torque channel searched (s)."""

    iterations: int
    tolerance: float
    max_lag_s: float


def strength_for_rms(torque_of, target_Nm: float, start: float, upper: float, search: SizeSearch) -> float:
    """The size s (from 0 up) at which RMS(torque_of(s) - torque_of(0)) = target: secant steps in log-log.

    The RMS change of a small effect grows as a power of its size (linearly for most; faster for
    one with a threshold), so a straight line through two points in log(size), log(change) lands
    close to the target at once: from the probe `start`, a linearised estimate (change
    proportional to size), then secant steps through the last two points, each kept inside the
    bracket known so far (a step outside it, or a change that does not grow with the size, falls
    back to halving the bracket in the logarithm). Stops when the RMS change is within
    ``search.tolerance`` of the target, after at most ``search.iterations`` evaluations beyond the probe.
    If even `upper` changes the torque by less than the target, `upper` is returned (the caller
    records the change it actually makes).
    """
    reference = torque_of(0.0)

    def change(s: float) -> float:
        return rms_difference(torque_of(s), reference)

    def close(value: float) -> bool:
        return abs(value - target_Nm) <= search.tolerance * target_Nm

    low, high = 0.0, float(upper)  # sizes known to give less / more than the target
    bounded = False  # whether `high` has been evaluated (or upper tried)
    points = [(float(min(start, upper)), change(float(min(start, upper))))]
    for _ in range(search.iterations):
        s, value = points[-1]
        if close(value):
            return s
        if value < target_Nm:
            low = max(low, s)
            if s >= upper:
                return upper
        else:
            high = min(high, s)
        if len(points) == 1 or value <= 0.0:
            guess = s * target_Nm / value if value > 0.0 else s * 4.0  # linearised: change proportional to size
        else:
            (s0, v0), (s1, v1) = points[-2], points[-1]
            slope = pm.log(v1 / v0) / pm.log(s1 / s0) if v0 > 0.0 and s0 != s1 and v1 != v0 else 0.0
            guess = s1 * pm.power(target_Nm / v1, 1.0 / slope) if slope > 0.0 else -1.0
        if not low < guess < high:  # outside the bracket
            if guess >= high and not bounded:
                guess = upper  # nothing above has reached the target yet: try the largest size itself
            elif low > 0.0:
                guess = math.sqrt(low * high)  # halve the bracket in the logarithm
            else:
                guess = high / 4.0
        bounded = bounded or guess >= upper or value >= target_Nm
        points.append((guess, change(guess)))
    return points[-1][0]
