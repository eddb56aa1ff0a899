"""The column law (parksteer.geometry.rack_from_handwheel): handwheel angle and torque to rack."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from parksteer.geometry import pinion_angle_from_column, rack_from_handwheel
from parksteer.model.symbolic.effects.hooke_joint import EFFECT as HOOKE


class _Symbols:
    """Stands in for the model space: the effect asks it for its parameters by name."""

    def __init__(self):
        self.symbols = {"joint_angle": sp.Symbol("alpha"), "phase": sp.Symbol("phase")}

    def p(self, *key):
        # p(key) with the quantity key, or p(effect, name): the joint angle and the phase either way
        return self.symbols["phase" if key[-1].endswith("phase") else "joint_angle"]


@pytest.mark.parametrize("joint_angle, phase", [(0.45, 0.0), (0.45, 0.7), (1.1, -2.0), (0.0, 0.3)])
def test_pinion_from_column_inverts_the_hooke_joints_own_map(joint_angle, phase):
    """Physical fact: the Hooke joint's column angle of a pinion angle, fed to the closed-form inverse, gives the
    pinion angle back to 1e-12 over five turns each way (both branches of tan crossed many times)."""
    model = _Symbols()
    theta_p = sp.Symbol("theta_p")
    column_of_pinion = sp.lambdify((theta_p, model.symbols["joint_angle"], model.symbols["phase"]),
                                   HOOKE.column_angle(model, theta_p), "numpy")
    pinion = np.linspace(-10 * np.pi, 10 * np.pi, 20001)
    column = column_of_pinion(pinion, joint_angle, phase)
    assert np.max(np.abs(pinion_angle_from_column(column, joint_angle, phase) - pinion)) < 1e-12
    if joint_angle > 0.3:
        assert np.max(np.abs(column - pinion)) > 0.01, "the joint is not the identity here: the test can fail"


def test_rack_from_handwheel_subtracts_the_column_twist(params):
    """Physical fact: torque twists the column by T / k before the pinion, so a torque that exactly undoes the
    handwheel angle leaves the rack at the centre, and a straight column (no joint angle) gives angle / ratio."""
    s = params.sections["steering"]
    k, ratio = s["column_torsional_stiffness"], s["handwheel_to_rack_ratio"]
    assert rack_from_handwheel(np.array([0.02]), np.array([0.02 * k]), params)[0] == pytest.approx(0.0, abs=1e-15)
    straight = params.with_overrides({"steering.hooke_joint_angle": 0.0})
    angle = np.linspace(-12.0, 12.0, 7)
    assert np.allclose(rack_from_handwheel(angle, np.zeros(7), straight), angle / ratio, rtol=0, atol=1e-15)
