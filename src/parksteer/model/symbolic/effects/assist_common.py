"""What the power-assist effects share: the torsion bar, the smooth boost-curve pieces and the sensor torque.

No ``EFFECT`` here: the registry skips this module; :mod:`.electric_assist` and :mod:`.hydraulic_assist` use it.

It gives the torsion bar's deflection law, the smooth dead band and clamp of the boost curve and the boost table's
law (:func:`table_law`, :func:`table_slope`, :func:`table_law_node`), on sympy expressions and on numbers alike. The
derivation, its reasoning and its sources: docs/assist.md, "What the assists share (`assist_common`)".
"""

from __future__ import annotations

import numpy as np
from ..lazy_sympy import sp

from functools import cache

from .... import portable
from ....boost_table import MAX_POINTS, MAX_SPEEDS, PAD_STEP_MPS, PAD_STEP_NM, table_keys
from ....parameters import Quantity

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


def _tanh(x):
    # on numbers the portable tanh, the compiled model's own (portable_math.c): the C library's differs in the last
    # bit from one machine to another
    return sp.tanh(x) if isinstance(x, sp.Basic) else portable.tanh(x)


def directional_efficiency(motor, speed, forward, back, width, sharpness):
    """What the gear delivers per motor torque, in the direction the power flows: eta_f when the motor drives
    (motor torque and speed of one sign), 1 / eta_b when the point of action drives the motor. With the smooth
    sign of the power s = tanh(sharpness speed) motor / sqrt(motor^2 + width^2) in (-1, 1),

        factor = 1 + s g(s),   g(s) = (eta_f - 1) (1 + s) / 2 + (1 - 1 / eta_b) (1 - s) / 2,

    eta_f at s = 1, 1 / eta_b at s = -1, 1 at rest. g < 0 everywhere, so factor < 1 when the motor drives and > 1
    when it is driven: the power the gear loses, motor power x (1 - factor), is s g(s) times minus that power, never
    negative (the gear dissipates, never creates)."""
    s = _tanh(sharpness * speed) * motor / _sqrt(motor * motor + width * width)
    return 1 + s * ((forward - 1) * (1 + s) / 2 + (1 - 1 / back) * (1 - s) / 2)


def speed_gain(gain, dependence, speed, half_speed):
    """The boost curve's gain at the vehicle speed, G / (1 + s (v / v_half)^2) (:mod:`.electric_assist`): exactly G
    at v = 0 or s = 0. Plain arithmetic, so the symbolic model and the assisted replay's law share it."""
    return gain / (1 + dependence * (speed / half_speed) ** 2)


def series_deflection(model, twist, torsion_bar_key: str):
    """The column spring's deflection law with the torsion bar in series (docs/assist.md)."""
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


def _select(branches, otherwise):
    """The first branch (condition, value) whose condition holds, else `otherwise`: a Piecewise on sympy
    expressions, elementwise on numbers (every value is finite, so all are computed and one kept)."""
    if any(isinstance(c, sp.Basic) or isinstance(v, sp.Basic) for c, v in branches) or isinstance(otherwise, sp.Basic):
        return sp.Piecewise(*((v, c) for c, v in branches), (otherwise, True))
    conditions = [np.asarray(c) for c, _ in branches]
    return np.select(conditions, [np.asarray(v, dtype=float) for _, v in branches], np.asarray(otherwise, dtype=float))


def _hermite(x, t0, t1, a0, a1, m0, m1):
    """The cubic Hermite segment through (t0, a0), (t1, a1) with slopes m0, m1; exactly a0 at x = t0."""
    h = t1 - t0
    s = (x - t0) / h
    r = 1 - s
    return a0 * ((1 + 2 * s) * r * r) + h * m0 * (s * r * r) + a1 * (s * s * (3 - 2 * s)) + h * m1 * (s * s * (s - 1))


