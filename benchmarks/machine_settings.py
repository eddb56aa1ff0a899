"""The whole pipeline under other arithmetic settings of this machine: the same bytes under each?

For each setting (an OpenBLAS kernel, the SIMD level numpy may use, a BLAS thread count) the repository's tracked
and new files are copied to a scratch directory (bench_pipeline.scratch_copy; with --keep-models the worktree's
compiled models are copied in, since a derivation does not touch the BLAS), `snakemake --cores N` builds every
figure and the paper under that setting's environment, and `snakemake --cores N verify_strict` checks the 35 files
against figures/SHA256SUMS. Each setting's key-number files (results/*.json) and PDF are compared with the first
setting's. It reports, as JSON, per setting: the wall time, verify_strict's summary line, and the files that differ
from the first setting (none expected); it exits 1 if verify_strict fails or any file differs.

    python benchmarks/machine_settings.py results/machine_settings.json [--cores 2] [--keep-models] [--only NAME ...]

On 2 cores a setting takes as long as the pipeline (about 2.5 min with the models kept). On a CPU without AVX-512
the settings of OpenBLAS's AVX-512 kernels (SkylakeX, Cooperlake) are skipped, and said so. docs/reproducibility.md
records a run; CI's .ci/other_kernels checks a part of the pipeline under three settings in every CI run.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_pipeline import REPO, SNAKEMAKE, scratch_copy  # noqa: E402

from parksteer.checksums.platform_facts import kernel_runs_here  # noqa: E402

# The machine's own setting first: the others' key numbers and PDF are compared with its.
SETTINGS = {
    "default": {},
    "skylakex_avx2_2threads": {"OPENBLAS_CORETYPE": "SkylakeX", "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4",
                               "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"},
    "nehalem_sse4_1thread": {"OPENBLAS_CORETYPE": "Nehalem", "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4 X86_V3",
                             "OPENBLAS_NUM_THREADS": "1"},
    "sandybridge_avx2_2threads": {"OPENBLAS_CORETYPE": "Sandybridge", "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4",
                                  "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"},
    "haswell_2threads": {"OPENBLAS_CORETYPE": "Haswell", "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"},
    "cooperlake_sse4_1thread": {"OPENBLAS_CORETYPE": "Cooperlake",
                                "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4 X86_V3", "OPENBLAS_NUM_THREADS": "1"},
    "zen_2threads": {"OPENBLAS_CORETYPE": "Zen", "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"},
}
# The variables a setting sets: cleared from the calling environment first, so that each setting is only itself.
VARIABLES = ("OPENBLAS_CORETYPE", "NPY_DISABLE_CPU_FEATURES", "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
             "PARKSTEER_MODEL_CACHE")


def _digests(work: Path) -> dict[str, str]:
    files = [*(work / "results").glob("*.json"), *(work / "paper").glob("*.pdf")]
    return {str(p.relative_to(work)): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(files)}


def run_setting(name: str, setting: dict[str, str], cores: int, keep_models: bool, scratch: Path) -> dict:
    work = scratch_copy(scratch / name)
    if keep_models:
        for entry in (REPO / "results" / "model").glob("*/"):
            if not entry.name.startswith("."):
                shutil.copytree(entry, work / "results" / "model" / entry.name)
    env = {k: v for k, v in os.environ.items() if k not in VARIABLES}
    env.update(setting, PYTHONPATH=str(work / "src"), PATH=f"{Path(sys.executable).parent}{os.pathsep}{env['PATH']}")
    start = time.perf_counter()
    for target in ([], ["verify_strict"]):
        done = subprocess.run([str(SNAKEMAKE), "--cores", str(cores), *target], cwd=work, env=env,
                              capture_output=True, text=True)
        if done.returncode:
            break
    report = work / "results" / "checksums_verified_strict.txt"
    summary = report.read_text(encoding="utf-8").splitlines()[-1] if report.exists() else done.stderr[-2000:]
    return {"setting": setting, "wall_s": round(time.perf_counter() - start, 1), "passed": done.returncode == 0,
            "verify_strict": summary, "digests": _digests(work)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--keep-models", action="store_true", help="copy the worktree's compiled models in")
    parser.add_argument("--only", nargs="+", choices=list(SETTINGS), help="these settings only (default first)")
    args = parser.parse_args()
    names = ["default", *[n for n in (args.only or SETTINGS) if n != "default"]]
    skipped = [n for n in names if not kernel_runs_here(SETTINGS[n].get("OPENBLAS_CORETYPE", ""))]
    if skipped:
        print(f"skipped, this CPU has no AVX-512: {', '.join(skipped)}", flush=True)
    names = [n for n in names if n not in skipped]
    results = {}
    with tempfile.TemporaryDirectory(prefix="parksteer-settings-") as scratch:
        for name in names:
            results[name] = run_setting(name, SETTINGS[name], args.cores, args.keep_models, Path(scratch))
            first = results["default"]["digests"]
            results[name]["differs_from_default"] = sorted(k for k, v in results[name]["digests"].items()
                                                           if first.get(k) != v)
            print(f"{name}: {results[name]['wall_s']} s; {results[name]['verify_strict']}; "
                  f"{len(results[name]['differs_from_default'])} key-number or PDF files differ", flush=True)
    for entry in results.values():
        del entry["digests"]
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=1) + "\n", encoding="utf-8")
    bad = [n for n, r in results.items() if not r["passed"] or r["differs_from_default"]]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
