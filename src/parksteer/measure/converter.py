"""A logger's converter: its levels, its rounding, and the analog noise added before it.

Quantisation convention: the 2**bits levels (256 for 8 bits) run from -full_scale to
+full_scale inclusive, so the step is ``2 full_scale / (2**bits - 1)`` (2 full_scale / 255 for
8 bits). The levels are symmetric about zero and zero itself is not a level (it lies half a step
from the two middle levels). A value rounds to the nearest level; a value beyond full scale reads
as the end level, as a saturated converter does. For a signal that is busy on the scale of a
step, the rounding error is uniform over one step, with RMS ``step / sqrt(12)``.
"""

from __future__ import annotations

import numpy as np

from ..errors import UsageError

LITECORDER_BITS = 8  # Section 3: "digitized via an 8-bit ... converter"


def quantisation_step(full_scale: float, bits: int = LITECORDER_BITS) -> float:
    """Converter step: 2 full_scale / (2**bits - 1) (the levels include both ends of the range)."""
    if full_scale <= 0.0:
        raise UsageError(f"full scale must be positive, got {full_scale:g}")
    return 2.0 * full_scale / (2**bits - 1)


def quantise(values: np.ndarray, full_scale: float, bits: int = LITECORDER_BITS) -> np.ndarray:
    """Round `values` to the nearest of 2**bits levels spanning [-full_scale, +full_scale]; saturate beyond."""
    step = quantisation_step(full_scale, bits)
    level = np.clip(np.rint((np.asarray(values, dtype=float) + full_scale) / step), 0, 2**bits - 1)
    return -full_scale + level * step


def add_noise(values: np.ndarray, rms: float, rng: np.random.Generator) -> np.ndarray:
    """`values` plus white Gaussian noise of the given RMS."""
    if rms < 0.0:
        raise UsageError(f"noise RMS must not be negative, got {rms:g}")
    values = np.asarray(values, dtype=float)
    return values + rng.normal(0.0, rms, size=values.shape) if rms > 0.0 else values.copy()