def _hermite_slope(x, t0, t1, a0, a1, m0, m1):
    """d/dx of :func:`_hermite`: 6 s r (a1 - a0) / h + m0 r (1 - 3 s) + m1 s (3 s - 2), s = (x - t0) / h, r = 1 - s."""
    h = t1 - t0
    s = (x - t0) / h
    r = 1 - s
    return 6 * s * r * (a1 - a0) / h + m0 * (r * (1 - 3 * s)) + m1 * (s * (3 * s - 2))


def _at_speed(speed, speeds, row_values):
    """One point's value at the vehicle speed, linear between the rows `row_values` at `speeds`, held beyond."""
    branches = [(speed < speeds[0], row_values[0])]
    for r in range(len(speeds) - 1):
        fraction = (speed - speeds[r]) / (speeds[r + 1] - speeds[r])
        branches.append((speed < speeds[r + 1], row_values[r] + fraction * (row_values[r + 1] - row_values[r])))
    return _select(branches, row_values[-1])


def table_points(value, speed):
    """(torque points, assists, slopes) of the boost table read at the vehicle speed `speed`, each point's assist
    and slope linear in speed between the rows; `value(key)` gives the table's scalar (``boost_torque_<k>``, ...)
    as a symbol or a number."""
    knots = [value(f"boost_torque_{k}") for k in range(MAX_POINTS)]
    speeds = [value(f"boost_speed_{r}") for r in range(MAX_SPEEDS)]
    assist = [_at_speed(speed, speeds, [value(f"boost_assist_{r}_{k}") for r in range(MAX_SPEEDS)])
              for k in range(MAX_POINTS)]
    slope = [_at_speed(speed, speeds, [value(f"boost_slope_{r}_{k}") for r in range(MAX_SPEEDS)])
             for k in range(MAX_POINTS)]
    return knots, assist, slope


def table_law(torque, value, speed, points=None):
    """The boost table's assist at the torsion-bar torque `torque` and the vehicle speed `speed` (docs/assist.md);
    `value(key)` gives the table's scalar (``boost_torque_<k>``, ...) as a symbol or a number. `points`, the
    :func:`table_points` of the same table and speed, spares a caller that evaluates the law many times reading
    them again (the same numbers)."""
    knots, assist, slope = points if points is not None else table_points(value, speed)

    def half(x):  # x >= 0
        branches = [(x < knots[k + 1], _hermite(x, knots[k], knots[k + 1], assist[k], assist[k + 1], slope[k],
                                                  slope[k + 1])) for k in range(MAX_POINTS - 1)]
        return _select(branches, assist[-1] + slope[-1] * (x - knots[-1]))

    if isinstance(torque, sp.Basic):
        return sp.Piecewise((half(torque), torque >= 0), (-half(-torque), True))
    torque = np.asarray(torque, dtype=float)
    if all(np.ndim(v) == 0 and not isinstance(v, sp.Basic) for v in (*knots, *assist, *slope)):
        magnitude = _half_numeric(np.abs(torque), knots, assist, slope)
    else:  # a point read at a speed that varies by sample: every segment, one kept
        magnitude = half(np.abs(torque))
    return np.where(torque >= 0, magnitude, -magnitude)


@cache
def table_functions() -> tuple[type, type]:
    """The two sympy functions that stand for :func:`table_law` in a model's expressions, ``BoostTableLaw`` and its
    torque derivative ``BoostTableSlope``, each of (torque, speed, the table's scalars in
    :func:`parksteer.boost_table.table_keys` order). A table of 32 points and 8 speeds is a Piecewise of 31
    segments over 64 values interpolated in speed; written out wherever the law enters (forcing, drive, outputs and
    the Jacobian's chain rule) it would triple the generated C. As one node, the generated C calls one function
    for it, whose body is :func:`table_law` itself printed once (``parksteer.model.codegen.generate``), so the C and
    the replay still evaluate one formula. Made on first use: the replay imports this module without sympy."""

    class BoostTableSlope(sp.Function):
        """table_slope, d(table_law)/d(torque), at (torque, speed, *table)."""

    class BoostTableLaw(sp.Function):
        """table_law at (torque, speed, *table)."""

        def fdiff(self, argindex=1):
            if argindex == 1:
                return BoostTableSlope(*self.args)
            return super().fdiff(argindex)

    return BoostTableLaw, BoostTableSlope


