"""Electric power assistance (EPS), acting at the column (EPS-C); the pinion and rack variants use the same class.

Outputs: torsion_bar_torque_Nm (T_s), assist_torque_Nm or assist_force_N (e N T_m at x), motor_torque_Nm,
motor_current_A; the simulation adds rack_force_N (the force the pinion and the assist together put on the
rack). The model has no tie rods (a linear linkage), so no tie-rod force.

Values: every default is assumed, a typical value of current production gears with its range and source in
the quantity; a vehicle file's ``[assist]`` gives the car's own.

The point of action is the effect's option: ``electric_assist_column`` (this module), ``electric_assist_pinion``,
``electric_assist_rack``. Its torsion bar fills the column_deflection slot (:mod:`.assist_common`), so a second
assist, or the rack lash, in the same set is refused in one line. The derivation, its reasoning and its sources:
docs/assist.md, "The electric assist (`electric_assist`)".
"""

from __future__ import annotations


from ..lazy_sympy import me, sp

from .... import portable as pm
from ....parameters import VEHICLE_SPEED, Quantity
from ....reduction_efficiency import (PI, back_efficiency, ball_nut_lead_angle, friction_angle_for_forward,
                                      lead_angle_for_forward)
from ..components import Effect
from ..system import torque_between
from .assist_common import (LOCATIONS, clamp, deadband, directional_efficiency, point_of_action,
                            series_deflection, speed_gain, table_law_node, table_quantities, torsion_bar_torque)

# The reduction's efficiencies from its geometry and friction (parksteer.reduction_efficiency: a thread of lead
# angle lambda and friction angle rho, eta_f = tan(lambda) / tan(lambda + rho),
# eta_b = tan(lambda - rho) / tan(lambda)).
# The forward efficiency is the assumption (what a gear's maker states); the friction angle of the worm's sliding
# flank, or the ball nut's lead and ball circle, is the second; the lead angle (worm) or the effective friction
# (ball nut, its belt lumped in) follows from the two, and eta_b from the formula.
WORM_FORWARD_EFFICIENCY = 0.85
WORM_FRICTION_ANGLE_RAD = 3.0 * PI / 180.0
BALL_NUT_FORWARD_EFFICIENCY = 0.90
BALL_NUT_LEAD_M = 0.007
BALL_NUT_BALL_CIRCLE_M = 0.028
_WORM_LEAD_ANGLE_RAD = lead_angle_for_forward(WORM_FORWARD_EFFICIENCY, WORM_FRICTION_ANGLE_RAD)
_NUT_LEAD_ANGLE_RAD = ball_nut_lead_angle(BALL_NUT_LEAD_M, BALL_NUT_BALL_CIRCLE_M)
_NUT_FRICTION_ANGLE_RAD = friction_angle_for_forward(BALL_NUT_FORWARD_EFFICIENCY, _NUT_LEAD_ANGLE_RAD)
WORM_BACK_EFFICIENCY = back_efficiency(_WORM_LEAD_ANGLE_RAD, WORM_FRICTION_ANGLE_RAD)
BALL_NUT_BACK_EFFICIENCY = back_efficiency(_NUT_LEAD_ANGLE_RAD, _NUT_FRICTION_ANGLE_RAD)
_WORM_SOURCE = (
    f"assumed: worm gear eta_f {WORM_FORWARD_EFFICIENCY:g} with a sliding flank of friction angle "
    f"{WORM_FRICTION_ANGLE_RAD * 180.0 / PI:g} deg (mu {pm.tan(WORM_FRICTION_ANGLE_RAD):.3f}); the lead angle at which "
    f"eta_f = tan(lambda) / tan(lambda + rho) is {WORM_FORWARD_EFFICIENCY:g}, "
    f"{_WORM_LEAD_ANGLE_RAD * 180.0 / PI:.1f} deg, "
    "gives eta_b = tan(lambda - rho) / tan(lambda)")
