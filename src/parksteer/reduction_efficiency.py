"""The efficiencies of an assist's reduction from its geometry and friction: a worm gear, a ball nut.

Both are a thread of lead angle lambda against a contact of friction coefficient mu, rho = atan(mu):
eta_f = tan(lambda) / tan(lambda + rho) driven from the screw (the motor drives), and
eta_b = tan(lambda - rho) / tan(lambda) driven from the wheel or the rack (back-driven), 0 when lambda <= rho (the
thread locks itself): the textbook worm-gear efficiencies in the lead angle (the flank's pressure angle left out, as
worm-gear calculators give them: novasolver.jp, "Worm gear efficiency & self-locking calculator"). For a ball nut
tan(lambda) = L / (pi d), lead L and ball circle diameter d, and the same expressions are the ball-screw
catalogues' forward and reverse efficiencies written in mu. Angles in rad, efficiencies dimensionless. The
derivation and the shipped gears' numbers: docs/assist.md, "The gear's efficiencies, both ways".

Only the four operations and tan/atan of the portable library: the same bits on every machine.
"""

from __future__ import annotations

from . import portable as pm

PI = 3.141592653589793


def forward_efficiency(lead_angle_rad: float, friction_angle_rad: float) -> float:
    """eta_f = tan(lambda) / tan(lambda + rho): the thread driven from the screw (the motor drives)."""
    if not 0.0 < lead_angle_rad < PI / 2 or not 0.0 <= friction_angle_rad < PI / 2 - lead_angle_rad:
        raise ValueError(f"lead angle {lead_angle_rad:g} rad, friction angle {friction_angle_rad:g} rad: need "
                         "0 < lambda, 0 <= rho, lambda + rho < pi/2")
    return pm.tan(lead_angle_rad) / pm.tan(lead_angle_rad + friction_angle_rad)


def back_efficiency(lead_angle_rad: float, friction_angle_rad: float) -> float:
    """eta_b = tan(lambda - rho) / tan(lambda): the thread driven from the wheel or rack; 0 when it locks itself
    (lambda <= rho)."""
    if not 0.0 < lead_angle_rad < PI / 2 or not 0.0 <= friction_angle_rad < PI / 2:
        raise ValueError(f"lead angle {lead_angle_rad:g} rad, friction angle {friction_angle_rad:g} rad: need "
                         "0 < lambda < pi/2, 0 <= rho < pi/2")
    if lead_angle_rad <= friction_angle_rad:
        return 0.0
    return pm.tan(lead_angle_rad - friction_angle_rad) / pm.tan(lead_angle_rad)


def friction_angle(friction_coefficient: float) -> float:
    """rho = atan(mu)."""
    return pm.atan(friction_coefficient)


def ball_nut_lead_angle(lead_m: float, ball_circle_diameter_m: float) -> float:
    """lambda = atan(L / (pi d)): the lead angle of a ball nut of lead L on a ball circle of diameter d."""
    if not lead_m > 0.0 or not ball_circle_diameter_m > 0.0:
        raise ValueError(f"lead {lead_m:g} m, ball circle diameter {ball_circle_diameter_m:g} m: both positive")
    return pm.atan(lead_m / (PI * ball_circle_diameter_m))


def lead_angle_for_forward(forward: float, friction_angle_rad: float) -> float:
    """The lead angle lambda at which the thread of friction angle rho drives at eta_f = `forward` (the smaller of
    the two roots: eta_f rises with lambda up to its peak at lambda = pi/4 - rho/2). Bisection on the monotone
    branch, only comparisons and the formula."""
    peak = PI / 4 - friction_angle_rad / 2
    if not 0.0 < forward < forward_efficiency(peak, friction_angle_rad):
        raise ValueError(f"eta_f {forward:g}: above the thread's best efficiency at friction angle "
                         f"{friction_angle_rad:g} rad")
    low, high = 1e-12, peak
    for _ in range(200):
        middle = 0.5 * (low + high)
        if middle in (low, high):
            break
        if forward_efficiency(middle, friction_angle_rad) < forward:
            low = middle
        else:
            high = middle
    return 0.5 * (low + high)


def friction_angle_for_forward(forward: float, lead_angle_rad: float) -> float:
    """The friction angle rho at which a thread of lead angle lambda drives at eta_f = `forward`:
    tan(lambda + rho) = tan(lambda) / eta_f, so rho = atan(tan(lambda) / eta_f) - lambda."""
    if not 0.0 < forward <= 1.0:
        raise ValueError(f"eta_f {forward:g}: in (0, 1]")
    return pm.atan(pm.tan(lead_angle_rad) / forward) - lead_angle_rad


def directional_slope_floor(forward: float, back: float, samples: int = 20001) -> float:
    """The least value over s in [-1, 1] of E(s) = min(f(s), f(s) + (1 - s^2) s f'(s)), f(s) = 1 + s g(s) the
    assist's directional factor with g(s) = (eta_f - 1)(1 + s)/2 + (1 - 1/eta_b)(1 - s)/2
    (:func:`parksteer.model.symbolic.effects.assist_common.directional_efficiency`).

    Why this is the condition. The gear delivers h(m) = m f(s) for the motor torque m, s = c u, u = m / sqrt(m^2 +
    w^2), c = tanh(rotor speed / w_speed) in (-1, 1), and m = w u / sqrt(1 - u^2) rises with u, so h rises with m
    iff it rises with u: dh/du = w (1 - u^2)^(-3/2) (f(s) + s (1 - u^2) f'(s)). For a given s, u = s / c ranges over
    |u| >= |s|, so
    1 - u^2 ranges over (0, 1 - s^2]; the bracket is linear in 1 - u^2, so it is positive at every speed iff it is
    at both ends: f(s) > 0 and f(s) + (1 - s^2) s f'(s) > 0. E is a quartic in s, sampled on a grid holding its
    ends and 0 (its least value is interior on the motor-driving side, s > 0, where s f' < 0)."""
    a, b = forward - 1.0, 1.0 - 1.0 / back
    least = None
    for i in range(samples):
        s = -1.0 + 2.0 * i / (samples - 1)
        f = 1.0 + s * (a + b) / 2.0 + s * s * (a - b) / 2.0
        edge = f + (1.0 - s * s) * s * ((a + b) / 2.0 + s * (a - b))
        value = f if f < edge else edge
        least = value if least is None or value < least else least
    return least


def min_monotone_back_efficiency(forward: float, tolerance: float = 1e-6) -> float:
    """The least eta_b (to `tolerance`, rounded up) at which the assist's delivered torque rises with the motor
    torque at every rotor speed, given eta_f = `forward` (:func:`directional_slope_floor` >= 0; the floor rises with
    eta_b). The assisted replay inverts T + A(T) = y and needs A increasing (model.numeric.assisted)."""
    low, high = tolerance, 1.0
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        if directional_slope_floor(forward, middle, samples=2001) >= 0.0:
            high = middle
        else:
            low = middle
    return high
