"""Shared simulations of the multibody model, run once per test session.

The compiled models live in the on-disk cache (derived once per effect set and model
source), so only the first session after a change of the model pays for a derivation.
"""

from __future__ import annotations

import pytest

from parksteer.model.numeric.simulate import simulate


@pytest.fixture(scope="session")
def nominal(params):
    """The paper's cycle, unladen car, all five effects, on the ground."""
    return simulate("unladen", params=params)


@pytest.fixture(scope="session")
def part_laden(params):
    return simulate("part_laden", params=params)