_BALL_NUT_SOURCE = (
    f"assumed: ball nut and belt eta_f {BALL_NUT_FORWARD_EFFICIENCY:g}, a {BALL_NUT_LEAD_M * 1e3:g} mm lead on a "
    f"{BALL_NUT_BALL_CIRCLE_M * 1e3:g} mm ball circle (lead angle {_NUT_LEAD_ANGLE_RAD * 180.0 / PI:.2f} deg); the "
    f"friction angle at which eta_f = {BALL_NUT_FORWARD_EFFICIENCY:g} there, "
    f"{_NUT_FRICTION_ANGLE_RAD * 180.0 / PI:.2f} "
    f"deg (mu {pm.tan(_NUT_FRICTION_ANGLE_RAD):.4f}, the belt's loss lumped into the nut's), gives "
    "eta_b = tan(lambda - rho) / tan(lambda)")

# Typical values by point of action: (reduction N, its unit, bounds, efficiency, motor torque limit N m,
# motor inertia kg m^2, source of the reduction). Column and pinion: a worm gear; rack: a ball nut driven through
# a belt (N = 2 pi / lead x belt ratio).
_GEARS = {
    "column": (18.0, "1", (1.0, 100.0), WORM_FORWARD_EFFICIENCY, 4.0, 2.0e-4,
               "assumed: worm gear of column EPS, 15-22:1 (Harrer & Pfeffer, Steering Handbook, Springer 2017, "
               "ch. 8.3; Kim, Mech. Sci. 9, 201, 2018)"),
    "pinion": (20.0, "1", (1.0, 100.0), WORM_FORWARD_EFFICIENCY, 4.5, 2.0e-4,
               "assumed: worm gear of pinion and dual-pinion EPS, 15-25:1 (Harrer & Pfeffer, Steering Handbook, "
               "ch. 8.3)"),
    "rack": (2400.0, "rad/m", (100.0, 20000.0), BALL_NUT_FORWARD_EFFICIENCY, 5.0, 3.0e-4,
             "assumed: ball nut of 7 mm lead through a 2.7:1 belt, 2 pi / 0.007 x 2.7 = 2420 rad/m; rack EPS "
             "1500-3500 rad/m (Harrer & Pfeffer, Steering Handbook, ch. 8.4)"),
}

# How sharply the motor's friction and the gear's direction of power flow change over at a reversal: the rotor speed
# w of tanh(omega / w) (the assist's own, not the car-wide friction smoothing of the rack's sliding contacts).
FRICTION_SPEED = 0.5
FRICTION_SPEED_SOURCE = (
    "assumed: narrower than a 100 Hz bus resolves at a parking reversal, 0.1-2.25 rad/s: a column worm's rotor "
    "(N = 18, G_hr = 125 rad/m: 2250 rad/s of rotor per m/s of rack) crosses +-0.5 rad/s within one 10 ms sample "
    "wherever the rack reverses at more than 0.045 m/s^2, so a narrower band reads the same; the car-wide friction "
    "smoothing's width, 1 mm/s of the rack, is 2.25 rad/s of this rotor; no data sheet gives it, and a diagnosis "
    "replays its band's ends (stage assumed)")

