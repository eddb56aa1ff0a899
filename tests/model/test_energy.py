"""Energy balance of the conservative model."""

from __future__ import annotations

import numpy as np
from scipy.integrate import cumulative_trapezoid

from model_helpers import DISSIPATION_OFF

from parksteer.model.numeric.simulate import simulate

def test_work_at_handwheel_equals_energy_change_without_dissipation(params):
    """With every friction and damper off (air bearings: no tyre friction), the work done at the handwheel,
    integral of T * dtheta_h/dt, equals the change of kinetic energy (from the bodies' velocities, not the
    mass matrix) plus gravity, tyre, roll, carcass and column spring energy, over the first 3 s of the cycle
    in which the steering lifts the car."""
    result = simulate("unladen", overrides=DISSIPATION_OFF, surface="air_bearing", params=params,
                      t_end_s=3.0, output_dt_s=0.0005, rtol=1e-10)
    c = result.columns
    out = result.model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
    energy_J = out["kinetic_energy_J"] + out["potential_energy_J"] + out["column_energy_J"]
    work_J = cumulative_trapezoid(c["handwheel_torque_Nm"] * c["handwheel_rate_rad_s"], c["time_s"], initial=0.0)
    assert work_J[-1] > 1.0  # the car has been lifted: a real exchange of energy, not a trivial zero
    assert np.max(np.abs(work_J - (energy_J - energy_J[0]))) < 1e-4 * work_J[-1]
