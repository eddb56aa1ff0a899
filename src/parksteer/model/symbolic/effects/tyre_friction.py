"""Tyre-to-ground friction moment on each tread ring, equation (2), smoothed with tanh."""

from __future__ import annotations

from ..lazy_sympy import me, sp

from ....names import SIDES
from ..components import Effect


class TyreFriction(Effect):
    name = "tyre_friction"
    description = (
        "Friction moment of the sliding contact patch on each tread ring about the ground normal: "
        "magnitude M(W) of equation (2) at the instantaneous wheel load, times -tanh(beta * ring yaw rate)"
    )
    uses = ("tyre.friction_coefficient", "tyre.tyre_pressure", "tyre.reference_pressure", "tyre.pressure_index",
            "steering.friction_smoothing")

    def moment_limit(self, model, load_N):
        """Equation (2): M = p0^(n - 1/2) (2 mu / (3 sqrt(pi))) W^1.5 / p^n; zero for a wheel off the ground."""
        mu, p, p0, n = (model.p(f"tyre.{k}") for k in ("friction_coefficient", "tyre_pressure", "reference_pressure",
                                                        "pressure_index"))
        contact = sp.Piecewise((load_N ** sp.Rational(3, 2), load_N > 0), (0, True))
        return p0 ** (n - sp.Rational(1, 2)) * 2 * mu / (3 * sp.sqrt(sp.pi)) * contact / p ** n

    def loads(self, model):
        k = model.kinematics
        beta = model.p("steering.friction_smoothing")  # per rad/s of tread yaw rate
        grip = model.d("surface_grip")  # 1 on the ground, 0 on air bearings
        out = []
        for side in SIDES:
            ring = k.ring_frame[side]
            yaw_rate = ring.ang_vel_in(model.N).dot(model.N.z)
            moment = grip * self.moment_limit(model, k.wheel_load[side]) * sp.tanh(beta * yaw_rate)
            out.append(me.Torque(ring, -moment * model.N.z))
        return out


EFFECT = TyreFriction()
