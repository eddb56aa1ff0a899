"""Design exploration: sweeps of the steering model over design parameters.

- :mod:`.declaration`: the YAML declaration, its validation and its expansion into points;
- :mod:`.design`: a point's values as `simulate` overrides (design variables kept consistent);
- :mod:`.merit`: figures of merit of one cycle (peak, plateau, lock, reversal drop, shares);
- :mod:`.run`: one point job (never derives the model);
- :mod:`.aggregate`: the table of all points and the summary a study quotes.

Only the declaration is imported here, so that reading a sweep (as the Snakefile does at
every start) does not import the model or sympy.
"""

from .declaration import (
    DESIGN_VARIABLES,
    AssistanceThreshold,
    MapSpec,
    Sweep,
    SweepError,
    SweepPoint,
    load_sweep,
)

__all__ = ["DESIGN_VARIABLES", "AssistanceThreshold", "MapSpec", "Sweep", "SweepError", "SweepPoint", "load_sweep"]
