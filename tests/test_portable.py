"""parksteer.portable: arithmetic whose bits the code fixes, not the machine.

Checked here:
- each elementary function is within one ulp (tanh two, power a few) of the true value, measured against mpmath at
  50 digits, not against the C library it replaces;
- the C of model/codegen/portable_math.c, compiled as the model is (-ffp-contract=off), and the numpy mirror give
  the same bits on 10^5 arguments per function: the model's C and its Python side agree exactly;
- the linear algebra solves what it claims (exact solutions of constructed systems, orthogonality, the projection
  property of a generalised inverse) and the filters meet their closed-form responses (-3 dB at the cutoff, unit
  gain at DC, a steady state that stays steady);
- the same battery of results under other OpenBLAS kernels, numpy SIMD levels and thread counts has the same
  SHA-256: nothing here reaches a CPU-dispatched routine.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import subprocess
import sys
from pathlib import Path

import mpmath
import numpy as np
import pytest

import syntax_trees

from parksteer import portable as pm
from parksteer.checksums.platform_facts import kernel_runs_here
from parksteer.measure.bspline import DesignMatrix
from parksteer.model.codegen import generate
from parksteer.portable import elimination, linalg

C_SOURCE = Path(generate.__file__).with_name("portable_math.c")
UNARY = ("sin", "cos", "atan", "exp", "expm1", "tanh", "log")
# How far each may be from the true value, in units of the last place of the true value.
ULP_BOUND = {"sin": 1.0, "cos": 1.0, "atan": 1.0, "exp": 1.0, "expm1": 1.0, "tanh": 2.5, "log": 1.0}


def _arguments(name: str, rng: np.random.Generator, n: int) -> np.ndarray:
    spans = {"sin": [(-50.0, 50.0), (-1e-3, 1e-3), (-1e5, 1e5)], "cos": [(-50.0, 50.0), (-1e5, 1e5)],
             "atan": [(-5.0, 5.0), (-1e6, 1e6)], "exp": [(-700.0, 700.0), (-1.0, 1.0)],
             "expm1": [(-30.0, 30.0), (-1e-6, 1e-6)], "tanh": [(-25.0, 25.0), (-1e-3, 1e-3)],
             "log": [(1e-300, 1e-290), (0.5, 2.0), (0.999, 1.001), (1.0, 1e300)]}[name]
    return np.concatenate([rng.uniform(lo, hi, n // len(spans)) for lo, hi in spans])


@pytest.fixture(scope="module")
def c_library(tmp_path_factory):
    """portable_math.c with one vector wrapper per function, compiled with the model's flags."""
    from parksteer.model.codegen.cache import COMPILE_FLAGS

    folder = tmp_path_factory.mktemp("portable_c")
    wrappers = [f"void v_{f}(int n, const double *x, double *o) {{ for (int i = 0; i < n; i++) o[i] = ps_{f}(x[i]); }}"
                for f in UNARY]
    wrappers += ["void v_atan2(int n, const double *y, const double *x, double *o) "
                 "{ for (int i = 0; i < n; i++) o[i] = ps_atan2(y[i], x[i]); }",
                 "void v_pow(int n, const double *x, const double *y, double *o) "
                 "{ for (int i = 0; i < n; i++) o[i] = ps_pow(x[i], y[i]); }"]
    source = folder / "portable.c"
    source.write_text("#include <math.h>\n" + C_SOURCE.read_text() + "\n" + "\n".join(wrappers) + "\n")
    subprocess.run([os.environ.get("CC", "cc"), *COMPILE_FLAGS, "-o", str(folder / "portable.so"), str(source),
                    "-lm"], check=True)
    return ctypes.CDLL(str(folder / "portable.so"))


def _call(lib, name: str, *arrays: np.ndarray) -> np.ndarray:
    arrays = [np.ascontiguousarray(a, dtype=float) for a in arrays]
    out = np.empty(len(arrays[0]))
    pointer = ctypes.POINTER(ctypes.c_double)
    getattr(lib, f"v_{name}")(ctypes.c_int(len(out)), *[a.ctypes.data_as(pointer) for a in arrays],
                              out.ctypes.data_as(pointer))
    return out


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    both_nan = np.isnan(a) & np.isnan(b)
    return bool(np.all(both_nan | (a.view(np.int64) == b.view(np.int64))))


