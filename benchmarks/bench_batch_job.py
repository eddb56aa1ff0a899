"""Benchmark (not a test): one hidden-effect benchmark job, its cases generated and diagnosed in one process as the
pipeline's diag_bench_batch runs them, in this tree and in reference trees, alternately; wall and CPU medians, their
ratios, and whether every tree's diagnoses are the same bits.

    python benchmarks/bench_batch_job.py [--reference [NAME=]SRC ...] [--repeats 3] [--job 0]

Each tree's ``src`` is put first on the path of a fresh interpreter, which runs
:func:`parksteer.experiments.benchmark.run_batch` on job ``--job`` of config/config.yaml's hidden-effect benchmark
(its cases dealt as the workflow deals them: ``case_batches`` in workflow/rules/common.smk) into a scratch folder,
and reports its wall time, its CPU time (user + system of the process; a benchmark job replays in line) and the
SHA-1 of its diagnoses' JSON with their ``cost`` (timings) left out. The first run of each tree is a warm-up (its
model cache filled, its bytecode compiled) and is not counted. A job is a diagnosis's whole cost many times over:
the replays in the compiled C and the Python around them (smoothing, linear algebra, bookkeeping), without the
process start a warm single diagnosis pays.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
JOB = r'''
import glob, hashlib, json, resource, sys, tempfile, time
import yaml
from parksteer import plan
from parksteer.experiments.benchmark import run_batch, run_case
from parksteer.synthetic.datasets import BenchmarkDesign
config = yaml.safe_load(open("config/config.yaml", encoding="utf-8"))
sections = {k: config[k] for k in ("car", "benchmark", "outclass", "variations", "signature")}
cases = plan.diagnosis(sections, config["parameters"], "src/parksteer/examples/column_imbalance.py")["bench_cases"]
count = -(-len(cases) // max(1, int(config["diagnosis_cases_per_job"])))
job = cases[int(sys.argv[1])::count]
out = tempfile.mkdtemp()
start = time.perf_counter()
run_batch(run_case, config["parameters"], BenchmarkDesign.from_config(config["benchmark"]), job, out)
wall = time.perf_counter() - start
usage = resource.getrusage(resource.RUSAGE_SELF)
digest = hashlib.sha1()
for path in sorted(glob.glob(out + "/*.diagnosis.json")):
    result = json.load(open(path, encoding="utf-8"))
    result.pop("cost", None)
    digest.update(json.dumps(result, sort_keys=True).encode())
print(json.dumps({"cases": len(job), "wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime,
                  "diagnoses_sha1": digest.hexdigest()}))
'''


def run(src: Path, job: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(src)}
    done = subprocess.run([sys.executable, "-c", JOB, str(job)], cwd=ROOT, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{src}: the job failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", action="append", default=[], help="[NAME=]SRC of another tree (repeatable)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--job", type=int, default=0)
    args = parser.parse_args()
    trees = {"this": ROOT / "src"}
    for ref in args.reference:
        name, _, src = ref.rpartition("=")
        trees[name or src] = Path(src).resolve()
    for name, src in trees.items():
        print(f"warm-up {name}", file=sys.stderr)
        run(src, args.job)
    runs: dict[str, list[dict]] = {name: [] for name in trees}
    for k in range(args.repeats):
        for name, src in trees.items():
            print(f"repeat {k + 1}/{args.repeats}: {name}", file=sys.stderr)
            runs[name].append(run(src, args.job))
    print("  ".join(f"{name}: {src}" for name, src in trees.items()))
    this = runs["this"]
    for name, done in runs.items():
        wall = statistics.median(r["wall_s"] for r in done)
        cpu = statistics.median(r["cpu_s"] for r in done)
        line = f"{name:12s} {done[0]['cases']} cases  wall {wall:7.2f} s  cpu {cpu:7.2f} s"
        if name != "this":
            line += (f"  this/{name}: wall {statistics.median(r['wall_s'] for r in this) / wall:.2f},"
                     f" cpu {statistics.median(r['cpu_s'] for r in this) / cpu:.2f}")
        same = {r["diagnoses_sha1"] for r in done} == {this[0]["diagnoses_sha1"]}
        print(f"{line}  diagnoses {'the same bits as this tree' if same else 'DIFFER'} ({done[0]['diagnoses_sha1'][:12]})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
