"""What the power-assist effects share: the torsion bar, the smooth boost-curve pieces and the sensor torque.

No ``EFFECT`` here: the registry skips this module; :mod:`.electric_assist` and :mod:`.hydraulic_assist` use it.

Torsion bar. An assisted gear measures the driver's torque as the twist of a torsion bar between the
handwheel and the point where the assist acts. The model's column is massless, so the column shaft (the
paper's stiffness k_c) and the torsion bar (k_t) are two springs in series: they carry the same torque and
act as one spring of stiffness k_s = k_c k_t / (k_c + k_t). The effect fills the column_deflection slot with
g(x) = sqrt(k_s / k_c) x, so that the column torque (k_c g + c_c g' dx/dt) g' becomes
k_s x + c_c (k_s / k_c) dx/dt: the series stiffness, and a damping that keeps the column's time constant
c_c / k_c. The torsion-bar torque is then the column torque (series elements carry one torque); at the pinion
it is the column torque times d(theta_c)/d(theta_p) (the intermediate shaft's Hooke joint, if any).

Boost curve. The assist demand is a dead band, a slope and a limit, each corner smoothed by the hyperbola
ramp(z, w) = (z + sqrt(z^2 + w^2)) / 2 (a smooth max(z, 0), as the rack lash's dead band):

    deadband(x) = ramp(x - D) - ramp(-x - D)          (= x exactly at D = 0)
    clamp(y, L) = y - ramp(y - L) + ramp(-y - L)      (= 0 exactly at y = 0; -> y well inside +-L)

so the Jacobian stays continuous, a zero gain gives exactly no assist, and only sqrt (exact in IEEE
arithmetic) enters the generated C. The same three functions evaluate the law on numbers (the assisted replay,
:mod:`parksteer.model.numeric.assisted`): on sympy expressions they build the model's terms, on floats and numpy
arrays they compute them, with products for squares (no ``pow``) so the numbers are the same on every machine.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

LOCATIONS = ("column", "pinion", "rack")


def _sqrt(x):
    return sp.sqrt(x) if isinstance(x, sp.Basic) else np.sqrt(x)


def ramp(z, width):
    """A smooth max(z, 0): the hyperbola through the two asymptotes, within `width` of the corner."""
    return (z + _sqrt(z * z + width * width)) / 2


def deadband(x, band, width):
    """x less the band +-`band` (zero inside it), corners smoothed over `width`; x exactly when band = 0."""
    return ramp(x - band, width) - ramp(-x - band, width)


def clamp(y, limit, width):
    """y limited to +-`limit`, corners smoothed over `width`; zero exactly at y = 0."""
    return y - ramp(y - limit, width) + ramp(-y - limit, width)


def speed_gain(gain, dependence, speed, half_speed):
    """The boost curve's gain at the vehicle speed, G / (1 + s (v / v_half)^2) (:mod:`.electric_assist`): exactly G
    at v = 0 or s = 0. Plain arithmetic, so the symbolic model and the assisted replay's law share it."""
    return gain / (1 + dependence * (speed / half_speed) ** 2)


def series_deflection(model, twist, torsion_bar_key: str):
    """The column spring's deflection law with the torsion bar in series (module docstring)."""
    k_c = model.p("steering.column_torsional_stiffness")
    k_t = model.p(torsion_bar_key)
    return sp.sqrt(k_t / (k_c + k_t)) * twist


def torsion_bar_torque(model, location: str):
    """The torque the torsion bar carries: the column torque above the intermediate shaft (column assist), the
    column torque through the shaft's joint at the pinion (pinion, rack and hydraulic gears)."""
    k = model.kinematics
    if location == "column":
        return k.column_torque
    return k.column_torque * k.column_angle_per_rack / model.p("steering.handwheel_to_rack_ratio")


def point_of_action(model, location: str):
    """The coordinate x the assist turns or moves and its rate: the column angle (rad), the pinion angle (rad)
    or the rack (m)."""
    k = model.kinematics
    ratio = model.p("steering.handwheel_to_rack_ratio")
    if location == "column":
        return k.column_angle, k.column_rate
    if location == "pinion":
        return ratio * model.rack_q, ratio * model.rack_u
    return model.rack_q, model.rack_u