@pytest.mark.parametrize("name", UNARY)
def test_c_and_numpy_give_the_same_bits(c_library, name):
    """The compiled model and the Python side compute each function with the same operations in the same order."""
    x = _arguments(name, np.random.default_rng(7), 100_000)
    assert _same_bits(_call(c_library, name, x), getattr(pm, name)(x))


def test_c_and_numpy_atan2_and_power_give_the_same_bits(c_library):
    rng = np.random.default_rng(8)
    y, x = rng.uniform(-10, 10, 50_000), rng.uniform(-10, 10, 50_000)
    x[:100] = 0.0
    y[100:200] = 0.0
    assert _same_bits(_call(c_library, "atan2", y, x), pm.atan2(y, x))
    base = np.concatenate([rng.uniform(1e-3, 1e3, 25_000), rng.uniform(-3, 3, 25_000)])
    exponent = np.concatenate([rng.uniform(-3, 3, 25_000), rng.integers(-8, 9, 25_000).astype(float)])
    assert _same_bits(_call(c_library, "pow", base, exponent), pm.power(base, exponent))


@pytest.mark.parametrize("name", UNARY)
def test_within_an_ulp_of_the_true_value(name):
    """Against mpmath at 50 digits: the approximation error, independent of any C library."""
    x = _arguments(name, np.random.default_rng(11), 1200)
    got = getattr(pm, name)(x)
    mpmath.mp.dps = 50
    exact = getattr(mpmath, name)
    worst = 0.0
    for xi, gi in zip(x.tolist(), got.tolist()):
        true = exact(mpmath.mpf(xi))
        ulp = np.spacing(abs(float(true))) if float(true) != 0.0 else np.spacing(0.0)
        worst = max(worst, float(abs(mpmath.mpf(gi) - true)) / ulp)
    assert worst <= ULP_BOUND[name], f"{name}: {worst:.2f} ulp"


def test_power_and_atan2_close_to_the_true_value():
    mpmath.mp.dps = 50
    rng = np.random.default_rng(12)
    for b, e in zip(rng.uniform(0.1, 10.0, 300).tolist(), rng.uniform(-3.0, 3.0, 300).tolist()):
        true = mpmath.power(mpmath.mpf(b), mpmath.mpf(e))
        assert abs(pm.power(b, e) - float(true)) <= 8 * np.spacing(float(true))  # exp(y log x): |y log x| ulp
    for y, x in zip(rng.uniform(-5, 5, 300).tolist(), rng.uniform(-5, 5, 300).tolist()):
        true = mpmath.atan2(mpmath.mpf(y), mpmath.mpf(x))
        assert abs(pm.atan2(y, x) - float(true)) <= 1.5 * np.spacing(abs(float(true)))
    assert pm.power(-2.0, 3.0) == -8.0 and pm.power(2.0, -2.0) == 0.25 and pm.power(0.0, 2.5) == 0.0


def test_special_values():
    assert pm.sin(0.0) == 0.0 and pm.cos(0.0) == 1.0 and pm.exp(0.0) == 1.0 and pm.log(1.0) == 0.0
    assert pm.exp(800.0) == np.inf and pm.exp(-800.0) == 0.0 and pm.log(0.0) == -np.inf
    assert np.isnan(pm.log(-1.0)) and np.isnan(pm.sin(np.inf)) and np.isnan(pm.tanh(np.nan))
    assert pm.tanh(30.0) == 1.0 and pm.tanh(-30.0) == -1.0 and pm.atan2(0.0, -1.0) == np.pi
    assert isinstance(pm.sin(0.5), float) and pm.sin(np.array([0.5])).shape == (1,)


