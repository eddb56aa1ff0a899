"""Ackermann steering linkage: inner and outer road wheels steer by different, nonlinear amounts (a candidate).

The paper's linkage steers both wheels by the same angle, roadwheel_to_rack_ratio * rack. A
steering-arm and track-rod linkage instead turns the inner wheel of a turn more than the
outer one. Both wheels roll about one point of the rear axle line (the Ackermann condition)
when cot(delta_outer) - cot(delta_inner) = track / wheelbase. Taking the paper's angle as the
reference (bicycle-model) angle, delta_m = roadwheel_to_rack_ratio * rack, the law

    cot(delta_right) = cot(delta_m) - a,   cot(delta_left) = cot(delta_m) + a,
    a = A (track / wheelbase) / 2,

i.e. delta_right/left = atan2(sin delta_m, cos delta_m -+ a sin delta_m), puts each wheel's
turning centre a distance A track / 2 from the reference one along the rear axle line: A = 1
meets the Ackermann condition exactly at every angle, A = 0 is the paper's parallel steer,
0 < A < 1 a partial Ackermann (anti-Ackermann, A < 0, is outside this candidate's range: a
strength is a size). Positive rack turns right, so the right wheel is the inner one; the law
is mirror-symmetric (delta_left(-rack) = -delta_right(rack)).
Each wheel's ratio is the paper's at the centre (the wheels differ by (track / wheelbase)
A delta_m^2 to leading order); the mean of the two exceeds delta_m by 2 % at the Maestro's
lock (0.56 rad).
"""

from __future__ import annotations

from ..lazy_sympy import sp

from ....parameters import Quantity
from ..components import Effect

SIDE_SIGN = {"left": -1, "right": 1}  # the right wheel is the inner one in a right turn (positive rack)


class Ackermann(Effect):
    name = "ackermann"
    description = (
        "Steering-arm geometry with Ackermann fraction A: cot(delta_right/left) = cot(delta_m) -+ A (track / "
        "wheelbase) / 2, delta_m = roadwheel_to_rack_ratio * rack; 0 = the paper's parallel linkage"
    )
    in_default_set = False
    quantities = (
        Quantity("ackermann.ackermann_fraction", "1", 0.0, 1.5, lower_inclusive=True, default=0.0,
                 source="candidate: fraction of the ideal Ackermann toe-out on turns; road cars typically have a "
                        "partial Ackermann, roughly 0.3-1; 0 = the paper's equal steer angles (absent)"),
        Quantity("ackermann.track_to_wheelbase", "1", 0.1, 2.0, lower_inclusive=True, default=0.582,
                 source="candidate: Austin Maestro front track 1.46 m (twice Table B1 y2) over wheelbase 2.507 m "
                        "(manufacturer's data), 0.582"),
    )
    uses = ("steering.roadwheel_to_rack_ratio", "ackermann.ackermann_fraction", "ackermann.track_to_wheelbase")
    replaces = "steer_function"

    def steer_angle(self, model, side):
        reference = model.p("steering.roadwheel_to_rack_ratio") * model.rack_q
        shift = model.p("ackermann.ackermann_fraction") * model.p("ackermann.track_to_wheelbase") / 2
        return sp.atan2(sp.sin(reference), sp.cos(reference) - SIDE_SIGN[side] * shift * sp.sin(reference))


EFFECT = Ackermann()
