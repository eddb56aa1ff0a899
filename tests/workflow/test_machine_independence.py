"""The same bytes whatever arithmetic libraries the machine gives: the pipeline's outputs do not depend on the OpenBLAS
kernel, numpy's SIMD level or the thread count.

A scratch copy of the repository (with the worktree's compiled models where it has them; otherwise the first run
derives them, which does not touch the BLAS) rebuilds the outputs
that go through the simulation and the diagnosis: fig12 (the model), figContrib (the mechanisms' shares), bands
(the reconstructed inputs swept), diag_compare (synthetic car data, calibration and diagnosis) and the design
sweep's batches, once under each of three settings:
- OpenBLAS's SkylakeX kernel (AVX-512, no FMA in some kernels);
- its Sandybridge kernel (AVX, no FMA) with numpy's dispatch held to AVX2 and below;
- its Zen kernel with two BLAS threads and numpy without AVX2 or AVX-512.
Every figure file must match figures/SHA256SUMS, which were written under the machine's own default setting, and
the sweep batches must match across the three. Before the arithmetic was made portable (parksteer.portable and
model/codegen/portable_math.c) fig12 differed from row 1779 on under Haswell and Zen.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

from parksteer.checksums import read_sums

SNAKEMAKE = Path(sys.executable).with_name("snakemake")
TARGETS = ("fig12", "figContrib", "bands", "diag_compare")
FIGURE_FILES = tuple(f"figures/{name}.{ext}" for name in TARGETS for ext in ("svg", "csv"))
# The rules that compute: forced, so each setting recomputes every number (the derivations are cached models).
RULES = ("simulate_model", "model_figure", "bands", "diag_car_data", "diag_compare", "sweep_batch")
SETTINGS = {
    "SkylakeX": {"OPENBLAS_CORETYPE": "SkylakeX"},
    "Sandybridge, numpy to AVX2": {"OPENBLAS_CORETYPE": "Sandybridge", "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4"},
    "Zen, 2 threads, numpy to SSE4": {"OPENBLAS_CORETYPE": "Zen", "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2",
                                      "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4 X86_V3"},
}


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def copy(copy_with_models, tmp_path_factory) -> Path:
    return copy_with_models(tmp_path_factory.mktemp("machines"), need_models=False)


def _rebuild(work: Path, setting: dict[str, str]) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items()
           if k not in ("PARKSTEER_MODEL_CACHE", "OPENBLAS_CORETYPE", "NPY_DISABLE_CPU_FEATURES",
                        "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    env.update(setting, PYTHONPATH=str(work / "src"))
    done = subprocess.run([str(SNAKEMAKE), "--cores", "2", "--forcerun", *RULES, "--", *TARGETS, "sweep_design"],
                          cwd=work, env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    batches = sorted((work / "results" / "sweeps").rglob("batches/*.json"))
    assert batches, "the sweep wrote no batch"
    files = [*FIGURE_FILES, *(str(b.relative_to(work)) for b in batches)]
    return {name: _sha256(work / name) for name in files}


@pytest.mark.slow
def test_same_bytes_under_other_blas_kernels_simd_levels_and_thread_counts(copy):
    stored = read_sums(copy / "figures" / "SHA256SUMS")
    first = None
    for label, setting in SETTINGS.items():
        sums = _rebuild(copy, setting)
        changed = [name for name in FIGURE_FILES if sums[name] != stored[name]]
        assert not changed, f"under {label} these differ from figures/SHA256SUMS: {', '.join(changed)}"
        if first is None:
            first = sums
        assert sums == first, f"under {label} the sweep's batches differ from the first setting's"
