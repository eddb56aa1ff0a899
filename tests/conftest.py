"""Shared fixtures: the repository root and the shipped parameter file, loaded once."""

from __future__ import annotations

from pathlib import Path

import pytest

from parksteer.parameters import DEFAULT_PATH, Parameters, load_parameters

REPO_ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The repository checkout (holds Snakefile, workflow/, data/)."""
    return REPO_ROOT


@pytest.fixture(scope="session")
def params() -> Parameters:
    """The shipped data/parameters.toml, validated."""
    return load_parameters(DEFAULT_PATH)
