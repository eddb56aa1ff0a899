"""The assisted benchmark on an independent truth (parksteer.experiments.assisted_truth): the owner's file and the
cases' identity."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from parksteer.errors import UsageError
from parksteer.experiments.assisted_truth import design_from_config
from parksteer.experiments.assisted_truth_design import TruthDesign, case_names, cases
from parksteer.experiments.assisted_truth_owner import owner_vehicle_text
from parksteer.model.symbolic.components import discover_effects
from parksteer.vehicle import vehicle_from_text

ROOT = Path(__file__).resolve().parents[2]
POLO = ROOT / "data" / "vehicles" / "polo_vi.toml"


def test_owner_file_holds_the_map_at_its_points_and_assumes_the_motor_friction(tmp_path):
    """The owner's file is what an owner has: the control unit's map at the design's points (a progressive
    power law 3.9 (|T| - 0.4)^1.6 here: 0 in the dead band, 3.9 x 0.4^1.6 = 0.900 N m at 0.8 N m), the gear's data
    sheet, and the motor friction no data sheet gives left at the template's assumed default, not the truth's; so is
    the band of rotor speed over which that friction and the worm's direction change over at a reversal (the
    truth's is 1 rad/s)."""
    discover_effects()
    design = TruthDesign()
    params = vehicle_from_text(owner_vehicle_text(POLO.read_text(encoding="utf-8"), design), tmp_path / "o.toml")
    name = "electric_assist_column"
    torques = [params[f"{name}.boost_torque_{k}"] for k in range(len(design.map_points_Nm))]
    assists = [params[f"{name}.boost_assist_0_{k}"] for k in range(len(design.map_points_Nm))]
    assert torques == list(design.map_points_Nm)
    assert assists[:2] == [0.0, 0.0]
    assert assists[2] == pytest.approx(3.9 * 0.4**1.6, abs=1e-6)
    assert params[f"{name}.reduction_ratio"] == design.gear.reduction
    assert params[f"{name}.motor_torque_limit"] == pytest.approx(4.0)
    assert params[f"{name}.motor_friction_torque"] != design.gear.motor_friction_Nm
    assert params.sources[f"{name}.motor_friction_torque"].startswith("assumed")
    assert params[f"{name}.friction_speed"] != design.gear.friction_speed_rad_s
    assert params.sources[f"{name}.friction_speed"].startswith("assumed")


def test_a_case_kept_by_the_default_grid_is_the_full_grids_case():
    """config/config.yaml's grid keeps cases of the full grid (config/full_grids.yaml) unchanged: the same name,
    hand seed and torque converter, so that the default figure's records are records of the full one."""
    default = yaml.safe_load((ROOT / "config" / "config.yaml").read_text(encoding="utf-8"))["assisted_truth"]
    full = yaml.safe_load((ROOT / "config" / "full_grids.yaml").read_text(encoding="utf-8"))["assisted_truth"]
    small = {c.name: c for c in cases(design_from_config(default))}
    large = {c.name: c for c in cases(design_from_config({**default, **full}))}
    assert small and set(small) <= set(large)
    for name, case in small.items():
        assert case == large[name]
    converters = {c.converter for c in large.values()}
    assert len(converters) == len(TruthDesign().torque_converters)  # the full grid logs on every converter


def test_the_tiers_make_distinct_records():
    """The angle-only tier's records are not the rack tier's with a column dropped: their noise is seeded apart."""
    design = TruthDesign(null_variations=("pauses",), hidden_variations=(), out_of_class_variations=())
    rack, angle = cases(design)
    assert (rack.tier, angle.tier) == ("rack", "angle")
    assert rack.seed != angle.seed
    assert len(set(case_names(design))) == 2


@pytest.mark.parametrize("section, word", [({"hidden": ["stiction"]}, "hidden"),
                                           ({"null_variations": ["no_such_hand"]}, "no_such_hand"),
                                           ({"tiers": ["can"]}, "tiers")])
def test_design_refuses_what_it_does_not_know_in_one_line(section, word):
    """A configuration naming an unknown hidden effect, hand or tier is refused in one line naming it."""
    with pytest.raises(UsageError) as error:
        design_from_config(section)
    assert word in str(error.value) and "\n" not in str(error.value)