def test_linear_algebra_solves_what_it_claims():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(7, 7))
    x = rng.normal(size=7)
    assert np.allclose(pm.solve(a, a @ x), x, rtol=1e-12, atol=1e-12)
    assert np.allclose(pm.matmul(pm.inv(a), a), np.eye(7), atol=1e-12)
    spd = a @ a.T + 7 * np.eye(7)
    low = pm.cholesky(spd)
    assert np.allclose(low @ low.T, spd, rtol=1e-14) and np.allclose(low, np.tril(low))
    with pytest.raises(pm.LinAlgError):
        pm.cholesky(-spd)
    with pytest.raises(pm.LinAlgError):
        pm.solve(np.zeros((3, 3)), np.ones(3))
    tall = rng.normal(size=(40, 4))
    coefficients = np.array([1.0, -2.0, 0.5, 3.0])
    assert np.allclose(pm.lstsq(tall, tall @ coefficients), coefficients, rtol=1e-12)
    tall[:, 2] = 0.0  # an unknown nothing depends on stays at zero
    assert pm.lstsq(tall, tall @ coefficients)[2] == 0.0
    q, r = pm.qr(tall[:, [0, 1, 3]])
    assert np.allclose(q.T @ q, np.eye(3), atol=1e-14) and np.allclose(q @ r, tall[:, [0, 1, 3]], atol=1e-13)
    assert pm.dot([3.0, 4.0], [3.0, 4.0]) == 25.0 and pm.norm([3.0, 4.0]) == 5.0
    assert np.array_equal(pm.matmul(np.eye(3), [1.0, 2.0, 3.0]), [1.0, 2.0, 3.0])


def _banded_matrix(rng, n: int, below: int, above: int) -> np.ndarray:
    """Random entries (signs mixed, so partial pivoting swaps rows; a few exact zeros) within the band only."""
    a = rng.normal(size=(n, n)) * 10.0 ** rng.integers(-2, 3, size=(n, n))
    rows, columns = np.indices((n, n))
    a[(columns - rows > above) | (rows - columns > below)] = 0.0
    a[rng.random((n, n)) < 0.05] = 0.0
    return a


def test_banded_elimination_is_the_dense_one_to_the_bit():
    """Solving, inverting and factoring a banded matrix touch only the band, and give the dense algorithms' bits
    (the skipped operations subtract exact zeros from entries that are not -0.0): checked against the same
    elimination run over the whole matrix, on matrices whose pivoting swaps rows and widens the band, on the
    Gram matrices of cubic B-splines (three diagonals either side), and on an input with a -0.0 (dense only)."""
    def same_bits(a, b):
        return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))

    def dense_solve(a, b, identity=False):
        n = a.shape[0]
        return elimination._eliminate(a, b, n - 1, n - 1, identity)[0]

    rng = np.random.default_rng(11)
    swaps = 0
    for trial in range(60):
        n = int(rng.integers(5, 80))
        below, above = int(rng.integers(0, 4)), int(rng.integers(0, 4))
        a = _banded_matrix(rng, n, below, above)
        if trial % 10 == 0:
            a[rng.integers(n), rng.integers(n)] = -0.0
        swaps += int(np.argmax(np.abs(a[:below + 1, 0])) != 0)
        try:
            expected = dense_solve(a, np.eye(n), identity=True)
        except pm.LinAlgError:
            with pytest.raises(pm.LinAlgError):
                pm.inv(a)
            continue
        assert same_bits(pm.inv(a), expected)
        b = rng.normal(size=(n, 3))
        assert same_bits(pm.solve(a, b), dense_solve(a, b))
        assert same_bits(pm.solve(a, b[:, 0]), dense_solve(a, b[:, :1])[:, 0])
        low = np.tril(_banded_matrix(rng, n, below, 0))
        spd = pm.matmul(low, low.T) + np.diag(rng.uniform(0.1, 1.0, n))
        assert same_bits(pm.cholesky(spd), elimination._cholesky(spd, n - 1))
    assert swaps > 5  # the pivoting did swap rows

    t = np.sort(rng.uniform(0.0, 10.0, 2000))
    gram = DesignMatrix(t, np.concatenate([[0.0] * 4, np.linspace(0.2, 9.8, 60), [10.0] * 4])).gram()
    assert elimination._bandwidths(gram) == (3, 3)
    n = gram.shape[0]
    assert same_bits(pm.inv(gram), dense_solve(gram, np.eye(n), identity=True))
    assert same_bits(pm.cholesky(gram), elimination._cholesky(gram, n - 1))


