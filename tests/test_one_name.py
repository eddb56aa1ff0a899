"""One name, one definition: the torque column's name is written once in the package (parksteer.names.TORQUE) and
every module reads the constant."""

from __future__ import annotations

import io
import tokenize
from pathlib import Path

from parksteer.names import TORQUE

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "parksteer"


def test_the_torque_column_is_named_once():
    """The fact checked: the string literal "handwheel_torque_Nm" occurs in no module of src/parksteer but
    names.py (prose in docstrings and messages is text, not a literal of its own, and is not counted)."""
    literals = {repr(TORQUE), f'"{TORQUE}"'}
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        if TORQUE not in text:
            continue
        found += [f"{path.relative_to(PACKAGE)}:{token.start[0]}" for token in
                  tokenize.generate_tokens(io.StringIO(text).readline)
                  if token.type == tokenize.STRING and token.string in literals]
    assert found == ["names.py:" + next(str(n) for n, line in enumerate(
        (PACKAGE / "names.py").read_text(encoding="utf-8").splitlines(), 1) if line.startswith("TORQUE ="))]
