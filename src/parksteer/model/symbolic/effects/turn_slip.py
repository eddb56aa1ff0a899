"""Parking while the car creeps: the tyre's moment about the steer axis falls as the wheel rolls while it steers.

The vehicle speed V is the run's (``run.vehicle_speed``, :data:`parksteer.parameters.VEHICLE_SPEED`: a constant of
the run, ``parksteer simulate --speed-kmh``), the one quantity the electric assist's speed-dependent boost curve
reads too. The coefficients are MF 6.1's published defaults (MFeval's default tyre property file): they
stand for a typical passenger-car tyre until a fitted .tir file is at hand.

It adds (1 - f) M(W) tanh(beta psi') (N m) against the tyre_friction moment, with f = 1 exactly at V = 0 (m/s).
Requires tyre_friction. The derivation, its reasoning and its sources: docs/assist.md, "Turn slip while the car
creeps (`turn_slip`)".
"""

from __future__ import annotations

from ..lazy_sympy import me, sp

from ....names import SIDES
from ....parameters import VEHICLE_SPEED, Quantity
from ..components import Effect

MF_SOURCE = ("MF 6.1 default tyre property file (MFeval readTIR defaults; Pacejka, Tire and Vehicle Dynamics, 3rd ed., "
             "2012, sec. 4.3.3)")


class TurnSlip(Effect):
    name = "turn_slip"
    description = (
        "The tyre moment of a rolling wheel: equation (2) times 1/sqrt(1 + y^2), y proportional to the distance "
        "rolled per steer angle (MF 6.x turn slip); exactly today's moment at zero vehicle speed"
    )
    in_default_set = False
    diagnosis_candidate = False
    requires = ("tyre_friction",)
    quantities = (
        Quantity("turn_slip.spin_slope_coefficient", "1", 0.0, 1.0, default=0.05,
                 description="q_Dz8: the spin moment's initial slope K = F_z R0 q_Dz8 per unit R0 phi",
                 source=f"|QDZ8| = 0.05, {MF_SOURCE}"),
        Quantity("turn_slip.camber_reduction", "1", 0.0, 1.0, lower_inclusive=True, upper_inclusive=False,
                 default=0.5, description="eps_gamma = PECP1: the share of camber in turn slip",
                 source=f"PECP1 = 0.5, {MF_SOURCE}"),
        Quantity("turn_slip.yaw_rate_smoothing", "rad/s", 0.0, 1.0, default=1.0e-3,
                 description="|psi'| is smoothed as sqrt(psi'^2 + w^2)",
                 source="numerical: a thousandth of the cycle's steer rates"),
    )
    uses = (VEHICLE_SPEED.key, *(q.key for q in quantities), "tyre.friction_coefficient", "tyre.tyre_pressure",
            "tyre.reference_pressure", "tyre.pressure_index", "steering.friction_smoothing")

    def rolling_factor(self, model, load_N, yaw_rate):
        """f = 1 / sqrt(1 + y^2) (docs/assist.md); 1 exactly at zero speed."""
        mu, p, p0, n = (model.p(f"tyre.{k}") for k in ("friction_coefficient", "tyre_pressure", "reference_pressure",
                                                        "pressure_index"))
        per_sqrt_load = p0 ** (n - sp.Rational(1, 2)) * 2 * mu / (3 * sp.sqrt(sp.pi)) / p ** n  # M(W) / W^1.5
        root_load = sp.Piecewise((sp.sqrt(load_N), load_N > 0), (0, True))
        radius = model.d("wheel_radius")
        rate = sp.sqrt(yaw_rate**2 + model.p("turn_slip.yaw_rate_smoothing") ** 2)
        y = (model.p(VEHICLE_SPEED.key) * (1 - model.p("turn_slip.camber_reduction")) * per_sqrt_load
             * root_load / (model.p("turn_slip.spin_slope_coefficient") * radius**2 * rate))
        return 1 / sp.sqrt(1 + y**2)

    def loads(self, model):
        from .tyre_friction import EFFECT as tyre

        k = model.kinematics
        beta = model.p("steering.friction_smoothing")
        grip = model.d("surface_grip")
        out = []
        for side in SIDES:
            ring = k.ring_frame[side]
            yaw_rate = ring.ang_vel_in(model.N).dot(model.N.z)
            load = k.wheel_load[side]
            standstill = grip * tyre.moment_limit(model, load) * sp.tanh(beta * yaw_rate)
            # the share the rolling wheel no longer carries, against the tyre_friction moment
            out.append(me.Torque(ring, (1 - self.rolling_factor(model, load, yaw_rate)) * standstill * model.N.z))
        return out


EFFECT = TurnSlip()
