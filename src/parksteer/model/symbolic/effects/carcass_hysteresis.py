"""Visco-elastic hysteresis of the tyre carcass: a Maxwell branch beside the carcass spring (a rival).

Strength s: the branch's stiffness as a fraction of the carcass's (0 = absent), with its relaxation time tau (s);
one new coordinate per side, the branch node's angle about the steer axis (rad). Requires carcass_compliance. The
derivation, its reasoning and its sources: docs/model.md, "Carcass hysteresis (`carcass_hysteresis`)".
"""

from __future__ import annotations

from fractions import Fraction

from ..lazy_sympy import me

from ....names import SIDES
from ....parameters import Quantity
from ..components import Effect, Rival
from ..system import torque_between
from .carcass_compliance import EFFECT as CARCASS

NODE_INERTIA_SHARE = Fraction(1, 100)  # of the tread ring's yaw inertia: the branch's node is nearly massless
INERTIA_FLOOR = Fraction(1, 1000)  # of the node's inertia share, so that M stays positive definite at s = 0


class CarcassHysteresis(Effect):
    name = "carcass_hysteresis"
    description = (
        "Maxwell branch (spring s k in series with a damper of relaxation time tau) beside each carcass spring; "
        "one node coordinate per side; 0 = the paper's Kelvin-Voigt carcass (absent)"
    )
    in_default_set = False
    rival = Rival(closest="brush_patch", related=("rack_damping",),
                  why="both change the tyre's wind-up at the start and each reversal and keep the sliding plateau; "
                      "its damper makes it rate dependent, as rack_damping is",
                  probe_strength=0.3)
    requires = ("carcass_compliance",)
    quantities = (
        Quantity("carcass_hysteresis.stiffness_fraction", "1", 0.0, 5.0, lower_inclusive=True, default=0.0,
                 source="candidate: stiffness of the carcass's Maxwell branch (spring in series with a damper) as a "
                        "fraction of the carcass torsional stiffness; rubber's dynamic to static stiffness ratio is "
                        "about 1.2-2, so 0.2-1; 0 = the paper's Kelvin-Voigt carcass (absent)"),
        Quantity("carcass_hysteresis.relaxation_time", "s", 0.001, 10.0, lower_inclusive=True, default=0.2,
                 source="candidate: relaxation time c_m / k_m of the Maxwell branch; tyre relaxation times of "
                        "0.05-0.5 s at parking speed; 0.2 s, a fraction of the carcass wind-up in the cycle (about "
                        "1.4 s: M cos / k at the steer rate of 0.12 rad/s), so the branch shows in the wind-up and "
                        "relaxes in steady sliding"),
    )
    uses = ("carcass_hysteresis.stiffness_fraction", "carcass_hysteresis.relaxation_time",
            "tyre.tread_ring_yaw_inertia", *CARCASS.uses)

    def configure(self, model):
        model.state(self).node = {
            side: model.add_coordinate(f"maxwell_{side}", "rad", owner=self.name) for side in SIDES
        }

    def bodies(self, model):
        state = model.state(self)
        strength = model.p("carcass_hysteresis.stiffness_fraction")
        inertia = (strength + INERTIA_FLOOR) * NODE_INERTIA_SHARE * model.p("tyre.tread_ring_yaw_inertia")
        state.frames = {}
        out = []
        for side in SIDES:
            axis_frame = model.kinematics.axis_frame[side]
            q, u = state.node[side]
            frame = me.ReferenceFrame(f"maxwell_{side}")
            frame.orient_axis(axis_frame, axis_frame.z, q)
            frame.set_ang_vel(axis_frame, u * axis_frame.z)
            state.frames[side] = frame
            centre = model.kinematics.wheel_centre[side]
            out.append(me.RigidBody(frame.name, centre, frame, 0, (inertia * me.outer(frame.z, frame.z), centre)))
        return out

    def _stiffness(self, model):
        return model.p("carcass_hysteresis.stiffness_fraction") * model.p("tyre.carcass_torsional_stiffness")

    def _spring_deflection(self, model, side):
        q, _ = model.state(self).node[side]
        return q - model.kinematics.steer_angle[side]

    def loads(self, model):
        k, state = model.kinematics, model.state(self)
        stiffness = self._stiffness(model)
        damping = stiffness * model.p("carcass_hysteresis.relaxation_time")
        out = []
        for side in SIDES:
            wheel, ring, node = k.steer_frame[side], k.ring_frame[side], state.frames[side]
            axis = k.axis_frame[side].z
            _, u = state.node[side]
            ring_rate = ring.ang_vel_in(k.axis_frame[side]).dot(axis)
            spring = stiffness * self._spring_deflection(model, side)
            out += torque_between(-spring, axis, node, wheel)
            out += torque_between(-damping * (u - ring_rate), axis, node, ring)
        return out

    def potential_energy(self, model):
        return sum(self._stiffness(model) * self._spring_deflection(model, side) ** 2 / 2 for side in SIDES)


EFFECT = CarcassHysteresis()
