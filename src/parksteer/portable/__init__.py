"""Arithmetic whose every bit is fixed by this code, not by the machine it runs on.

numpy hands matrix products, ``dot``, ``norm`` and everything in ``numpy.linalg`` to the BLAS and LAPACK it was
built with (OpenBLAS), which picks a kernel for the CPU at load time: a Haswell kernel sums in another order, and
fuses multiply-adds, where a SkylakeX or Sandybridge kernel does not, and the thread count splits sums differently
again. Its transcendental functions (``np.sin``, ``np.exp``, ``np.tanh``, ...) dispatch on the SIMD level (AVX-512
and AVX2 have their own implementations). Each gives the last bit to the machine; an adaptive integrator or an
iterative fit then turns that bit into a visible difference in a figure.

What is here uses only what IEEE 754 fixes exactly: elementwise +, -, *, /, sqrt, floor, frexp and ldexp, and
``np.sum``, whose pairwise order depends on the array's shape alone. So the same inputs give the same bits on any
machine, with any BLAS kernel, SIMD level or thread count.

- Linear algebra for the small systems of the model and the diagnosis (up to a few hundred unknowns):
  :func:`dot`, :func:`matmul`, :func:`norm`, :func:`solve`, :func:`inv`, :func:`cholesky`, :func:`lstsq`,
  :func:`qr`. Sums run in a fixed order; solves are Gaussian elimination with partial pivoting and Householder
  QR with column pivoting, the algorithms LAPACK uses, written out.
- Elementary functions :func:`sin`, :func:`cos`, :func:`tan`, :func:`atan`, :func:`atan2`, :func:`exp`,
  :func:`expm1`, :func:`tanh`, :func:`log`, :func:`power`, :func:`hypot`: fdlibm's algorithms, mirroring operation
  for operation the C in ``model/codegen/portable_math.c`` that the compiled model uses, so the model's C and its
  Python side agree to the bit (``tests/test_portable.py``). Each is within about one ulp of the true value.
- The few filters the loggers and the import use, designed in closed form: :func:`butterworth_lowpass_sos`,
  :func:`sos_steady_state`, :func:`hamming_lowpass_fir` (scipy designs them through numpy's polynomial and
  linear-algebra routines, which call the BLAS).

Scalars in give Python floats out; arrays give arrays.
"""

# The package is the one import path of all of it (`from parksteer import portable as pm`, then pm.solve, pm.sin,
# ...: a drop-in where numpy's own would leave the last bit to the machine); each job is a module of its own.
from .elementary import atan, atan2, cos, exp, expm1, hypot, log, power, sin, tan, tanh
from .filters import (
    butterworth_lowpass_sos,
    fir_decimate,
    hamming_lowpass_fir,
    running_max3,
    running_median,
    sos_steady_state,
)
from .linalg import (
    LinAlgError,
    cholesky,
    dot,
    generalized_inverse,
    inv,
    inv_spd_batched,
    lstsq,
    matmul,
    norm,
    psd_factor,
    qr,
    solve,
    solve_tridiagonal,
)

__all__ = ["LinAlgError", "dot", "matmul", "norm", "solve", "inv", "cholesky", "lstsq", "qr", "inv_spd_batched",
           "generalized_inverse", "psd_factor", "solve_tridiagonal",
           "sin", "cos", "tan", "atan", "atan2", "exp", "expm1", "tanh", "log", "power", "hypot",
           "butterworth_lowpass_sos", "sos_steady_state", "hamming_lowpass_fir", "fir_decimate",
           "running_median", "running_max3"]
