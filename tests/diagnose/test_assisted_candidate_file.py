"""An assisted candidate is one user file: the control unit's thermal derating of the motor's limit
(examples/assisted_candidate/current_derating.py), loaded as a user's effect module, is a candidate of an
electrically assisted car's diagnosis, named at its size where the car has it and not where it has not.

The records are the independent assisted truth (parksteer.synthetic.assisted_truth), not the model's assisted
replay: the Polo file's car replayed without its assist, and over it a column EPS written apart from the model's
(its own progressive map read through the sensor's converter steps, a worm gear, the control unit's current clipped
at its limit), logged as the assisted benchmarks log (a 10-bit torsion-bar torque on +-10 N m, 0.03 N m and 0.25 A of
noise). Its motor is sized for the parking duty: the 26 A limit is reached near the ends of the kerb cycle's strokes
(the current the map asks for peaks at about 28 A), so at its full limit the assist already saturates there for a
moment. The owner's file is the gear's data sheet and the map at its points
(parksteer.experiments.assisted_truth.owner_file): the motor's limit 26 A x k_t. The truth's rotor friction and the
band over which its friction and worm pass through rest are those the owner's file and the model's smoothing
describe (docs/assist_diagnosis.md, the truth ladder), so what the file does not hold is the map between its points and the
control unit's steps, and, in the derated record, the lower current limit.

The diagnoses offer the file's effect alone as candidate (the registry given to diagnose): what is tested is that a
user's file is taken as an assisted candidate and that its law is the derating's, not the ranking among the
package's candidates (the assisted benchmarks' subject). The model with the file's effect is derived once per
cache (about 10 s cold); the diagnoses take about 2 s with it.
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from parksteer.diagnose.candidates import candidate_effects
from parksteer.diagnose.problem import prepare_file
from parksteer.reporting.report import diagnosis_dict
from parksteer.diagnose.select import diagnose
from parksteer.experiments.assisted_truth_owner import owner_file
from parksteer.experiments.assisted_truth_design import TruthDesign
from parksteer.experiments.benchmark import BENCHMARK_SETTINGS
from parksteer.model.symbolic.components import MODULES_ENV, discover_effects, load_effect_module, resolve_effects
from parksteer.synthetic.assisted_truth import TruthGear, TruthLogger, TruthMap, manual_road, truth_record
from parksteer.synthetic.column_eps_layer import truth_clean
from parksteer.synthetic.variations import HandVariant

pytestmark = pytest.mark.slow  # derives the model with the user's effect once per cache

CASE = "kerb"
NAME = "current_derating"
DERATED = 0.2  # the truth's current limit is (1 - d) of the file's
# the owner's friction (the template's 0.02 N m) and the model's smoothing, tanh(1000 s/m x rack speed): linear up to
# about 2.25 rad/s of the rotor
FILE_GEAR = TruthGear(motor_friction_Nm=0.02, friction_speed_rad_s=2.25, direction_speed_rad_s=2.25,
                      current_limit_A=26.0)


@pytest.fixture(scope="module")
def candidate_file(repo_root):
    return repo_root / "examples" / "assisted_candidate" / "current_derating.py"


@pytest.fixture(scope="module")
def owner(repo_root, tmp_path_factory):
    discover_effects()  # the assists' quantities, which the owner's [assist] sets
    return owner_file(repo_root / "data" / "vehicles" / "polo_vi.toml", TruthDesign(gear=FILE_GEAR),
                      tmp_path_factory.mktemp("owner"))


@pytest.fixture(scope="module")
def road(owner):
    """The manual replay of one hand of the kerb cycle: the column torque the car without assist needs."""
    return manual_road(owner.params, HandVariant(0.05, 0.2, seed=3), CASE)


def diagnosed(owner, candidate_file, road, gear: TruthGear, seed: int) -> dict:
    """The JSON of the diagnosis, with the owner's file and the file's effect as the one candidate, of the truth's
    record with `gear`."""
    logger = TruthLogger(torque_bits=10, torque_full_scale_Nm=10.0, torque_noise_Nm=0.03, current_noise_A=0.25,
                         seed=seed)
    measurement = truth_record(truth_clean(road, TruthMap(), gear, logger), logger, CASE)
    effect = load_effect_module(str(candidate_file))
    result = diagnose([prepare_file(measurement, CASE, label="polo")], owner.params, owner.effects,
                      settings=BENCHMARK_SETTINGS, registry={effect.name: effect})
    return diagnosis_dict(result)


def test_a_user_file_is_an_assisted_candidate_of_an_assisted_car_only(candidate_file, monkeypatch, owner):
    """Registered as a user's effect module (the environment variable a user sets), the derating is a testable
    candidate of a diagnosis of the electrically assisted car, and not of a car without assist; the package's own
    effects do not include it."""
    monkeypatch.delenv(MODULES_ENV, raising=False)
    assert NAME not in discover_effects()
    monkeypatch.setenv(MODULES_ENV, str(candidate_file))
    registry = discover_effects()
    assisted, _ = candidate_effects(owner.effects, registry)
    manual, _ = candidate_effects(resolve_effects(None), registry)
    assert NAME in [e.name for e in assisted]
    assert NAME not in [e.name for e in manual]


def test_a_derated_current_limit_is_named_and_its_fraction_recovered(owner, road, candidate_file):
    """A control unit that allows 80 % of the motor's current (20.8 A of 26 A): the assist saturates earlier and
    lower, over a longer part of each stroke's end, and the driver's torsion-bar torque takes the shortfall there
    (up by some 4 N m at the peaks). The diagnosis calls the model missing the derating and its 95 % interval of
    the fraction holds the true 0.2."""
    truth = replace(FILE_GEAR, current_limit_A=FILE_GEAR.current_limit_A * (1.0 - DERATED))
    result = diagnosed(owner, candidate_file, road, truth, seed=11)
    assert result["verdict"] == "missing" and result["effect"] == NAME
    entry = next(r for r in result["ranking"] if r["effect"] == NAME)
    low, high = entry["parameters"][entry["strength_parameter"]]["ci95"]
    assert entry["strength_parameter"] == f"{NAME}.fraction"
    assert low <= DERATED <= high and high - low < 0.05


def test_a_car_at_its_full_current_limit_is_not_called_derated(owner, road, candidate_file):
    """The same car at its full current limit (saturating at the strokes' ends as its file says): the derating is
    not named."""
    result = diagnosed(owner, candidate_file, road, FILE_GEAR, seed=12)
    assert result["effect"] != NAME
