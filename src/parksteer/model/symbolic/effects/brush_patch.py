"""Brush-model contact patch: the patch slides progressively from its rim inwards (a candidate).

The paper's tyre is a lumped law: the carcass spring k (728 N m/rad) winds up until the whole
tread ring slides at the moment M of equation (2), a sharp knee. In a brush model the tread
elements of a uniform-pressure disc of radius R twist with the wheel and each slides when
its shear reaches mu p: the rim slides first, so the moment-twist curve leaves the straight
line at 3/4 of M and rounds off towards M (for pure spin: M f(x), x = k twist / M,
f = x up to 3/4, then 1 - (27/256) / x^3). After a reversal every element sticks again, so
the unloading is at the full stiffness (Masing).

Here the patch is split into concentric annuli, each a spring-slider element between the
wheel and the ground, in parallel (an Iwan model of the brush): the annulus between radii
r_(j-1) and r_j has the stiffness share w_j = (r_j^4 - r_(j-1)^4) / R^4 (bristle stiffness
times r^2 over its area) and the friction share m_j = (r_j^3 - r_(j-1)^3) / R^3 (mu p r over
its area), so it slides at x = m_j / w_j, the rim first. Three annuli split at 0.53 R and
0.78 R (the radii that minimise the largest departure from the continuous law) slide at
x = 0.83, 1.12 and 1.89, and their piecewise-linear curve stays within 0.016 M of the
continuous brush law. The total stiffness (sum of w_j k) and the total sliding moment (sum of
m_j M) are the paper's, so the initial slope and the plateau are unchanged.

The paper's tread ring becomes the rim annulus (this effect takes the share 1 - w_rim of its
carcass spring and damper and 1 - m_rim of its friction off it); the inner annuli are new
coordinates (their yaw about the steer axis, from the body), each with the spring, damper
and friction shares and the yaw inertia share w_j of the tread ring. The strength s blends:
the removed shares and the inner annuli's springs, dampers, frictions and inertias are all
scaled by s (the inertias by s + 0.001, which keeps the mass matrix positive definite at s = 0,
where the annuli are free and carry nothing). Requires carcass_compliance and tyre_friction.

Sidewall and brush: in a tyre the carcass sidewall is a spring in series with the tread bristles
(wheel - sidewall - tread base - bristles - ground). This effect has no separate sidewall: the
paper's whole carcass compliance 1/k is given to the bristles, so s = 1 is the series arrangement's
limit of a rigid sidewall. With a sidewall taking a fraction phi of the compliance (1/k_s = phi/k,
1/k_b = (1 - phi)/k, the same initial slope), the extra twist the rounded knee adds to the lumped law
at any moment below M is (1 - phi) times this effect's, and the sliding moment is the same M: the
rounding modelled here is an upper bound, reached when the bristles carry all the compliance.
"""

from __future__ import annotations

from fractions import Fraction

from ..lazy_sympy import me, sp

from ....names import SIDES
from ....parameters import Quantity
from ..components import Effect
from ..system import torque_between
from .carcass_compliance import EFFECT as CARCASS
from .tyre_friction import EFFECT as TYRE_FRICTION

ANNULUS_RADII = (Fraction(53, 100), Fraction(78, 100))  # inner boundaries, in patch radii
ANNULI = len(ANNULUS_RADII) + 1
INERTIA_FLOOR = Fraction(1, 1000)  # of an annulus's inertia share, so that M stays positive definite at s = 0


def annulus_shares() -> list[tuple[Fraction, Fraction]]:
    """(stiffness share, friction share) of each annulus of the uniform-pressure brush disc, centre to rim."""
    radii = (0, *ANNULUS_RADII, 1)
    return [(radii[j] ** 4 - radii[j - 1] ** 4, radii[j] ** 3 - radii[j - 1] ** 3) for j in range(1, len(radii))]


