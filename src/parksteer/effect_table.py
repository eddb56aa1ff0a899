"""The table of every effect and its quantities that the article lists its chosen values from (rule ``effects``).

An effect's own quantities are declared in its file, not in the parameter file, so the article, which reads files
only, reads them from ``results/effects.json``. A module of its own, so that the article's rule does not depend on
the model's code.
"""

from __future__ import annotations

from pathlib import Path


def write_effect_quantities(parameters_path: str | Path, json_path: str | Path) -> None:
    """Every effect the registry finds with its own quantities' values and sources (``parksteer effects --json``),
    for the article's table of chosen values: an effect's quantities are declared in its file, not the parameter
    file."""
    from .model.symbolic.components import discover_effects
    from .parameters import load_parameters
    from .tables import write_json

    params = load_parameters(parameters_path)
    write_json(json_path, [effect.describe(params) for effect in discover_effects().values()])
