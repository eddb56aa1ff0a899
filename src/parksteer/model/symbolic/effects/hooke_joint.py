"""Hooke (Cardan) joint between the steering column and the pinion, at a fixed joint angle."""

from __future__ import annotations

from ..lazy_sympy import sp

from ..components import Effect


class HookeJoint(Effect):
    name = "hooke_joint"
    description = (
        "Non-constant-velocity joint from column to pinion: tan(theta_p - phase) = tan(theta_c - phase) / cos(alpha), "
        "so the torque ripples twice per column revolution"
    )
    uses = ("steering.hooke_joint_angle", "steering.hooke_joint_phase")
    replaces = "column_map"

    def column_angle(self, model, pinion_angle):
        """theta_c from theta_p, continuous across branches.

        With psi = theta_p - phase, tan(theta_c - phase) = cos(alpha) tan(psi), and
        theta_c - theta_p = atan((cos a - 1) sin psi cos psi / (cos^2 psi + cos a sin^2 psi)),
        whose denominator is at least cos(alpha) > 0, so no branch is ever crossed.
        """
        cos_a = sp.cos(model.p("steering.hooke_joint_angle"))
        psi = pinion_angle - model.p("steering.hooke_joint_phase")
        s, c = sp.sin(psi), sp.cos(psi)
        return pinion_angle + sp.atan((cos_a - 1) * s * c / (c**2 + cos_a * s**2))


EFFECT = HookeJoint()
