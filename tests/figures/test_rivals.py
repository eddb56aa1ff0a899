"""Rivals of lifting (parksteer.figures.rivals): the matched rivals' rises checked against the physics of each
mechanism, and lifting's against equation (A1)."""

from __future__ import annotations

import pytest

from parksteer.figures.rivals import compare_rivals, rivals_table
from parksteer.geometry import steer_axis


@pytest.fixture(scope="module")
def result(params):
    return compare_rivals(params, rivals=("top_mount_windup", "gear_efficiency", "carcass_hysteresis"))


def test_lifting_rise_grows_with_the_kingpin_offset_as_equation_a1_says(params, result):
    """Equation (A1): at given wheel loads and steer angle the lifting torque is proportional to the offset d of
    the wheel centre from the steer axis, so the 68.5 mm spacers (same loads) scale lifting's rise by d'/d."""
    lifting = result["lifting"]["tests"]
    ratio = lifting["spacer_68_5_ground"]["rise_Nm"] / lifting["unladen_ground"]["rise_Nm"]
    d_ratio = steer_axis(params, "offset_68_5mm", "left").offset_d_m / steer_axis(params, "unladen", "left").offset_d_m
    assert ratio == pytest.approx(d_ratio, rel=0.05)
    # and it needs no tyre friction: on air bearings the rise is the ground's within a few per cent
    assert lifting["unladen_air"]["rise_Nm"] == pytest.approx(lifting["unladen_ground"]["rise_Nm"], rel=0.05)


def test_a_matched_rival_adds_lifting_rise_in_the_matched_test(result):
    target = result["target_rise_Nm"]
    for name in result["matched"]:
        assert result["rivals"][name]["tests"]["unladen_ground"]["rise_Nm"] == pytest.approx(target, rel=0.011)


def test_top_mount_windup_is_elastic_so_load_surface_and_offset_leave_it_alone(result):
    """An elastic torque about the king-pin axis depends on the steer angle only: the same rise in every test (to
    2 %), so only a test that changes lifting (spacers, loads) can separate the two; the spacers do."""
    top = result["rivals"]["top_mount_windup"]
    assert top["status"] == "matched"
    rises = [t["rise_Nm"] for t in top["tests"].values()]
    assert max(rises) - min(rises) < 0.02 * result["target_rise_Nm"]
    assert top["separating_test"] == "spacer_68_5_ground" and top["told_apart"]


def test_gear_efficiency_loses_its_rise_on_air_bearings(result):
    """Mesh friction proportional to the load it transmits: on air bearings the tyre's moment is gone, so its
    rise falls with the transmitted torque (to well under lifting's, which needs no tyre friction)."""
    gear = result["rivals"]["gear_efficiency"]
    assert gear["status"] == "matched"
    assert gear["tests"]["unladen_air"]["rise_Nm"] < 0.7 * result["lifting"]["tests"]["unladen_air"]["rise_Nm"]


def test_carcass_hysteresis_does_not_rise_toward_lock(result):
    """A Maxwell branch beside the carcass spring relaxes while the wheel steers steadily: it shapes the reversals,
    not the torque near lock, so it cannot stand in for lifting."""
    assert result["rivals"]["carcass_hysteresis"]["status"] == "no rise"
    assert "carcass_hysteresis" in result["no_rise"]


def test_table_has_lifting_first_and_a_row_per_rival(result):
    rows = rivals_table(result)
    assert rows["mechanism"] == ["lifting", "top_mount_windup", "gear_efficiency", "carcass_hysteresis"]
    assert all(len(v) == 4 for v in rows.values())