def test_sums_in_python_floats_are_numpys_to_the_bit():
    """The small least squares in Python floats sums in numpy's orders: a vector's pairwise sum (one by one below 8
    terms, eight interleaved partial sums from 8 on) and a column's sum over the first axis (one row after another
    for several columns), signed zeros included, for every length up to 128."""
    rng = np.random.default_rng(12)
    for count in range(0, 129):
        for _ in range(20):
            terms = rng.normal(size=count) * 10.0 ** rng.integers(-12, 13, size=count)
            terms[rng.random(count) < 0.2] = rng.choice([0.0, -0.0])
            if rng.random() < 0.2:
                terms[:] = -0.0
            expected = np.add.reduce(terms)
            assert np.float64(linalg._pairwise_sum(terms.tolist())).view(np.int64) == expected.view(np.int64)
            down = np.add.reduce(np.stack([terms, terms[::-1]], axis=1), axis=0)[0]
            assert np.float64(linalg._sum_down(terms.tolist(), 2)).view(np.int64) == down.view(np.int64)
            single = np.add.reduce(terms[:, None], axis=0)[0]
            assert np.float64(linalg._sum_down(terms.tolist(), 1)).view(np.int64) == single.view(np.int64)


def test_least_squares_in_python_floats_is_the_numpy_one_to_the_bit(monkeypatch):
    """lstsq of a small system in Python floats gives the bits of the same algorithm in numpy calls (rank-deficient
    and -0.0 columns, one and several right-hand sides, up to 14 rows and 12 columns)."""
    rng = np.random.default_rng(13)
    cases = []
    for _ in range(300):
        m, n = int(rng.integers(1, 15)), int(rng.integers(1, 13))
        a = rng.normal(size=(m, n)) * 10.0 ** rng.integers(-6, 7, size=(m, n))
        a[rng.random((m, n)) < 0.15] = rng.choice([0.0, -0.0])
        if rng.random() < 0.2:
            a[:, rng.integers(n)] = 0.0
        b = rng.normal(size=m) if rng.random() < 0.5 else rng.normal(size=(m, int(rng.integers(1, 3))))
        cases.append((a, b))
    monkeypatch.setattr(linalg, "_FLOATS_AT_MOST", 10**6)
    in_floats = [pm.lstsq(a, b) for a, b in cases]
    monkeypatch.setattr(linalg, "_FLOATS_AT_MOST", 0)
    for (a, b), fast in zip(cases, in_floats):
        slow = pm.lstsq(a, b)
        assert fast.shape == slow.shape and np.array_equal(fast.view(np.int64), slow.view(np.int64))


def test_generalised_inverse_and_semidefinite_factor():
    rng = np.random.default_rng(4)
    rows = rng.normal(size=(3, 6))
    repeated = np.vstack([rows, rows[1]])  # a constraint stated twice
    m = repeated @ repeated.T
    g = pm.generalized_inverse(m)
    assert np.allclose(m @ g @ m, m, atol=1e-10)
    covariance = rows.T @ rows  # rank 3 of 6
    factor = pm.psd_factor(covariance)
    assert factor.shape == (6, 3) and np.allclose(factor @ factor.T, covariance, atol=1e-12)
    batch = np.stack([covariance + np.eye(6), 2 * covariance + 3 * np.eye(6)])
    assert np.allclose(np.einsum("wij,wjk->wik", pm.inv_spd_batched(batch), batch), np.eye(6), atol=1e-12)
    n = 50
    lower, diagonal, upper = rng.normal(size=n - 1), rng.normal(size=n), rng.normal(size=n - 1)
    dense = np.diag(diagonal) + np.diag(lower, -1) + np.diag(upper, 1)
    x = rng.normal(size=n)
    assert np.allclose(pm.solve_tridiagonal(lower, diagonal, upper, dense @ x), x, rtol=1e-9, atol=1e-9)


