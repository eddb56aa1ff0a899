"""The door of a user's effect file (parksteer.commands.effect_files) and of a quantity's declaration
(parksteer.parameters.declaration_problem): what it lets through as well as what it refuses (the refusals, one per
defect and command, are in the bad-input corpus, tests/hardening/corpus.py)."""

from __future__ import annotations

import dataclasses
import math
import os
from multiprocessing.pool import RemoteTraceback

import pytest

from parksteer.commands import effect_files
from parksteer.errors import UsageError
from parksteer.model.symbolic import components
from parksteer.parameters import CASE_SCHEMA, SCHEMA, VEHICLE_SPEED, Quantity, declaration_problem

from .corpus import REPO, effect_text

EXAMPLES = (*sorted((REPO / "examples").glob("*/*.py")), REPO / "src" / "parksteer" / "examples" / "column_imbalance.py")


def test_environment_variable_is_the_registrys():
    """The door reads the same environment variable as the effect registry, which it names apart so that a
    command without a user's effect does not import the symbolic model."""
    assert effect_files.MODULES_ENV == components.MODULES_ENV


def test_every_library_quantity_passes_the_door():
    """Every quantity the library declares or the parameter file holds has a declaration the door accepts and an SI
    unit pint knows: the checks refuse no quantity of the library's own (its effects' and the file's keys)."""
    library = effect_files.library_effects()
    quantities = ({q.key: q for e in library.values() for q in e.quantities}
                  | {q.key: q for table in (*SCHEMA.values(), CASE_SCHEMA) for q in table.values()}
                  | {VEHICLE_SPEED.key: VEHICLE_SPEED})
    assert len(library) >= 20 and len(quantities) > 100
    refused = {k: declaration_problem(q) for k, q in quantities.items()
               if q.default is not None and declaration_problem(q) is not None}
    assert refused == {}
    assert {q.unit: effect_files.unit_problem(q.unit) for q in quantities.values()
            if effect_files.unit_problem(q.unit) is not None} == {}


@pytest.mark.parametrize("unit, si", [("mm", "m"), ("deg", "rad"), ("bar", "kg / m / s ** 2"), ("km/h", "m / s"),
                                      ("percent", "1")])
def test_a_unit_that_is_not_si_is_refused_with_its_si_unit(unit, si):
    """The model reads every value in SI: a unit pint knows but not SI (a prefix, degrees, bar, km/h, per cent) is
    refused with the factor to SI and the SI unit to give."""
    problem = effect_files.unit_problem(unit)
    assert problem is not None and "is not SI" in problem and problem.endswith(f"give {si}"), problem


def test_declaration_problems_of_bounds():
    """A declaration's bounds: both numbers, not NaN, lower below upper; finite on both sides when the quantity is
    fitted (free), open ends allowed when it is not; a default that is a number."""
    q = Quantity("mine.force", "N", 0.0, 10.0, lower_inclusive=True, default=0.0, source="x")
    assert declaration_problem(q) is None
    assert declaration_problem(dataclasses.replace(q, upper=math.inf)) is None
    assert declaration_problem(dataclasses.replace(q, free=True)) is None
    assert "finite bounds" in declaration_problem(dataclasses.replace(q, upper=math.inf, free=True))
    assert "not a number" in declaration_problem(dataclasses.replace(q, lower=None))
    assert "not a number" in declaration_problem(dataclasses.replace(q, upper=True))
    assert "NaN" in declaration_problem(dataclasses.replace(q, upper=math.nan))
    assert "out of order" in declaration_problem(dataclasses.replace(q, lower=10.0, upper=10.0))
    assert "default" in declaration_problem(dataclasses.replace(q, default="0"))


def test_the_shipped_examples_pass_the_door():
    """The example effects (examples/*/ and the package's column imbalance) load through the door unchanged."""
    found = effect_files.check_effect_files(",".join(f"+{p}" for p in EXAMPLES))
    assert [u.effect.name for u in found] == ["current_derating", "centre_friction", "column_imbalance"]
    assert [u.path for u in found] == [str(p) for p in EXAMPLES]


