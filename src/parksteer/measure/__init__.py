"""Measurements of handwheel torque against rack displacement: the file format and what is read from a file.

- :mod:`.io`: read, validate and write measurement files (format: data/measurements/README.md);
- :mod:`.importers`: the one way in for every measurement, rack drive or angle record (logger exports mapped to the
  format), a thin dispatcher over the readers, running the channel map (:mod:`.channel_map`), the units'
  conversion (:mod:`.units`) and the plausibility checks against the car (:mod:`.plausibility`);
- :mod:`.readers`: one reader per file format (native CSV, logger CSV, ASAM MDF) in a table, ``READERS``;
- :mod:`.phases`: split a steering cycle into initial rise, wind-up, plateau, reversal, return;
- :mod:`.smoothing`: a measured rack as a motion the model can follow (least-squares spline);
- :mod:`.metrics`: residual statistics of a model against a measurement, per phase, beside the
  noise floor the data allow.

This package imports neither the model nor :mod:`parksteer.synthetic` (the import contract in pyproject.toml
checks it): synthetic measurements (logger, hand, stand-ins, data sets) live in :mod:`parksteer.synthetic`.
"""

from .io import Measurement, read_measurement, write_measurement

__all__ = ["Measurement", "read_measurement", "write_measurement"]