_BACK_EFFICIENCY = {
    "column": (WORM_BACK_EFFICIENCY, f"assumed: the thread formula's {WORM_BACK_EFFICIENCY:.3f} for the "
                                     f"{_WORM_SOURCE.removeprefix('assumed: ')} (the worm-gear efficiencies in the "
                                     "lead angle: novasolver.jp worm gear calculator; parksteer.reduction_efficiency); "
                                     "an EPS worm is back-drivable (lambda > rho)"),
    "pinion": (WORM_BACK_EFFICIENCY, f"assumed: the thread formula's {WORM_BACK_EFFICIENCY:.3f}, as at the column, for "
                                     f"the {_WORM_SOURCE.removeprefix('assumed: ')}"),
    "rack": (BALL_NUT_BACK_EFFICIENCY, f"assumed: the thread formula's {BALL_NUT_BACK_EFFICIENCY:.3f} for the "
                                       f"{_BALL_NUT_SOURCE.removeprefix('assumed: ')} (the ball-screw catalogue form "
                                       "(1 - mu / tan(lambda)) / (1 + mu tan(lambda)), the same expression; "
                                       "parksteer.reduction_efficiency)"),
}
_FORWARD_SOURCE = {
    "column": f"{_WORM_SOURCE}; range 0.75-0.9",
    "pinion": f"{_WORM_SOURCE}; range 0.75-0.9",
    "rack": f"{_BALL_NUT_SOURCE}; range 0.85-0.95",
}


def assist_quantities(name: str, location: str) -> tuple[Quantity, ...]:
    ratio, ratio_unit, (lo, hi), efficiency, limit, inertia, ratio_source = _GEARS[location]
    back, back_source = _BACK_EFFICIENCY[location]
    return (
        Quantity(f"{name}.gain", "1", 0.0, 50.0, lower_inclusive=True, default=6.0,
                 description="boost curve: assist per driver torque beyond the dead band",
                 source="assumed: the parking gain of EPS boost curves, 4-10 (assist 80-90 % of the load at "
                        "standstill; Harrer & Pfeffer, Steering Handbook, ch. 8.2); 0 = a motor that never "
                        "pushes"),
        Quantity(f"{name}.dead_band", "N m", 0.0, 10.0, lower_inclusive=True, default=0.5,
                 description="boost curve: torsion-bar torque below which the motor does not assist",
                 source="assumed: 0.3-1.5 N m on published EPS boost curves (Harrer & Pfeffer, ch. 8.2)"),
        Quantity(f"{name}.dead_band_smoothing", "N m", 0.0, 1.0, default=0.05,
                 description="width over which the dead band's corners are rounded",
                 source="numerical: a fraction of the dead band, keeps the Jacobian continuous"),
        Quantity(f"{name}.torsion_bar_stiffness", "N m/rad", 10.0, 10000.0, default=115.0,
                 description="torsion bar of the torque sensor, in series with the column",
                 source="assumed: 2 N m/deg; EPS torsion bars 1.5-3 N m/deg, 85-170 N m/rad (Harrer & Pfeffer, "
                        "ch. 8.5)"),
        Quantity(f"{name}.reduction_ratio", ratio_unit, lo, hi, default=ratio,
                 description="motor angle per unit of the point of action's travel", source=ratio_source),
        Quantity(f"{name}.efficiency", "1", 0.0, 1.0, default=efficiency,
                 description="forward efficiency of the reduction (worm gear or ball nut)",
                 source=_FORWARD_SOURCE[location]),
        Quantity(f"{name}.back_efficiency", "1", 0.0, 1.0, default=back,
                 description="efficiency of the reduction back-driven (power from the point of action into the "
                             "motor): the motor feels eta_b of the power the rack puts in",
                 source=back_source),
        Quantity(f"{name}.motor_torque_limit", "N m", 0.0, 30.0, default=limit,
                 description="peak torque of the motor (the boost curve's saturation)",
                 source="assumed: EPS motors 3-6 N m peak at 60-100 A on 12 V (Harrer & Pfeffer, ch. 8.6)"),
        Quantity(f"{name}.limit_smoothing", "N m", 0.0, 1.0, default=0.05,
                 description="width over which the motor limit's corners are rounded (motor torque)",
                 source="numerical: about 1 % of the limit"),
        Quantity(f"{name}.torque_constant", "N m/A", 0.0, 1.0, default=0.05,
                 description="motor torque per ampere of current",
                 source="assumed: 12 V EPS motors 0.03-0.07 N m/A (4 N m at 80 A; Harrer & Pfeffer, ch. 8.6)"),
        Quantity(f"{name}.motor_inertia", "kg m^2", 0.0, 0.01, lower_inclusive=True, default=inertia,
                 description="rotor inertia about its axis",
                 source="assumed: brushless EPS rotors 1-5e-4 kg m^2 (Harrer & Pfeffer, ch. 8.6)"),
        Quantity(f"{name}.motor_friction_torque", "N m", 0.0, 1.0, lower_inclusive=True, default=0.02,
                 description="Coulomb friction of the rotor's bearings and seals, at the motor",
                 source="assumed: 0.01-0.05 N m for EPS motors (Harrer & Pfeffer, ch. 8.6)"),
        Quantity(f"{name}.friction_speed", "rad/s", 0.0, 100.0, default=FRICTION_SPEED,
                 description="rotor speed over which the motor's Coulomb friction and the gear's direction of power "
                             "flow change over at a reversal: the width w of tanh(rotor speed / w)",
                 source=FRICTION_SPEED_SOURCE),
        Quantity(f"{name}.speed_dependence", "1", 0.0, 1.0, lower_inclusive=True, default=0.0,
                 description="1: the gain falls with the vehicle speed as G / (1 + (v / v_half)^2); 0: a "
                             "speed-independent boost curve (between: the same fall with v_half / sqrt(s))",
                 source="off by default: a speed-independent boost curve, as for the paper's standstill test; "
                        "current EPS control units scale the assist by vehicle speed (Servotronic: BMW and MINI "
                        "EPS functional descriptions)"),
        Quantity(f"{name}.gain_half_speed", "m/s", 0.0, 100.0, default=13.9,
                 description="v_half: the vehicle speed at which the speed-dependent gain is half the parking gain",
                 source="assumed: 50 km/h, range 40-80 km/h: a speed-proportional gear gives the least effort (full "
                        "assist) from 0 to about 32 km/h and the most (the least assist) from about 100 km/h "
                        "(Chrysler 1999 Concorde service manual, speed proportional steering gear); with v_half "
                        "40-80 km/h, G / (1 + (v / v_half)^2) keeps 61-86 % of the parking gain at 32 km/h and "
                        "14-39 % at 100 km/h"),
        *(table_quantities(name, "N", "N/(N m)", "at the rack") if location == "rack"
          else table_quantities(name, "N m", "1", f"at the {location}")),
    )


