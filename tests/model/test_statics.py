"""Static equilibrium of the model against Table B1."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.model.numeric.simulate import prepare, static_state


@pytest.mark.parametrize("case", ["unladen", "part_laden", "offset_12_7mm", "offset_44_5mm", "offset_68_5mm"])
def test_static_equilibrium_carries_table_b1_loads(params, case):
    """At zero steer and rest, the full model's equilibrium (Newton on all coordinates, u = 0) carries the Table B1
    wheel loads within 0.1 N: the tyre free lengths and the roll spring's neutral angle are chosen for this,
    and the equilibrium can only hold them if the model's total weight equals W_l + W_r (m_chassis + 100 kg)."""
    run = prepare(case, params=params)
    y = static_state(run)
    out = run.model.evaluate_outputs(np.zeros(1), y[None, :], run.p)
    c = params.case(case)
    assert abs(out["load_left_N"][0] - c["load_left"]) < 0.1
    assert abs(out["load_right_N"][0] - c["load_right"]) < 0.1
    total_weight_N = (c["chassis_mass"] + params["vehicle.unsprung_mass"]) * params["vehicle.gravity"]
    assert abs(out["load_left_N"][0] + out["load_right_N"][0] - total_weight_N) < 1e-6 * total_weight_N


def test_static_state_is_at_rest(params):
    """The static state is an equilibrium: integrating from it with the handwheel held at zero leaves it at rest."""
    run = prepare("part_laden", params=params)
    y0 = static_state(run)
    rates = run.model.rhs(0.0, y0, run.p)
    assert np.max(np.abs(rates)) < 1e-9
