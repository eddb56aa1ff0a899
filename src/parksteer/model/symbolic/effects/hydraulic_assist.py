"""Hydraulic power assistance: a rotary valve on the pinion and a double-acting piston on the rack.

Outputs: torsion_bar_torque_Nm, assist_force_N (A dp), pressure_Pa (dp); the simulation adds rack_force_N.
Values: assumed, typical of hydraulic gears of small and medium cars, with range and source in each quantity.

Its torsion bar fills the column_deflection slot, as the electric assist's does: the two are refused together. The
derivation, its reasoning and its sources: docs/assist.md, "The hydraulic assist (`hydraulic_assist`)".
"""

from __future__ import annotations

from ..lazy_sympy import sp

from ....parameters import VEHICLE_SPEED, Quantity
from ..components import Effect
from ..system import action_reaction
from .assist_common import clamp, deadband, series_deflection, table_law_node, table_quantities, torsion_bar_torque

NAME = "hydraulic_assist"
HANDBOOK = "Harrer & Pfeffer, Steering Handbook, Springer 2017, ch. 7"


class HydraulicAssist(Effect):
    name = NAME
    description = (
        "Hydraulic power assistance: valve torsion bar in series with the column, valve pressure against "
        "torsion-bar torque (dead band and slope, or a progressive table; relief pressure), piston on the rack with "
        "seal friction; off by default"
    )
    in_default_set = False
    diagnosis_candidate = False
    power_assist = "hydraulic"  # the simulation's rack force leaves its contribution out (the gear's own push)
    location = "rack"  # the piston pushes the rack; the valve and its torsion bar sit on the pinion
    replaces = "column_deflection"
    quantities = (
        Quantity(f"{NAME}.valve_slope", "Pa/(N m)", 0.0, 1.0e8, lower_inclusive=True, default=1.5e6,
                 description="valve characteristic: pressure per torsion-bar torque beyond the dead band",
                 source=f"assumed: rotary valves reach 5-8 MPa at 3-5 N m of torsion-bar torque ({HANDBOOK}.3); "
                        "0 = a valve that never opens"),
        Quantity(f"{NAME}.dead_band", "N m", 0.0, 10.0, lower_inclusive=True, default=0.5,
                 description="torsion-bar torque below which the valve builds no pressure (its open centre)",
                 source=f"assumed: 0.3-1 N m ({HANDBOOK}.3)"),
        Quantity(f"{NAME}.dead_band_smoothing", "N m", 0.0, 1.0, default=0.05,
                 description="width over which the dead band's corners are rounded",
                 source="numerical: a fraction of the dead band, keeps the Jacobian continuous"),
        Quantity(f"{NAME}.relief_pressure", "Pa", 1.0e5, 3.0e7, default=9.0e6,
                 description="the relief valve's pressure: the characteristic's saturation",
                 source=f"assumed: 8-11 MPa for passenger cars ({HANDBOOK}.4)"),
        Quantity(f"{NAME}.pressure_smoothing", "Pa", 0.0, 1.0e6, default=5.0e4,
                 description="width over which the relief limit's corners are rounded",
                 source="numerical: about 0.5 % of the relief pressure"),
        Quantity(f"{NAME}.piston_area", "m^2", 1.0e-5, 1.0e-2, default=8.0e-4,
                 description="effective area of the rack's piston (bore less rod)",
                 source=f"assumed: 40 mm bore on a 24 mm rod, pi/4 (0.040^2 - 0.024^2) = 8.0e-4 m^2; 5-12e-4 m^2 "
                        f"({HANDBOOK}.4)"),
        Quantity(f"{NAME}.seal_friction_force", "N", 0.0, 2000.0, lower_inclusive=True, default=100.0,
                 description="Coulomb friction of the piston's and rack's seals",
                 source=f"assumed: 50-200 N ({HANDBOOK}.4)"),
        Quantity(f"{NAME}.torsion_bar_stiffness", "N m/rad", 10.0, 10000.0, default=90.0,
                 description="torsion bar of the rotary valve, in series with the column",
                 source=f"assumed: valve torsion bars 1-2 N m/deg, 57-115 N m/rad ({HANDBOOK}.3)"),
        # a table's padded points continue its last slope up to 9 N m beyond its last point: 1e9 Pa leaves room
        # for any table within the relief pressure's range
        *table_quantities(NAME, "Pa", "Pa/(N m)", "(the valve's pressure)", upper=1.0e9),
    )
    uses = (*(q.key for q in quantities), VEHICLE_SPEED.key, "steering.column_torsional_stiffness",
            "steering.handwheel_to_rack_ratio", "steering.friction_smoothing")

    def deflection(self, model, twist):
        return series_deflection(model, twist, f"{NAME}.torsion_bar_stiffness")

    def pressure(self, model):
        p = lambda key: model.p(f"{NAME}.{key}")  # noqa: E731
        sensor = torsion_bar_torque(model, "pinion")
        opening = deadband(sensor, p("dead_band"), p("dead_band_smoothing"))
        demand = p("valve_slope") * opening + table_law_node(sensor, p, model.p(VEHICLE_SPEED.key))
        return clamp(demand, p("relief_pressure"), p("pressure_smoothing"))

    def loads(self, model):
        k = model.kinematics
        seal = model.p(f"{NAME}.seal_friction_force") * sp.tanh(model.p("steering.friction_smoothing") * model.rack_u)
        force = model.p(f"{NAME}.piston_area") * self.pressure(model) - seal
        # The piston pushes the rack and the cylinder (the housing) back.
        return action_reaction(k.rack_point, force * k.B.y, k.rack_housing_point)

    def outputs(self, model):
        pressure = self.pressure(model)
        return [
            ("torsion_bar_torque_Nm", torsion_bar_torque(model, "pinion")),
            ("assist_force_N", model.p(f"{NAME}.piston_area") * pressure),
            ("pressure_Pa", pressure),
        ]


EFFECT = HydraulicAssist()
