"""An assist candidate shipped in the library is one effect file plus one row: the assisted benchmarks' tables of
what they hide (the quantity set, the size band, the cases, how the independent truth shows it) are built from the
library's declarations and the truth's rows (parksteer.synthetic.assisted_truth.HIDDEN_TRUTH), nowhere else."""

from __future__ import annotations

import textwrap

import pytest

from parksteer.errors import UsageError
from parksteer.experiments import assisted_benchmark as model_bench
from parksteer.experiments import assisted_truth_design as truth_design
from parksteer.experiments.assisted_truth import design_from_config
from parksteer.model.symbolic.components import MODULES_ENV, discover_effects
from parksteer.synthetic import assisted_truth as truth

NAME = "worm_load_friction"
# the new candidate's strength band (its file's quantity) and the truth's row: the truth's gear friction that grows
# with the motor's torque, searched up to 0.8
UPPER = 0.6
ROW = truth.TruthHidden("current_friction", 0.8)

EFFECT_FILE = f'''
"""A friction of the worm growing with the motor's torque: a test's assist candidate, declared only."""
from parksteer.model.symbolic.components import Effect
from parksteer.parameters import Quantity

NAME = "{NAME}"


class WormLoadFriction(Effect):
    name = NAME
    description = "a friction of the worm growing with the motor's torque; 0 = absent"
    in_default_set = False
    diagnosis_candidate = False
    assist_candidate = True
    quantities = (Quantity(f"{{NAME}}.strength", "1", 0.0, {UPPER}, lower_inclusive=True, default=0.0,
                           source="candidate: a test's; 0 = absent"),)
    uses = (f"{{NAME}}.strength",)


EFFECT = WormLoadFriction()
'''


@pytest.fixture
def added(tmp_path, monkeypatch):
    """The library with one more assist candidate: its file (loaded as a user's effect module) and its one row."""
    path = tmp_path / f"{NAME}.py"
    path.write_text(textwrap.dedent(EFFECT_FILE), encoding="utf-8")
    monkeypatch.setenv(MODULES_ENV, str(path))
    monkeypatch.setitem(truth.HIDDEN_TRUTH, NAME, ROW)
    return NAME


def test_an_added_assist_candidate_is_in_every_table(added):
    """The fact checked: with one file and one row, the new candidate is hidden by both assisted benchmarks: the
    model's records set its strength quantity and search up to that quantity's upper bound, at every hidden hand
    and size of the design; the truth's records set the row's field of Hidden, searched up to the row's size, at
    every hidden hand, size and tier; a configuration may select it."""
    hidden = model_bench.hidden_candidates()
    assert hidden[added] == (f"{added}.strength", UPPER)
    assert model_bench.largest_size(added, hidden) == UPPER
    design = model_bench.AssistedDesign()
    names = set(model_bench.case_names(design))
    assert {f"{v}__{added}_{s:g}" for v in design.hidden_variations for s in design.steps} <= names

    assert added in truth_design.TruthDesign().hidden
    assert truth_design.largest_size(added) == ROW.largest
    assert truth.with_hidden(truth.Hidden(), added, 0.25).current_friction == 0.25
    selected = design_from_config({"hidden": ["assist_motor_friction", added]})
    cases = [c for c in truth_design.cases(selected) if c.hidden == added]
    assert len(cases) == len(selected.tiers) * len(selected.hidden_variations) * len(selected.floors)


def test_a_candidate_without_its_row_or_a_row_without_its_candidate_is_refused(tmp_path, monkeypatch):
    """The fact checked: the tables cannot drift apart silently: an assist candidate the package ships with no truth
    row, and a truth row naming no assist candidate, are each refused in one line naming it; a user's effect module
    without a row is left out of the benchmarks (diagnosed, not benchmarked)."""
    path = tmp_path / f"{NAME}.py"
    path.write_text(textwrap.dedent(EFFECT_FILE), encoding="utf-8")
    monkeypatch.setenv(MODULES_ENV, str(path))
    assert NAME in discover_effects() and NAME not in model_bench.hidden_candidates()
    monkeypatch.delenv(MODULES_ENV)
    library = discover_effects()
    rows = {name: row for name, row in truth.HIDDEN_TRUTH.items() if name != "torsion_bar_offset"}
    monkeypatch.setattr(model_bench, "HIDDEN_TRUTH", rows)  # the truth's table itself stays as it is
    with pytest.raises(UsageError, match="shipped assist candidate 'torsion_bar_offset' has no row") as info:
        model_bench.hidden_candidates(library)
    assert "\n" not in str(info.value)
    without = {name: effect for name, effect in library.items() if name != "boost_gain_error"}
    with pytest.raises(UsageError, match="row 'boost_gain_error' is not an assist candidate") as info:
        model_bench.hidden_candidates(without)
    assert "\n" not in str(info.value)


def test_the_shipped_library_hides_each_assist_candidate_at_its_declared_band():
    """The fact checked: every assist candidate the package ships has its truth row, and the model's records set one
    of the candidate's own quantities, absent at 0, searched up to the top of the range its source declares."""
    library = discover_effects()
    shipped = [name for name, effect in library.items() if effect.assist_candidate]
    hidden = model_bench.hidden_candidates(library)
    assert sorted(shipped) == sorted(name for name in hidden if name != "rack_friction")
    for name in shipped:
        quantity = next(q for q in library[name].quantities if q.key == hidden[name][0])
        assert hidden[name][1] == quantity.upper and quantity.default == 0.0