def table_law_node(torque, value, speed):
    """:func:`table_law` in a model's expressions: one function node of the torque, the speed and the table's
    scalars (:func:`table_functions`), evaluated in the generated C by the printed law."""
    law, _ = table_functions()
    return law(torque, speed, *(value(key) for key in table_keys()))


def table_slope(torque, value, speed, points=None):
    """d(:func:`table_law`)/d(torque): the derivative of the same segment the law takes (its Hermite segment's, the
    last point's slope beyond it), even in the torque. The generated C's Jacobian takes it (:func:`table_functions`)."""
    knots, assist, slope = points if points is not None else table_points(value, speed)

    def half(x):  # x >= 0
        branches = [(x < knots[k + 1], _hermite_slope(x, knots[k], knots[k + 1], assist[k], assist[k + 1], slope[k],
                                                        slope[k + 1])) for k in range(MAX_POINTS - 1)]
        return _select(branches, slope[-1] + 0 * x)

    if isinstance(torque, sp.Basic):
        return sp.Piecewise((half(torque), torque >= 0), (half(-torque), True))
    torque = np.asarray(torque, dtype=float)
    return half(np.abs(torque))


def _half_numeric(x, knots, assist, slope):
    """:func:`table_law`'s law for x >= 0 on numbers: each sample's own segment found (the first k with x <
    knots[k + 1], as the piecewise form selects it) and only that segment evaluated, with the same operations."""
    knots, assist, slope = (np.asarray(v, dtype=float) for v in (knots, assist, slope))
    k = np.searchsorted(knots[1:], x, side="right")  # len(knots) - 1 beyond the last point
    inner = np.minimum(k, len(knots) - 2)
    value = _hermite(x, knots[inner], knots[inner + 1], assist[inner], assist[inner + 1], slope[inner], slope[inner + 1])
    return np.where(k < len(knots) - 1, value, assist[-1] + slope[-1] * (x - knots[-1]))


def table_quantities(name: str, unit: str, slope_unit: str, where: str,
                     upper: float = 1.0e6) -> tuple[Quantity, ...]:
    """The scalar quantities of `name`'s boost table (:mod:`parksteer.boost_table`), the assist in `unit` (`where`
    names the point of action), its slopes in `slope_unit`, both bounded by `upper` (the padded points beyond a
    table's last continue its last slope); by default a table of zeros: no assist from the table."""
    table = "derived from [assist.boost] of the vehicle file; default 0: no table"
    out = [Quantity(f"{name}.boost_torque_{k}", "N m", 0.0, 100.0, lower_inclusive=True, default=k * PAD_STEP_NM,
                    description=f"boost table: torsion-bar torque of point {k}",
                    source="derived from [assist.boost] of the vehicle file (padded 1 N m apart beyond its last "
                           "point); default evenly spaced, unused without a table") for k in range(MAX_POINTS)]
    out += [Quantity(f"{name}.boost_speed_{r}", "m/s", 0.0, 200.0, lower_inclusive=True,
                     default=r * PAD_STEP_MPS, description=f"boost table: vehicle speed of row {r}",
                     source="derived from [assist.boost] of the vehicle file (one row: 0); default evenly spaced, "
                            "unused without a table") for r in range(MAX_SPEEDS)]
    for r in range(MAX_SPEEDS):
        out += [Quantity(f"{name}.boost_assist_{r}_{k}", unit, 0.0, upper, lower_inclusive=True, default=0.0,
                         description=f"boost table: assist {where} at point {k}, row {r}", source=table)
                for k in range(MAX_POINTS)]
        out += [Quantity(f"{name}.boost_slope_{r}_{k}", slope_unit, 0.0, upper, lower_inclusive=True, default=0.0,
                         description=f"boost table: Fritsch-Carlson slope at point {k}, row {r}", source=table)
                for k in range(MAX_POINTS)]
    return tuple(out)