class ElectricAssist(Effect):
    """An electric assist; its point of action (``column``, ``pinion``, ``rack``) is chosen by :meth:`at`, which
    gives the effect class of that point (its name, quantities and description are class attributes, so that an
    instance keeps no state; docs/assist.md)."""

    in_default_set = False
    diagnosis_candidate = False
    power_assist = "electric"  # the simulation's rack force leaves its contribution out (the gear's own push)
    replaces = "column_deflection"

    @classmethod
    def at(cls, location: str) -> type[ElectricAssist]:
        """The electric assist acting at `location`, one of :data:`LOCATIONS`."""
        if location not in LOCATIONS:
            raise ValueError(f"electric assist at {location!r}: the point of action is one of {', '.join(LOCATIONS)}")
        name = f"electric_assist_{location}"
        quantities = assist_quantities(name, location)
        return type(f"ElectricAssist{location.title()}", (cls,), {
            "location": location,
            "name": name,
            "description": (
                f"Electric power assistance at the {location}: torsion bar in series with the column, boost curve "
                "(gain beyond a dead band, motor torque limit) through a reduction with its efficiency, rotor "
                "inertia and friction; off by default"),
            "quantities": quantities,
            "uses": (*(q.key for q in quantities), VEHICLE_SPEED.key, "steering.column_torsional_stiffness",
                     "steering.handwheel_to_rack_ratio"),
            "__module__": cls.__module__,
        })

    def q(self, model, name: str):
        return model.p(f"{self.name}.{name}")

    def deflection(self, model, twist):
        return series_deflection(model, twist, f"{self.name}.torsion_bar_stiffness")

    def configure(self, model):
        model.state(self).frame = None

    def _motor_frame(self, model):
        state = model.state(self)
        if state.frame is None:
            k = model.kinematics
            x, rate = point_of_action(model, self.location)
            frame = me.ReferenceFrame(f"motor_{self.name}")
            frame.orient_axis(k.B, k.B.y, self.q(model, "reduction_ratio") * x)
            frame.set_ang_vel(k.B, self.q(model, "reduction_ratio") * rate * k.B.y)
            state.frame = frame
        return state.frame

    def sensor_torque(self, model):
        return torsion_bar_torque(model, self.location)

    def gain(self, model):
        """G(v) = G / (1 + s (v / v_half)^2): exactly G at v = 0 or s = 0 (docs/assist.md)."""
        return speed_gain(self.q(model, "gain"), self.q(model, "speed_dependence"), model.p(VEHICLE_SPEED.key),
                          self.q(model, "gain_half_speed"))

    def motor_torque(self, model):
        scale = model.p("steering.handwheel_to_rack_ratio") if self.location == "rack" else 1
        sensor = self.sensor_torque(model)
        demand = self.gain(model) * deadband(sensor, self.q(model, "dead_band"),
                                             self.q(model, "dead_band_smoothing")) * scale
        demand = demand + table_law_node(sensor, lambda key: self.q(model, key), model.p(VEHICLE_SPEED.key))
        at_motor = demand / (self.q(model, "efficiency") * self.q(model, "reduction_ratio"))
        return clamp(at_motor, self.q(model, "motor_torque_limit"), self.q(model, "limit_smoothing"))

    def rotor_speed(self, model):
        """The rotor's speed, N times the point of action's rate (rad/s)."""
        _, rate = point_of_action(model, self.location)
        return self.q(model, "reduction_ratio") * rate

    def friction_sign(self, model):
        """The smooth sign of the rotor's speed, tanh(omega / w), w the assist's ``friction_speed``: how the motor's
        friction and the gear's direction of power flow change over at a reversal."""
        return sp.tanh(self.rotor_speed(model) / self.q(model, "friction_speed"))

    def delivered_factor(self, model, motor):
        """The gear's efficiency in the direction the power flows (eta_f driving, 1 / eta_b back-driven), smooth
        through the power's sign (docs/assist.md)."""
        return directional_efficiency(motor, self.rotor_speed(model), self.q(model, "efficiency"),
                                      self.q(model, "back_efficiency"), self.q(model, "limit_smoothing"),
                                      1 / self.q(model, "friction_speed"))

    def bodies(self, model):
        k = model.kinematics
        rotor = me.RigidBody(f"rotor_{self.name}", k.rack_housing_point, self._motor_frame(model), sp.S.Zero,
                             (self.q(model, "motor_inertia") * me.outer(k.B.y, k.B.y), k.rack_housing_point))
        return [rotor]

    def loads(self, model):
        k = model.kinematics
        frame = self._motor_frame(model)
        friction = self.q(model, "motor_friction_torque") * self.friction_sign(model)
        motor = self.motor_torque(model)
        delivered = self.delivered_factor(model, motor) * motor
        # Motor torque (less the gear's loss) and bearing friction on the rotor, reacted on the body.
        return torque_between(delivered - friction, k.B.y, frame, k.B)

    def outputs(self, model):
        motor = self.motor_torque(model)
        at_x = self.delivered_factor(model, motor) * self.q(model, "reduction_ratio") * motor
        return [
            ("torsion_bar_torque_Nm", self.sensor_torque(model)),
            ("assist_force_N" if self.location == "rack" else "assist_torque_Nm", at_x),
            ("motor_torque_Nm", motor),
            ("motor_current_A", motor / self.q(model, "torque_constant")),
        ]


EFFECT = ElectricAssist.at("column")()
