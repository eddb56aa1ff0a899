"""Parking while the car creeps: the tyre's moment about the steer axis falls as the wheel rolls while it steers.

Source: the turn-slip extension of the Magic Formula (MF 6.1/6.2; Pacejka, Tire and Vehicle Dynamics, 3rd ed.,
2012, section 4.3.3 and Appendix 3; the MF-Tyre 6.2 equations as coded in MFeval, M. Furlan). The spin moment of
a tyre turning at the yaw rate psi' while it rolls at speed V has the turn slip (path curvature)
phi = psi' / V, and with C_Dr_phi = QDRP1 = 1 (the published default) its magnitude is

    D_r(phi) = M_phi_inf sin(atan(B R0 phi)) = M_phi_inf x / sqrt(1 + x^2),   x = B R0 phi,
    B = K_zgr0 / (M_phi_inf (1 - eps_g)),   K_zgr0 = F_z R0 q_Dz8,   eps_g = PECP1,

with M_phi_inf the moment at infinite turn slip (at standstill, phi -> infinity) and K_zgr0 its initial slope.
Here M_phi_inf is the paper's equation (2), M(W) (the tyre_friction effect), in place of MF's
QCRP1 mu_y R0 F_z sqrt(F_z / F_z0); both grow as F_z^1.5. Writing 1/x = V (1 - eps_g) M(W) / (q_Dz8 R0^2 W |psi'|),
the tyre moment is

    M = M(W) tanh(beta psi') f,   f = 1 / sqrt(1 + y^2),   y = V (1 - eps_g) c(p) sqrt(W) / (q_Dz8 R0^2 |psi'|),

c(p) sqrt(W) = M(W) / W from equation (2), |psi'| smoothed as sqrt(psi'^2 + w^2). This effect adds the
difference, (1 - f) M(W) tanh(beta psi'), against the tyre_friction moment, so the sum is f times today's. At
V = 0, y = 0 and f = 1 exactly: the standstill torque is today's, bit for bit. f falls monotonically as y, the
distance rolled per radian of steer (V / |psi'|) measured in units of q_Dz8 R0^2 / ((1 - eps_g) c sqrt(W)),
grows: at 1 km/h and 0.3 rad/s of steer rate the wheel rolls 0.9 m per radian of steer, several contact
lengths, and the moment is a fraction of the standstill's.

The vehicle speed V is the run's (``run.vehicle_speed``, :data:`parksteer.parameters.VEHICLE_SPEED`: a constant of
the run, ``parksteer simulate --speed-kmh``), the one quantity the electric assist's speed-dependent boost curve
reads too. The coefficients are MF 6.1's published defaults (MFeval's default tyre property file): they
stand for a typical passenger-car tyre until a fitted .tir file is at hand.
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
        """f = 1 / sqrt(1 + y^2) (module docstring); 1 exactly at zero speed."""
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