def test_symmetric_eigen_diagonalizes_with_orthonormal_vectors():
    """A V = V diag(w) with V^T V = I and w descending, the eigenvalues those of the characteristic polynomial
    (numpy's LAPACK as the reference); a known spectrum is recovered (Q diag(d) Q^T); a diagonal matrix is its
    own answer; a repeated eigenvalue still gives orthonormal vectors."""
    rng = np.random.default_rng(11)
    for n in (1, 2, 5, 12):
        x = rng.normal(size=(n, n))
        a = x + x.T
        w, v = pm.symmetric_eigen(a)
        assert np.all(np.diff(w) <= 0.0)
        assert np.allclose(a @ v, v * w, atol=1e-12 * np.abs(a).max())
        assert np.allclose(v.T @ v, np.eye(n), atol=1e-13)
        assert np.allclose(w, np.linalg.eigvalsh(a)[::-1], atol=1e-12 * np.abs(a).max())
    q, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    spectrum = np.array([7.0, 3.0, 3.0, 1.0, 0.0, -2.0])
    w, v = pm.symmetric_eigen(q @ np.diag(spectrum) @ q.T)
    assert np.allclose(w, spectrum, atol=1e-12) and np.allclose(v.T @ v, np.eye(6), atol=1e-13)
    w, v = pm.symmetric_eigen(np.diag([1.0, 4.0, 2.0]))
    assert np.array_equal(w, [4.0, 2.0, 1.0]) and np.array_equal(np.abs(v), np.eye(3)[:, [1, 2, 0]])


@pytest.mark.parametrize("order", [1, 2, 3, 4])
def test_butterworth_response(order):
    """|H| = 1 at DC and 1/sqrt(2) at the cutoff (the -3 dB point), monotonic between: Butterworth's definition."""
    rate, cutoff = 1000.0, 40.0
    sos = pm.butterworth_lowpass_sos(order, cutoff, rate)

    def gain(f):
        z = np.exp(-1j * 2 * np.pi * f / rate)
        h = 1.0
        for b0, b1, b2, _a0, a1, a2 in sos:
            h *= (b0 + b1 * z + b2 * z * z) / (1.0 + a1 * z + a2 * z * z)
        return abs(h)

    assert gain(0.0) == pytest.approx(1.0, abs=1e-12)
    assert gain(cutoff) == pytest.approx(2 ** -0.5, abs=1e-12)
    assert gain(4 * cutoff) < gain(2 * cutoff) < gain(cutoff)


def test_steady_state_stays_steady():
    from scipy.signal import sosfilt

    sos = pm.butterworth_lowpass_sos(3, 25.0, 500.0)
    out, _ = sosfilt(sos, np.full(200, 2.5), zi=pm.sos_steady_state(sos) * 2.5)
    assert np.allclose(out, 2.5, rtol=1e-13)


def test_fir_low_pass_is_linear_phase_with_unit_dc_gain():
    h = pm.hamming_lowpass_fir(61, 1.0 / 3.0)
    assert np.sum(h) == pytest.approx(1.0, abs=1e-15)
    assert np.allclose(h, h[::-1], rtol=0.0, atol=1e-15 * np.max(np.abs(h)))  # symmetric to rounding: linear phase


@pytest.mark.parametrize("padtype", ["constant", "antireflect"])
@pytest.mark.parametrize("factor", [2, 3, 5, 10])
def test_fir_decimation_is_scipys_resample_poly_to_the_bit(factor, padtype):
    """The record importer's anti-alias decimation, written out so that a diagnosis need not import scipy.signal,
    gives scipy.signal.resample_poly's bits (same taps, same zero-phase delay, same padding beyond the ends: zeros,
    or the record reflected through its end sample, same order of sums), at lengths that are and are not multiples
    of the factor, on a walk away from 0 at both ends (where the two paddings differ)."""
    from scipy.signal import resample_poly

    rng = np.random.default_rng(factor)
    fir = pm.hamming_lowpass_fir(20 * factor + 1, 1.0 / factor)
    for n in (40 * factor, 40 * factor + 1, 4999):
        x = 3.0 + np.cumsum(rng.normal(size=n)) * 1e-3
        assert np.array_equal(pm.fir_decimate(x, fir, factor, padtype),
                              resample_poly(x, 1, factor, window=fir, padtype=padtype))


