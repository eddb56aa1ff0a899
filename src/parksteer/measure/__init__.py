"""Measurements of handwheel torque against rack displacement, and their comparison with the model.

- :mod:`.io`: read, validate and write measurement files (format: data/measurements/README.md);
- :mod:`.degrade`: turn a clean model output into a realistic measurement (8-bit logger,
  analog noise, sampling, an irregular hand);
- :mod:`.phases`: split a steering cycle into initial rise, wind-up, plateau, reversal, return;
- :mod:`.metrics`: residual statistics of a model against a measurement, per phase, beside the
  noise floor the data allow;
- :mod:`.standin`: a closed-form quasi-static cycle (not the model) for fast, independent tests;
- :mod:`.example`: the synthetic example file data/measurements/example_unladen.csv.
"""

from .io import Measurement, read_measurement, write_measurement

__all__ = ["Measurement", "read_measurement", "write_measurement"]
