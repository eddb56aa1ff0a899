"""The assisted replay's torsion-bar inversion in compiled C (``torsion_bar.c``), loaded once a process.

:meth:`parksteer.model.numeric.assisted.BoostLaw.torsion_bar` solves T + f A(T) = y for the torsion-bar torque at
every output sample of a replay, some ten evaluations of the boost law a sample; in C they cost a small part of the
replay. The C is compiled on its own once per model cache and compiler (``compiler.standalone_library``:
``runtime/torsion_bar-<key>.so``, keyed by its text, the flags and the compiler) on the first assisted replay of a
process, and loaded with ctypes once a process (:func:`entry_point`); nothing happens at import.
"""

from __future__ import annotations

import ctypes
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..codegen.cache import cache_root, writing_cache
from ..codegen.compiler import find_compiler, standalone_library

SOURCE = Path(__file__).resolve().with_name("torsion_bar.c")
# The law's values in the order the C reads them (its enum; its ps_torsion_bar_fields says the same, checked at load).
LAW_FIELDS = ("gain", "dead_band", "band_width", "line_scale", "table_scale", "limit", "limit_width", "area", "ratio",
              "efficiency", "reduction", "back_efficiency", "direction_width", "assist_scale")


# ps_torsion_bar's C signature: int (long n, const double *y, *factor, *direction, *values, int hydraulic, int points,
# const double *knots, *assist, *slope, double width, int width_known, double tolerance, int iterations, double *out)
_SIGNATURE = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_long, *[ctypes.c_void_p] * 4, ctypes.c_int, ctypes.c_int,
                              *[ctypes.c_void_p] * 3, ctypes.c_double, ctypes.c_int, ctypes.c_double, ctypes.c_int,
                              ctypes.c_void_p)


@lru_cache(maxsize=1)
def entry_point() -> int:
    """The address of the compiled inversion's ps_torsion_bar: its library built into the model cache if it is not
    there yet (a cache that cannot be written is one line, :func:`~parksteer.model.codegen.cache.writing_cache`)
    and loaded once a process (ctypes never unloads a library)."""
    compiler, root = find_compiler(), cache_root()
    with writing_cache(root):
        path = standalone_library(compiler, "torsion_bar", SOURCE.read_text(encoding="utf-8"),
                                  "the assisted replay's torsion-bar inversion", root)
    lib = ctypes.CDLL(str(path))
    names = ctypes.cast(ctypes.addressof(ctypes.c_char.in_dll(lib, "ps_torsion_bar_fields")), ctypes.c_char_p).value
    if tuple(names.decode().split(",")) != LAW_FIELDS:
        raise RuntimeError(f"{path}: the law's values in another order than torsion_bar.LAW_FIELDS")
    return ctypes.cast(lib.ps_torsion_bar, ctypes.c_void_p).value


def invert(values: np.ndarray, hydraulic: bool, points: np.ndarray | None, y: np.ndarray, factor: np.ndarray | None,
           direction: np.ndarray | None, width: float | None, tolerance: float, iterations: int) -> np.ndarray | None:
    """The torsion-bar torque T with T + factor A(T) = y at each sample (``ps_torsion_bar`` of torsion_bar.c): the
    law's `values` (:data:`LAW_FIELDS`), its table's `points` (torques, assists, slopes at its speed: a 3 x n array)
    or None, `y`, `factor` and `direction` (tanh(omega / w), None for a valve) as contiguous float arrays of one
    length (factor None: 1), the fallback bracket's half `width` (None: it could not be had). None if a sample needed
    that bracket and `width` is None."""
    out = np.empty_like(y)
    pointer = lambda a: None if a is None else a.ctypes.data  # noqa: E731
    knots, assist, slope = (None, None, None) if points is None else (points[0], points[1], points[2])
    function = _SIGNATURE(entry_point())
    status = function(y.size, y.ctypes.data, pointer(factor), pointer(direction), values.ctypes.data, int(hydraulic),
                      0 if points is None else points.shape[1], pointer(knots), pointer(assist), pointer(slope),
                      0.0 if width is None else width, int(width is not None), tolerance, iterations, out.ctypes.data)
    return None if status else out