def test_fir_decimation_reflected_through_its_ends_passes_a_line_unchanged():
    """A zero-phase filter of unit gain passes a straight line unchanged, and the record reflected through its end
    sample continues the line beyond each end: every decimated sample of a ramp is the ramp's, the first and last
    included (zeros beyond the ends would pull them toward 0)."""
    x = 2.0 + 0.01 * np.arange(401)
    fir = pm.hamming_lowpass_fir(41, 0.5)
    assert np.allclose(pm.fir_decimate(x, fir, 2, "antireflect"), x[::2], rtol=0.0, atol=1e-12)
    assert abs(pm.fir_decimate(x, fir, 2)[-1] - x[-1]) > 1.0


def test_running_filters_are_scipy_ndimages_to_the_bit():
    """The running median and the three-sample maximum are selections, so the numpy forms must give
    scipy.ndimage's median_filter and maximum_filter1d (mode "nearest") exactly, ties and ends included."""
    from scipy.ndimage import maximum_filter1d, median_filter

    rng = np.random.default_rng(3)
    for n in (1, 2, 7, 1000, 70001):
        x = np.round(rng.normal(size=n), 1)  # rounded: many ties
        for size in (1, 3, 21):
            assert np.array_equal(pm.running_median(x, size), median_filter(x, size=size, mode="nearest"))
        assert np.array_equal(pm.running_max3(x), maximum_filter1d(x, size=3, mode="nearest"))


BATTERY = r"""
import hashlib, numpy as np
from parksteer import portable as pm
rng = np.random.default_rng(5)
x = rng.uniform(-20.0, 20.0, 20000)
a = rng.normal(size=(300, 9))
parts = [pm.sin(x), pm.cos(x), pm.atan(x), pm.exp(x), pm.tanh(x), pm.log(np.abs(x)), pm.power(np.abs(x), 1.7),
         pm.matmul(a.T, a), pm.solve(pm.matmul(a.T, a), pm.matmul(a.T, x[:300])), pm.lstsq(a, x[:300]),
         pm.qr(a)[0], pm.inv(pm.matmul(a.T, a)), pm.norm(a, axis=0), *pm.symmetric_eigen(pm.matmul(a.T, a)),
         pm.butterworth_lowpass_sos(4, 30.0, 1000.0), pm.hamming_lowpass_fir(41, 0.2),
         pm.fir_decimate(x, pm.hamming_lowpass_fir(101, 0.2), 5), pm.running_median(x, 21), pm.running_max3(x)]
print(hashlib.sha256(b"".join(np.ascontiguousarray(p).tobytes() for p in parts)).hexdigest())
"""
# OpenBLAS kernels of three generations, numpy without AVX-512 and without AVX2, and two threads. The widest
# kernel is SkylakeX (AVX-512) where the CPU has AVX-512, else Nehalem (SSE4.2): SkylakeX's code would die of SIGILL.
SETTINGS = [
    {"OPENBLAS_CORETYPE": "SkylakeX" if kernel_runs_here("SkylakeX") else "Nehalem"},
    {"OPENBLAS_CORETYPE": "Haswell", "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4"},
    {"OPENBLAS_CORETYPE": "Sandybridge", "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4 X86_V3"},
    {"OPENBLAS_CORETYPE": "Zen", "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"},
]


def test_same_bits_under_every_kernel_simd_level_and_thread_count():
    digests = set()
    for setting in SETTINGS:
        env = {**os.environ, **setting}
        out = subprocess.run([sys.executable, "-c", BATTERY], env=env, capture_output=True, text=True, check=True)
        digests.add(out.stdout.strip())
    assert len(digests) == 1, digests


