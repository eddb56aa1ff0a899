"""Tyre-to-ground friction moment on each tread ring, equation (2), smoothed with tanh."""

from __future__ import annotations

import sympy as sp

from ..components import Effect, EffectParameter
from ..system import SIDES


class TyreFriction(Effect):
    name = "tyre_friction"
    description = (
        "Friction moment of the sliding contact patch on each tread ring about the ground normal: "
        "magnitude M(W) of equation (2) at the instantaneous wheel load, times -tanh(beta * ring yaw rate)"
    )
    parameters = (
        EffectParameter("friction_coefficient", "1", 0.0, 3.0, "Appendix B; Section 2: 2438 N / 3660 N",
                        file_key="tyre.friction_coefficient"),
        EffectParameter("tyre_pressure", "Pa", 1.0e4, 1.0e6, "Appendix B, p (car model)", file_key="tyre.tyre_pressure"),
        EffectParameter("reference_pressure", "Pa", 1.0e4, 1.0e6, "Section 4, p0 of equation (2)",
                        file_key="tyre.reference_pressure"),
        EffectParameter("pressure_index", "1", 0.0, 3.0, "Section 4, n of equation (2)", file_key="tyre.pressure_index"),
        EffectParameter("smoothing", "s/rad", 1.0, 1.0e6,
                        "Appendix B beta, used per rad/s of tread yaw rate", file_key="steering.friction_smoothing"),
    )

    def moment_limit(self, model, load_N):
        """Equation (2): M = p0^(n - 1/2) (2 mu / (3 sqrt(pi))) W^1.5 / p^n; zero for a wheel off the ground."""
        mu, p, p0, n = (model.p(self, k) for k in ("friction_coefficient", "tyre_pressure", "reference_pressure",
                                                     "pressure_index"))
        contact = sp.Piecewise((load_N ** sp.Rational(3, 2), load_N > 0), (0, True))
        return p0 ** (n - sp.Rational(1, 2)) * 2 * mu / (3 * sp.sqrt(sp.pi)) * contact / p ** n

    def loads(self, model):
        beta = model.p(self, "smoothing")
        grip = model.d("surface_grip")  # 1 on the ground, 0 on air bearings
        out = []
        for side in SIDES:
            ring = model.ring_frame[side]
            yaw_rate = ring.ang_vel_in(model.N).dot(model.N.z)
            moment = grip * self.moment_limit(model, model.wheel_load[side]) * sp.tanh(beta * yaw_rate)
            out.append((ring, -moment * model.N.z))
        return out


EFFECT = TyreFriction()
