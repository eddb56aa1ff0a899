"""The reports advise only what the tool accepts: which of an assisted car's assumed values `parksteer assist
identify` can fix (parksteer.reporting.sections)."""

from __future__ import annotations

from parksteer.reporting.sections import _assumed_parts, _identify_measures

NAME = "electric_assist_column"


def _row(key: str, decides: bool = True) -> dict:
    end = {"calibrated_over_floor": 1.0, "verdict": "missing"}
    return {"quantity": f"{NAME}.{key}", "value": 1.0, "band": [0.5, 2.0], "ends": [end, end], "decides": decides}


def test_identify_is_advised_only_for_what_it_measures():
    """assist identify measures the motor's friction and inertia, the back-driven efficiency and the product
    k_t eta N: a factor of that product (efficiency, reduction) is fixed by it only while the product is itself
    assumed; once the file's torque constant is identified (not among the assumed values), only a data sheet gives
    the efficiency, and the torsion bar's stiffness is never measured by it."""
    assumed_product = [_row("torque_constant"), _row("efficiency"), _row("torsion_bar_stiffness")]
    assert _identify_measures(f"{NAME}.efficiency", assumed_product)
    assert _identify_measures(f"{NAME}.motor_inertia", assumed_product)
    assert not _identify_measures(f"{NAME}.torsion_bar_stiffness", assumed_product)
    identified_product = [_row("efficiency"), _row("reduction_ratio")]
    assert not _identify_measures(f"{NAME}.efficiency", identified_product)
    text = _assumed_parts({"nominal": {"calibrated_over_floor": 1.0, "verdict": "missing"},
                           "quantities": identified_product})[0].text
    assert "assist identify" not in text and "a data sheet" in text
    text = _assumed_parts({"nominal": {"calibrated_over_floor": 1.0, "verdict": "missing"},
                           "quantities": assumed_product})[0].text
    assert f"assist identify` on a baseline record fixes `{NAME}.torque_constant`, `{NAME}.efficiency`" in text
