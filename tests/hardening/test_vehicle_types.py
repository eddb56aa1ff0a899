"""Every value of a vehicle file has its type checked: each entry of each shipped vehicle file, its value, unit or
source replaced by one of another type (a TOML boolean, a number in quotes, a table, an empty list), is refused in
one line naming the file and the entry's key, never taken (float() would take true and "0.9") and never a
traceback."""

from __future__ import annotations

import re

import pytest

import parksteer.model  # noqa: F401 (an effect's own quantities in a vehicle file are known once the model is)
from parksteer.errors import UsageError
from parksteer.model.numeric.assist import check_assist
from parksteer.vehicle import vehicle_from_text

from .corpus import REPO

CARS = sorted((REPO / "data" / "vehicles").glob("*.toml"))
ENTRY = re.compile(r"^(\w+) = \{")
WRONG_VALUES = ("true", '"0.5"', "{ a = 1 }", "[]")
WRONG_TEXT = ("1", "true", '["x"]')


def _variants(text: str):
    """(key, changed text) for each entry line of `text` and each wrong type of its value, unit and source."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        entry = ENTRY.match(line)
        if entry is None:
            continue
        changes = [re.sub(r"value = (\[[^\]]*\]|[^,]+)", f"value = {v}", line, count=1) for v in WRONG_VALUES]
        changes += [re.sub(f'{field} = "[^"]*"', f"{field} = {v}", line, count=1)
                    for field in ("unit", "source") if f'{field} = "' in line for v in WRONG_TEXT]
        for changed in changes:
            assert changed != line
            yield entry.group(1), "\n".join(lines[:i] + [changed] + lines[i + 1:]) + "\n"


@pytest.mark.parametrize("car", CARS, ids=[c.stem for c in CARS])
def test_every_entry_of_a_wrong_type_is_refused_naming_its_key(car, params):
    """Each shipped car loads; each of its entries with a value, unit or source of the wrong type is refused with
    a one-line error naming the file and the entry's key. Each variant is read over the base file loaded once (the
    session's `params`), whose parse would otherwise be most of each check's time."""
    text = car.read_text(encoding="utf-8")
    check_assist(vehicle_from_text(text, car, params))
    count = 0
    for key, changed in _variants(text):
        count += 1
        with pytest.raises(UsageError) as refused:
            check_assist(vehicle_from_text(changed, car, params))
        message = str(refused.value)
        assert "\n" not in message and message.startswith(f"{car}: ") and key in message, (key, message)
    assert count > 300