def test_a_library_name_is_taken_once_the_library_effect_is_removed(tmp_path):
    """An effect of a library effect's name is refused while the library's is in the set, and taken when the spec
    removes the library's first (-name before +FILE), or names the set exactly without it."""
    path = tmp_path / "mine.py"
    path.write_text(effect_text(name="column_friction"), encoding="utf-8")
    with pytest.raises(UsageError, match="has the name of the library's"):
        effect_files.check_effect_files(f"+{path}")
    with pytest.raises(UsageError, match="has the name of the library's"):
        effect_files.check_effect_files(f"column_friction,{path}")
    assert [u.effect.name for u in effect_files.check_effect_files(f"-column_friction,+{path}")] == ["column_friction"]
    assert [u.effect.name for u in effect_files.check_effect_files(f"tyre_friction,{path}")] == ["column_friction"]


def test_no_user_effect_no_model_import(monkeypatch):
    """Without a user's effect in the spec or the environment the door loads nothing."""
    monkeypatch.delenv(effect_files.MODULES_ENV, raising=False)
    assert effect_files.check_effect_files("-rack_friction,+hooke_joint") == []
    assert effect_files.check_effect_files(None) == []


def _user(tmp_path):
    path = tmp_path / "mine.py"
    return effect_files.UserEffect(str(path), object(), os.path.abspath(path)), path


def test_a_workers_exception_names_the_file_and_the_hook(tmp_path):
    """An exception raised in a user's hook inside a worker reaches the parent with its frames as text
    (multiprocessing's RemoteTraceback as its cause): the line names the file, the outermost hook of the file and
    the innermost line of it."""
    user, path = _user(tmp_path)
    exc = ZeroDivisionError("division by zero")
    exc.__cause__ = RemoteTraceback(
        'Traceback (most recent call last):\n'
        '  File "/x/parksteer/model/numeric/assisted.py", line 300, in law\n'
        f'  File "{path}", line 31, in boost_law\n'
        f'  File "{path}", line 12, in _gain\n'
        'ZeroDivisionError: division by zero\n')
    assert effect_files.hook_error(exc, [user]) == (
        f"effect file {path}: its hook boost_law() raised ZeroDivisionError: division by zero (line 12)")


def test_an_exception_elsewhere_is_left_alone(tmp_path):
    """An exception with no frame in a user's file is not attributed to it (it stays a traceback: a fault of the
    package, not of the user's input)."""
    user, _ = _user(tmp_path)
    try:
        raise KeyError("x")
    except KeyError as exc:
        assert effect_files.hook_error(exc, [user]) is None


def test_an_exception_in_a_real_worker_names_the_file_and_the_hook(tmp_path):
    """A user's function raising in a forked pool worker (as a diagnosis's replay workers call an effect's
    boost_law): the exception the parent receives is reported with the file, the hook called and the innermost
    line of the file (the division, line 5)."""
    import importlib.util
    import multiprocessing
    import sys

    path = tmp_path / "mine.py"
    path.write_text("def boost_law(x):\n    return _gain(x)\n\ndef _gain(x):\n    return 1 / x\n", encoding="utf-8")
    spec = importlib.util.spec_from_file_location("door_worker_probe", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # found by name in the forked worker, as parksteer.diagnose.parallel arranges
    try:
        spec.loader.exec_module(module)
        with multiprocessing.get_context("fork").Pool(1) as pool, pytest.raises(ZeroDivisionError) as raised:
            pool.apply(module.boost_law, (0.0,))
    finally:
        del sys.modules[spec.name]
    user = effect_files.UserEffect(str(path), object(), os.path.abspath(path))
    assert effect_files.hook_error(raised.value, [user]) == (
        f"effect file {path}: its hook boost_law() raised ZeroDivisionError: float division by zero (line 5)")
