"""The prescribed-rack drive mode against the handwheel-driven model."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.model.numeric.inputs import rack_drive_from_arrays
from parksteer.model.numeric.simulate import simulate


def test_prescribed_rack_reproduces_the_handwheel_torque(params):
    """Driving the rack with the rack travel that the handwheel-driven cycle produced, and solving the Kane
    equations for the column torque together with the other accelerations, gives back the same handwheel torque
    and handwheel angle (within 0.05 N m and 1e-4 rad away from the spline's end samples)."""
    reference = simulate("unladen", params=params, output_dt_s=0.005)
    c = reference.columns
    drive = rack_drive_from_arrays(c["time_s"], c["rack_m"])
    driven = simulate("unladen", rack_drive=drive, params=params, output_dt_s=0.01)
    d = driven.columns
    inner = (d["time_s"] > 0.1) & (d["time_s"] < 17.9)
    torque = np.interp(d["time_s"], c["time_s"], c["handwheel_torque_Nm"])
    angle = np.interp(d["time_s"], c["time_s"], c["handwheel_angle_rad"])
    assert np.max(np.abs(d["handwheel_torque_Nm"] - torque)[inner]) < 0.05
    assert np.max(np.abs(d["handwheel_angle_rad"] - angle)[inner]) < 1e-4
    total = sum(d[name] for name in driven.contribution_names)
    assert np.max(np.abs(total - d["handwheel_torque_Nm"])) < 1e-9 * np.max(np.abs(d["handwheel_torque_Nm"]))


def test_rack_drive_rejects_bad_samples():
    """A rack drive needs at least four samples at strictly increasing times."""
    with pytest.raises(UsageError):
        rack_drive_from_arrays([0.0, 1.0, 1.0, 2.0], [0.0, 0.01, 0.02, 0.03])
    with pytest.raises(UsageError):
        rack_drive_from_arrays([0.0, 1.0], [0.0, 0.01])
