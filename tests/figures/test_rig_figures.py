"""Outputs of Table 1, Fig. 3 and Fig. 4: the quoted numbers are the physics, the files are reproducible."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from parksteer.resources import data_file
from parksteer.errors import UsageError
from parksteer.figures.rig import make_fig3, make_fig4, make_table1
from parksteer.tables import read_csv


def test_table1_outputs_list_exactly_the_ratio_discrepancies(params, repo_root, tmp_path):
    """Only the 60 mm and 105 mm spin/steer ratios disagree with their angle quotient, and both are explained
    by the rounding of the printed angles; the CSV carries printed and recomputed columns side by side."""
    make_table1(params, data_file("table1_printed.csv"), tmp_path / "t.csv", tmp_path / "t.json")
    summary = json.loads((tmp_path / "t.json").read_text())
    found = [(d["offset_mm"], d["quantity"], d["explained_by_angle_rounding"]) for d in summary["disagreements"]]
    assert found == [(60.0, "spin_steer_ratio", True), (105.0, "spin_steer_ratio", True)]
    columns, header = read_csv(tmp_path / "t.csv")
    np.testing.assert_allclose(columns["printed_percentage_difference"], [-15.0, -3.2, 0.5])
    assert "Table 1" in header["printed source"]


def test_fig3_outputs_cross_at_reference_pressure_and_quote_the_correction(params, tmp_path):
    """The (1) and (2) curves meet at p0 = 2.45 bar; the quoted eq(2)/eq(1) ratio at 1.5 bar is (2.45/1.5)^0.28."""
    make_fig3(params, tmp_path / "f.svg", tmp_path / "f.csv", tmp_path / "f.json")
    columns, _ = read_csv(tmp_path / "f.csv")
    at_p0 = np.isclose(columns["pressure_Pa"], 2.45e5)
    assert at_p0.sum() == len(params["rig.loads"])
    np.testing.assert_allclose(columns["empirical_torque_Nm"][at_p0], columns["gough_torque_Nm"][at_p0], rtol=1e-6)
    summary = json.loads((tmp_path / "f.json").read_text())
    ratios = {entry["pressure_Pa"]: entry["ratio"] for entry in summary["equation2_over_equation1"]}
    assert ratios[1.5e5] == pytest.approx((2.45 / 1.5) ** 0.28, rel=1e-6)
    assert summary["loads_source"].startswith("choice:")


def test_fig4_outputs_flat_free_rolling_and_rising_braked(params, tmp_path):
    """Free-rolling torque is the same at every offset (equation (2) at that pressure); the braked torque
    at the largest offset is well above it, and never above mu W e plus the free-rolling torque (friction cannot
    sum to more than mu W, whatever the pressure); the SVG is byte-identical when made twice."""
    make_fig4(params, tmp_path / "a.svg", tmp_path / "a.csv", tmp_path / "a.json")
    make_fig4(params, tmp_path / "b.svg", tmp_path / "b.csv", tmp_path / "b.json")
    assert (tmp_path / "a.svg").read_bytes() == (tmp_path / "b.svg").read_bytes()
    summary = json.loads((tmp_path / "a.json").read_text())
    headline = summary["headline"]
    assert (headline["load_N"], headline["pressure_Pa"]) == (3800.0, 2.0e5)
    hand_eq2 = 2.0 / 3.0 * 0.666 * 3800.0**1.5 / math.sqrt(math.pi * 2.0e5) * (2.45 / 2.0) ** 0.28
    assert headline["free_rolling_torque_Nm"] == pytest.approx(hand_eq2, rel=1e-6)
    assert headline["braked_over_free"] > 2.0
    columns, _ = read_csv(tmp_path / "a.csv")
    for p in params["rig.fig4_pressures"]:
        for w in params["rig.loads"]:
            rows = (columns["pressure_Pa"] == p) & (columns["load_N"] == w)
            free = columns["free_rolling_torque_Nm"][rows]
            assert np.ptp(free) == 0.0
            assert np.all(np.diff(columns["braked_torque_Nm"][rows]) > 0.0)
            bound = params["tyre.friction_coefficient"] * w * columns["offset_m"][rows] + free
            assert np.all(columns["braked_torque_Nm"][rows] <= bound * (1.0 + 1e-9))
    assert "(p0/p)^(n-0.5)" in summary["statement"]


def test_bad_parameter_file_is_a_usage_error(tmp_path):
    """A missing parameter file stops the figure with a one-line usage error and writes nothing."""
    with pytest.raises(UsageError) as info:
        make_fig3(tmp_path / "missing.toml", tmp_path / "f.svg", tmp_path / "f.csv", tmp_path / "f.json")
    assert "\n" not in str(info.value)
    assert not any(tmp_path.iterdir())
