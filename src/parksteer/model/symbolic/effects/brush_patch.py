"""Brush-model contact patch: the patch slides progressively from its rim inwards (a candidate).

Strength s (0 = the paper's lumped tread ring, 1 = the brush of three annuli); the inner annuli's yaw about the
steer axis (rad) are new coordinates. Requires carcass_compliance and tyre_friction. The derivation, its reasoning
and its sources: docs/model.md, "The brush patch (`brush_patch`)".
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
