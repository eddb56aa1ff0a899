"""Determinism of the whole pipeline: three rebuilds from clean must give byte-identical figures, tables and PDF.

The repository's tracked and new files are copied to a scratch directory (bench_pipeline.scratch_copy: no
results/, no compiled model; the copy's package is the one its jobs import, through PYTHONPATH). Then, three times:
every output is deleted (results/, figures/*.svg, figures/*.csv, paper/*.pdf, .snakemake/), `snakemake --cores N
TARGET...` runs, and the SHA-256 of every figure, data file, key-number file (results/*.json) and the PDF is
recorded. With --keep-models the compiled models (results/model/<key>/) survive the cleaning, so only the first
rebuild derives them. It reports, as JSON, each rebuild's wall time and the files whose bytes differ between
rebuilds (none expected), and exits 1 if any does.

    python benchmarks/three_rebuilds.py results/three_rebuilds.json [--cores 2] [--keep-models] [TARGET ...]

With no target, the default target (every figure and the paper). Cold, on 2 cores, each rebuild takes as long as
the pipeline (bench_pipeline.py measures it); the suite's tests/workflow/test_faults.py checks two rebuilds of a
small target set instead.
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
from bench_pipeline import SNAKEMAKE, scratch_copy  # noqa: E402

REBUILDS = 3


def clean(work: Path, keep_models: bool) -> None:
    """Delete every output (and Snakemake's records); keep the compiled models' entries if asked."""
    shutil.rmtree(work / ".snakemake", ignore_errors=True)
    shutil.rmtree(work / "logs", ignore_errors=True)
    results = work / "results"
    if results.is_dir():
        for path in results.iterdir():
            if keep_models and path.name == "model":
                for item in path.iterdir():
                    if item.is_file():
                        item.unlink()  # the manifests, which record build timings
                continue
            shutil.rmtree(path) if path.is_dir() else path.unlink()
    for path in [*(work / "figures").glob("*.svg"), *(work / "figures").glob("*.csv"), *(work / "paper").glob("*.pdf")]:
        path.unlink()


def digests(work: Path) -> dict[str, str]:
    files = [*(work / "figures").glob("*.svg"), *(work / "figures").glob("*.csv"), *(work / "results").glob("*.json"),
             *(work / "paper").glob("*.pdf")]
    return {str(p.relative_to(work)): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(files)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--keep-models", action="store_true")
    parser.add_argument("targets", nargs="*")
    args = parser.parse_intermixed_args()  # the targets may follow the options, as the usage line shows them
    env = {k: v for k, v in os.environ.items() if k != "PARKSTEER_MODEL_CACHE"}
    with tempfile.TemporaryDirectory(prefix="parksteer-rebuilds-") as tmp:
        work = scratch_copy(Path(tmp))
        env["PYTHONPATH"] = str(work / "src")
        runs = []
        for _ in range(REBUILDS):
            clean(work, args.keep_models)
            start = time.perf_counter()
            done = subprocess.run([str(SNAKEMAKE), "--cores", str(args.cores), *args.targets], cwd=work, env=env,
                                  capture_output=True, text=True)
            wall = time.perf_counter() - start
            if done.returncode != 0:
                print((done.stdout + done.stderr)[-3000:], file=sys.stderr)
                return 2
            runs.append({"wall_s": round(wall, 1), "sha256": digests(work)})
    names = sorted(set().union(*(r["sha256"] for r in runs)))
    differing = [n for n in names if len({r["sha256"].get(n) for r in runs}) > 1]
    report = {"targets": args.targets or ["all"], "cores": args.cores, "keep_models": args.keep_models,
              "files": len(names), "wall_s": [r["wall_s"] for r in runs], "differing": differing}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    print(json.dumps(report, indent=2))
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())
