"""Design exploration: sweeps of the steering model over design parameters.

- :mod:`.declaration`: the YAML declaration, its validation and its expansion into points (:class:`Sweep`);
- :mod:`.fields`, :mod:`.keys`, :mod:`.model_check`: the readers of its fields, its keys' bounds, the check
  that its points make a consistent model;
- :mod:`.expansion`, :mod:`.batch_index`: point ids, batches, and the index a batch job reads its points from;
- :mod:`.design`: a point's values as `simulate` overrides (design variables kept consistent);
- :mod:`.merit`: figures of merit of one cycle (peak, plateau, lock, reversal drop, shares);
- :mod:`.run`: one point job (never derives the model);
- :mod:`.records`, :mod:`.totals`, :mod:`.gathering`: the points' records, what is counted over all of them,
  and the table of all points written streamed;
- :mod:`.aggregate`: the summary a study quotes.

Only the declaration and its readers are imported here, so that reading a sweep (as the Snakefile does at
every start) does not import the model or sympy.
"""

from .declaration import Sweep, SweepPoint, load_sweep
from .design import SweepError
from .fields import AssistanceThreshold, MapSpec
from .keys import DESIGN_VARIABLES

__all__ = ["DESIGN_VARIABLES", "AssistanceThreshold", "MapSpec", "Sweep", "SweepError", "SweepPoint", "load_sweep"]