def test_generated_c_calls_no_machine_dependent_libm():
    """The model's C takes its elementary functions from portable_math.c: any libm one is refused."""
    generate.check_portable("double f(double x) { return ps_sin(x) + sqrt(x) + fabs(x); }")
    for call in ("sin(x)", "pow(x, 2.5)", "tanh(x)", "exp(x)"):
        with pytest.raises(RuntimeError, match="C library"):
            generate.check_portable(f"double f(double x) {{ return {call}; }}")


def test_no_module_outside_portable_calls_blas_or_lapack():
    """Every number the package computes stays off the CPU-dispatched BLAS and LAPACK: outside ``portable/``, no
    ``@`` operator, no ``np.linalg`` routine (its ``LinAlgError`` aside) and no ``np.dot``/``np.matmul``/``np.einsum``
    (which go through the BLAS for floats), so that a figure's bytes do not depend on the machine's kernel."""
    import ast

    found = []
    for where, node in _nodes_outside_portable():
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.MatMult):
            found.append(f"{where}:{node.lineno}: @")
        elif (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Attribute)
              and node.value.attr == "linalg" and node.attr != "LinAlgError"):
            found.append(f"{where}:{node.lineno}: linalg.{node.attr}")
        elif (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "np"
              and node.attr in ("dot", "matmul", "einsum", "tensordot", "inner", "vdot")):
            found.append(f"{where}:{node.lineno}: np.{node.attr}")
    assert not found, "BLAS/LAPACK outside parksteer.portable: " + "; ".join(found)


def _nodes_outside_portable():
    """(the module's path in the package, node) for every syntax node of every module outside ``portable/``."""
    root = Path(pm.__file__).parents[1]
    for path in sorted(root.rglob("*.py")):
        where = path.relative_to(root).as_posix()
        if where.startswith("portable/"):
            continue
        for node in syntax_trees.nodes(path.read_text(encoding="utf-8")):
            yield where, node


# numpy's and the math module's elementary functions: numpy's dispatch on the CPU's SIMD level, and the C library's
# (behind math, and numpy's where it has no SIMD loop) pick FMA or SSE2 variants by processor; either differs from
# the other in the last bit.
ELEMENTARY = {"sin", "cos", "tan", "arcsin", "arccos", "arctan", "arctan2", "asin", "acos", "atan", "atan2", "sinh",
              "cosh", "tanh", "arcsinh", "arccosh", "arctanh", "exp", "exp2", "expm1", "log", "log2", "log10", "log1p",
              "power", "float_power", "pow", "cbrt", "erf", "erfc", "gamma", "lgamma"}
# The calls whose last bit reaches no number the package writes, each with its reason.
ELEMENTARY_ALLOWED = {
    # a logarithmic axis's positions in a figure (its data are written as computed)
    ("figures/assisted.py", "log10"),
    # a converter's bit count, rounded to a whole number
    ("synthetic/quirk_eps.py", "log2"), ("synthetic/column_eps_layer.py", "log2"),
}


def test_no_module_outside_portable_calls_numpys_or_the_c_librarys_elementary_functions():
    """Every number the package computes through sin, exp, tanh, log, ... takes them from parksteer.portable (fdlibm's
    algorithms, the model's C's own): outside ``portable/``, no ``np.<f>`` or ``math.<f>`` of :data:`ELEMENTARY`
    but the listed few, so that a figure's bytes do not depend on the processor's SIMD level or FMA (CI's
    .ci/other_kernels runs figures again under both held back)."""
    import ast

    found = [f"{where}:{node.lineno}: {node.value.id}.{node.attr}" for where, node in _nodes_outside_portable()
             if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
             and node.value.id in ("np", "numpy", "math") and node.attr in ELEMENTARY
             and (where, node.attr) not in ELEMENTARY_ALLOWED]
    assert not found, "elementary functions outside parksteer.portable: " + "; ".join(found)
