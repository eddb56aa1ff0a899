"""Braked front wheels: the contact patch cannot roll, so it also slides sideways about the steer axis.

Strength s: the brake fraction (0 = rolling freely, 1 = locked); it adds the drag part of the braked pin torque (N
m) to each tread ring's friction moment. Requires tyre_friction. The derivation, its reasoning and its sources:
docs/model.md, "Braked wheels (`braked_wheels`)".
"""

from __future__ import annotations

from fractions import Fraction

from ..lazy_sympy import me, sp

from ....names import SIDES
from ....parameters import Quantity
from ..components import Effect
from .tyre_friction import EFFECT as TYRE_FRICTION

# f(k) - 1 inside the patch, as a polynomial in m = k^2 (series of the elliptic closed form)
_INSIDE_COEFFICIENTS = (Fraction(3, 4), -Fraction(3, 64), -Fraction(1, 256), -Fraction(15, 16384),
                        -Fraction(21, 65536))
# f(k) / (3 k / 2) outside the patch, as a polynomial in 1 / k^2 (far-field series of the same integral)
_OUTSIDE_COEFFICIENTS = (1, Fraction(1, 8), Fraction(1, 192), Fraction(1, 1024))


def braked_excess_ratio(k_squared):
    """f(k) - 1: the braked pin torque over the spin torque, minus one, at (scrub offset / patch radius)^2."""
    inside = sum(c * k_squared ** (i + 1) for i, c in enumerate(_INSIDE_COEFFICIENTS))
    k = sp.sqrt(k_squared)
    outside = sp.Rational(3, 2) * k * sum(c / k_squared**i for i, c in enumerate(_OUTSIDE_COEFFICIENTS)) - 1
    return sp.Piecewise((inside, k_squared <= 1), (outside, True))


class BrakedWheels(Effect):
    name = "braked_wheels"
    description = (
        "Wheels held by the brakes: the patch slides rigidly about the steer axis's ground intercept, adding "
        "s M_1(W) (f(scrub offset / patch radius) - 1), M_1 equation (1), to each tread's friction moment (rig "
        "theory, the drag part without the pressure correction); 0 = free to roll"
    )
    in_default_set = False
    quantities = (
        Quantity("braked_wheels.brake_fraction", "1", 0.0, 1.0, lower_inclusive=True, default=0.0,
                 source="candidate: share of the braked (non-rolling) excess moment, 0 = wheels free to roll as in "
                        "the paper (absent), 1 = wheels locked (brakes held on the front wheels; not a front-drive "
                        "car in gear: an open differential leaves the wheels free to turn in opposite senses, which "
                        "is all the scrub of a steered pair needs)"),
    )
    uses = ("braked_wheels.brake_fraction", *TYRE_FRICTION.uses)
    requires = ("tyre_friction",)

    def scrub_offset_squared(self, model, side):
        """Square of the lateral distance from the axis's ground intercept to the contact centre, zero steer."""
        d = lambda name: model.d(f"{side}.{name}")  # noqa: E731
        foot_y, foot_z = d("foot_y"), d("foot_z")
        axis_y, axis_z = d("axis_frame_12"), d("axis_frame_22")  # the axis direction (third column), body y and z
        centre_y = foot_y + sum(d(f"axis_frame_1{j}") * d(f"centre_in_axis_{c}") for j, c in enumerate("xyz"))
        centre_z = foot_z + sum(d(f"axis_frame_2{j}") * d(f"centre_in_axis_{c}") for j, c in enumerate("xyz"))
        along = (centre_z + model.d("wheel_radius") - foot_z) / axis_z  # down the axis from its foot to the ground
        return (centre_y - foot_y - along * axis_y) ** 2

    def loads(self, model):
        k = model.kinematics
        fraction = model.p("braked_wheels.brake_fraction")
        pressure = model.p("tyre.tyre_pressure")
        p0, n = model.p("tyre.reference_pressure"), model.p("tyre.pressure_index")
        beta = model.p("steering.friction_smoothing")
        grip = model.d("surface_grip")
        out = []
        for side in SIDES:
            load = k.wheel_load[side]
            # the patch radius squared, kept above 1e-12 m^2: a wheel off the ground has no patch (and no moment:
            # moment_limit is 0 there). A Piecewise rather than Max, which re-simplifies its arguments on every
            # substitution (seconds per model in the code generation).
            floor = sp.Float(1e-12)
            patch_radius_squared = sp.Piecewise((load / (sp.pi * pressure), load > floor * sp.pi * pressure),
                                                (floor, True))
            k_squared = self.scrub_offset_squared(model, side) / patch_radius_squared
            # equation (1): equation (2) without its pressure correction (p0/p)^(n - 1/2)
            spin_uniform = TYRE_FRICTION.moment_limit(model, load) / (p0 / pressure) ** (n - sp.Rational(1, 2))
            excess = fraction * spin_uniform * braked_excess_ratio(k_squared)
            ring = k.ring_frame[side]
            yaw_rate = ring.ang_vel_in(model.N).dot(model.N.z)
            out.append(me.Torque(ring, -grip * excess * sp.tanh(beta * yaw_rate) * model.N.z))
        return out


EFFECT = BrakedWheels()