class BrushPatch(Effect):
    name = "brush_patch"
    description = (
        "Brush-model patch: concentric tread annuli in parallel, each a spring and a slider, so sliding spreads "
        "from the rim inwards and the wind-up knee rounds off below the same plateau; s blends lumped to brush"
    )
    in_default_set = False
    requires = ("carcass_compliance", "tyre_friction")
    quantities = (
        Quantity("brush_patch.brush_fraction", "1", 0.0, 1.0, lower_inclusive=True, default=0.0,
                 source="candidate: blend of the brush law (1) into the paper's lumped spring and Coulomb slider "
                        "(0, absent); the brush shape follows from uniform pressure (the paper's patch) and uniform "
                        "bristle stiffness"),
    )
    uses = ("brush_patch.brush_fraction", "tyre.tread_ring_yaw_inertia", *CARCASS.uses, *TYRE_FRICTION.uses)

    def configure(self, model):
        model.state(self).annulus = {
            side: [model.add_coordinate(f"annulus{j}_{side}", "rad", owner=self.name) for j in range(1, ANNULI)]
            for side in SIDES
        }

    def _frames(self, model, side):
        """The inner annuli's frames: each turned about the steer axis from the body-fixed axis frame."""
        axis_frame = model.kinematics.axis_frame[side]
        frames = []
        for j, (q, u) in enumerate(model.state(self).annulus[side], start=1):
            frame = me.ReferenceFrame(f"annulus{j}_{side}")
            frame.orient_axis(axis_frame, axis_frame.z, q)
            frame.set_ang_vel(axis_frame, u * axis_frame.z)
            frames.append(frame)
        return frames

    def bodies(self, model):
        state = model.state(self)
        strength = model.p("brush_patch.brush_fraction")
        ring_inertia = model.p("tyre.tread_ring_yaw_inertia")
        shares = annulus_shares()
        state.frames = {}
        out = []
        for side in SIDES:
            state.frames[side] = self._frames(model, side)
            centre = model.kinematics.wheel_centre[side]
            for (stiffness_share, _), frame in zip(shares, state.frames[side]):
                inertia = (strength + INERTIA_FLOOR) * stiffness_share * ring_inertia
                out.append(me.RigidBody(frame.name, centre, frame, 0, (inertia * me.outer(frame.z, frame.z), centre)))
        return out

    def _relative(self, model, side, q, u):
        """Angle and rate of an annulus relative to its wheel (both about the steer axis)."""
        wheel = model.kinematics.steer_angle[side]
        return q - wheel, u - sp.diff(wheel, model.rack_q) * model.rack_u

    def loads(self, model):
        k, state = model.kinematics, model.state(self)
        strength = model.p("brush_patch.brush_fraction")
        stiffness, damping = model.p("tyre.carcass_torsional_stiffness"), model.p("tyre.carcass_torsional_damping")
        beta = model.p("steering.friction_smoothing")
        grip = model.d("surface_grip")
        shares = annulus_shares()
        rim_stiffness, rim_friction = shares[-1]
        out = []
        for side in SIDES:
            wheel, ring = k.steer_frame[side], k.ring_frame[side]
            axis = wheel.z
            moment_limit = grip * TYRE_FRICTION.moment_limit(model, k.wheel_load[side])
            # The tread ring becomes the rim annulus: take the other annuli's shares off its spring and slider.
            twist = k.ring_twist[side]
            twist_rate = twist.diff(model.t).xreplace(k.qd_to_u)
            spring_off = strength * (1 - rim_stiffness) * (stiffness * twist + damping * twist_rate)
            out += torque_between(spring_off, axis, ring, wheel)
            ring_yaw = ring.ang_vel_in(model.N).dot(model.N.z)
            friction_off = strength * (1 - rim_friction) * moment_limit * sp.tanh(beta * ring_yaw)
            out.append(me.Torque(ring, friction_off * model.N.z))
            for (stiffness_share, friction_share), frame, (q, u) in zip(shares, state.frames[side],
                                                                        state.annulus[side]):
                angle, rate = self._relative(model, side, q, u)
                spring = strength * stiffness_share * (stiffness * angle + damping * rate)
                out += torque_between(-spring, axis, frame, wheel)
                yaw = frame.ang_vel_in(model.N).dot(model.N.z)
                friction = strength * friction_share * moment_limit * sp.tanh(beta * yaw)
                out.append(me.Torque(frame, -friction * model.N.z))
        return out

    def potential_energy(self, model):
        k, state = model.kinematics, model.state(self)
        strength = model.p("brush_patch.brush_fraction")
        stiffness = model.p("tyre.carcass_torsional_stiffness")
        shares = annulus_shares()
        energy = 0
        for side in SIDES:
            energy -= strength * (1 - shares[-1][0]) * stiffness * k.ring_twist[side] ** 2 / 2
            for (stiffness_share, _), (q, u) in zip(shares, state.annulus[side]):
                angle, _ = self._relative(model, side, q, u)
                energy += strength * stiffness_share * stiffness * angle**2 / 2
        return energy


EFFECT = BrushPatch()
