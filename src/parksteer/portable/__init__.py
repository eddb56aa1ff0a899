"""Arithmetic whose every bit is fixed by this code, not by the machine it runs on.

numpy hands matrix products and ``numpy.linalg`` to the BLAS it was built with, whose kernel, fused multiply-adds
and thread count change the last bit, and its transcendental functions dispatch on the SIMD level; an adaptive
integrator or an iterative fit turns that bit into a visible difference in a figure. What is here uses only what
IEEE 754 fixes exactly (elementwise +, -, *, /, sqrt, floor, frexp, ldexp, and ``np.sum``, whose pairwise order
depends on the shape alone), so the same inputs give the same bits on any machine:

- linear algebra for systems of up to a few hundred unknowns: :func:`dot`, :func:`matmul`, :func:`norm`,
  :func:`solve`, :func:`inv`, :func:`cholesky`, :func:`lstsq`, :func:`qr` (LAPACK's algorithms written out),
  :func:`symmetric_eigen` (cyclic Jacobi);
- elementary functions :func:`sin`, :func:`cos`, :func:`tan`, :func:`atan`, :func:`atan2`, :func:`exp`,
  :func:`expm1`, :func:`tanh`, :func:`log`, :func:`power`, :func:`hypot`: fdlibm's algorithms, mirroring the C of
  ``model/codegen/portable_math.c`` to the bit (``tests/test_portable.py``), each within about one ulp;
- Student's t quantile and the chi-square survival for whole degrees of freedom, in closed form:
  :func:`student_t_quantile`, :func:`chi2_survival` (no scipy.special, whose import costs half a second);
- the filters the loggers and the import use, designed in closed form: :func:`butterworth_lowpass_sos`,
  :func:`sos_steady_state`, :func:`hamming_lowpass_fir`.

Scalars in give Python floats out; arrays give arrays. Why and what was verified: docs/reproducibility.md.
"""

# The package is the one import path of all of it (`from parksteer import portable as pm`, then pm.solve, pm.sin,
# ...: a drop-in where numpy's own would leave the last bit to the machine); each job is a module of its own.
from .distributions import chi2_survival, student_t_quantile
from .elementary import atan, atan2, cos, exp, expm1, hypot, log, power, sin, tan, tanh
from .filters import (
    butterworth_lowpass_sos,
    fir_decimate,
    hamming_lowpass_fir,
    running_max3,
    running_median,
    sos_steady_state,
)
from .elimination import cholesky, inv, solve
from .linalg import (
    LinAlgError,
    dot,
    generalized_inverse,
    inv_spd_batched,
    lstsq,
    matmul,
    norm,
    psd_factor,
    qr,
    solve_tridiagonal,
    symmetric_eigen,
)

__all__ = ["LinAlgError", "dot", "matmul", "norm", "solve", "inv", "cholesky", "lstsq", "qr", "inv_spd_batched",
           "generalized_inverse", "psd_factor", "solve_tridiagonal", "symmetric_eigen",
           "sin", "cos", "tan", "atan", "atan2", "exp", "expm1", "tanh", "log", "power", "hypot",
           "butterworth_lowpass_sos", "sos_steady_state", "hamming_lowpass_fir", "fir_decimate",
           "running_median", "running_max3", "student_t_quantile", "chi2_survival"]
