"""The pipeline's DAG run cold in a scratch copy, and where its time goes, from Snakemake's `benchmark:` files.

The repository's tracked and new files (git ls-files) are copied to a scratch directory, so that nothing is built
there yet: no results/, no compiled model (the copy's package is the one its jobs import, through PYTHONPATH, and
its model cache is the copy's results/model), and the copy's package bytecode is compiled (`python -m compileall`,
as the README's quick start does; `--no-bytecode` leaves it out, so that every job compiles the modules it imports
where PYTHONDONTWRITEBYTECODE is set). Then `snakemake --cores N TARGET...` runs once, timed, and every
rule's benchmark file (results/benchmarks/<rule>/*.tsv: wall seconds `s` and `cpu_time` of each job) is read.
It reports the run's wall time, and per rule the number of jobs and the sum of their wall and CPU seconds; the
top five rules by summed wall time are printed. The sum over jobs exceeds the run's wall time when jobs ran in
parallel. It also reports the critical path: the chain of jobs through the DAG (`snakemake --dag`) whose wall
times add up to the most, which no number of cores shortens, and the lower bound of the run's wall time on N
cores, the larger of that path and the jobs' summed wall time over N.

    python benchmarks/bench_pipeline.py results/bench_pipeline.json [--cores 2] [--keep DIR] [--no-bytecode] [TARGET ...]

With no target, the default target (every figure and the paper). A rule without a `benchmark:` directive does not
appear; the report names the rules of the run that wrote no benchmark file (the aggregate rule `all` has none).
"""

from __future__ import annotations

import argparse
import compileall
import csv
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).with_name("snakemake")
TOP = 5


def scratch_copy(dest: Path, bytecode: bool = False) -> Path:
    """The repository's tracked and untracked, not ignored, files copied to dest (no results, no model cache); with
    `bytecode`, the copy's package compiled (compileall), as the README's quick start compiles a checkout's."""
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=REPO,
                            capture_output=True, text=True, check=True).stdout.split("\0")
    for name in filter(None, listed):
        source = REPO / name
        if source.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, dest / name)
    if bytecode and not compileall.compile_dir(dest / "src", quiet=1):
        raise RuntimeError(f"compileall failed on {dest / 'src'}")
    return dest


def read_benchmarks(work: Path) -> dict[str, dict]:
    """Rule -> {jobs, wall_s, cpu_s, max_wall_s} from results/benchmarks/<rule>/*.tsv."""
    rules: dict[str, dict] = {}
    for path in sorted((work / "results" / "benchmarks").glob("*/*.tsv")):
        with path.open(encoding="utf-8") as f:
            rows = list(csv.DictReader(f, delimiter="\t"))
        entry = rules.setdefault(path.parent.name, {"jobs": 0, "wall_s": 0.0, "cpu_s": 0.0, "max_wall_s": 0.0})
        for row in rows:
            wall = float(row["s"])
            entry["jobs"] += 1
            entry["wall_s"] += wall
            entry["cpu_s"] += float(row.get("cpu_time") or 0.0)
            entry["max_wall_s"] = max(entry["max_wall_s"], wall)
    return rules


def run(work: Path, cores: int, targets: list[str]) -> tuple[float, list[str]]:
    """Run the DAG in `work`; return its wall time and the rules of the jobs it ran (from its summary)."""
    env = dict(os.environ, PYTHONPATH=str(work / "src"), PARKSTEER_MODEL_CACHE=str(work / "results" / "model"))
    cmd = [str(SNAKEMAKE), *targets, "--cores", str(cores), "--quiet", "all"]
    start = time.perf_counter()
    done = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode:
        logs = sorted((work / ".snakemake" / "log").glob("*.log"))
        detail = logs[-1].read_text(encoding="utf-8")[-3000:] if logs else (done.stdout + done.stderr)[-3000:]
        raise SystemExit(f"snakemake failed ({' '.join(cmd)} in {work}):\n{detail}")
    summary = subprocess.run([str(SNAKEMAKE), *targets, "--summary", "--quiet", "all"], cwd=work, env=env,
                             capture_output=True, text=True).stdout
    ran = sorted({line.split("\t")[2] for line in summary.splitlines()[1:] if line.count("\t") >= 2})
    return wall, ran


def critical_path(work: Path, targets: list[str], env: dict) -> tuple[float, list[str]]:
    """(seconds, jobs) of the longest chain of the DAG, each job weighted by its benchmark file's wall time."""
    import re

    dot = subprocess.run([str(SNAKEMAKE), *targets, "--dag", "--quiet", "all"], cwd=work, env=env,
                         capture_output=True, text=True, check=True).stdout
    labels = {m.group(1): m.group(2).split("\\n") for m in re.finditer(r'^\s*(\d+)\[label = "([^"]*)"', dot, re.M)}
    edges = [(a, b) for a, b in re.findall(r"^\s*(\d+) -> (\d+)", dot, re.M)]

    def seconds(node: str) -> float:
        rule, *wildcards = labels[node]
        stem = "__".join(w.split(": ", 1)[1] for w in wildcards) or rule
        path = work / "results" / "benchmarks" / rule / f"{stem}.tsv"
        if not path.is_file():
            return 0.0
        with path.open(encoding="utf-8") as f:
            return max((float(row["s"]) for row in csv.DictReader(f, delimiter="\t")), default=0.0)

    before: dict[str, list[str]] = {node: [] for node in labels}
    for a, b in edges:  # a is an input of b
        before[b].append(a)
    best: dict[str, tuple[float, list[str]]] = {}

    def longest(node: str) -> tuple[float, list[str]]:
        if node not in best:
            prior = max((longest(a) for a in before[node]), default=(0.0, []))
            best[node] = (prior[0] + seconds(node), prior[1] + [" ".join(labels[node])])
        return best[node]

    sys.setrecursionlimit(max(10_000, sys.getrecursionlimit()))
    return max((longest(node) for node in labels), default=(0.0, []))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("targets", nargs="*", help="Snakemake targets (default: the default target)")
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--keep", help="run in this (new) directory and keep it, instead of a temporary one")
    parser.add_argument("--no-bytecode", action="store_true",
                        help="leave the copy's package without its bytecode (the README's quick start compiles it)")
    args = parser.parse_args(argv)
    load_start = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="bench_pipeline_") as tmp:
        work = Path(args.keep) if args.keep else Path(tmp) / "work"
        work.mkdir(parents=True, exist_ok=False)
        scratch_copy(work, bytecode=not args.no_bytecode)
        wall, ran = run(work, args.cores, args.targets)
        rules = read_benchmarks(work)
        env = dict(os.environ, PYTHONPATH=str(work / "src"), PARKSTEER_MODEL_CACHE=str(work / "results" / "model"))
        path_s, path_jobs = critical_path(work, args.targets, env)
    top = sorted(rules.items(), key=lambda item: -item[1]["wall_s"])[:TOP]
    result = {
        "targets": args.targets or ["(default)"], "cores": args.cores, "bytecode": not args.no_bytecode,
        "wall_s": wall,
        "jobs_wall_s": sum(r["wall_s"] for r in rules.values()), "jobs_cpu_s": sum(r["cpu_s"] for r in rules.values()),
        "rules": rules, "top": [name for name, _ in top],
        "rules_without_benchmark": sorted(set(ran) - set(rules)),
        "critical_path_s": path_s, "critical_path": path_jobs,
        "wall_lower_bound_s": max(path_s, sum(r["wall_s"] for r in rules.values()) / args.cores),
        "machine": platform.platform(), "cpu_count": os.cpu_count(), "python": platform.python_version(),
        "load_average_at_start": load_start, "load_average_at_end": os.getloadavg(),
    }
    print(f"cold run of {' '.join(result['targets'])} on {args.cores} cores: {wall:.1f} s wall; jobs "
          f"{result['jobs_wall_s']:.1f} s wall, {result['jobs_cpu_s']:.1f} s CPU in all")
    print(f"{'rule':<20} {'jobs':>5} {'wall s':>9} {'CPU s':>9} {'max s':>8}")
    for name, r in top:
        print(f"{name:<20} {r['jobs']:>5} {r['wall_s']:>9.1f} {r['cpu_s']:>9.1f} {r['max_wall_s']:>8.1f}")
    print(f"critical path {path_s:.1f} s ({' -> '.join(path_jobs)}); lower bound of the wall time on {args.cores} "
          f"cores {result['wall_lower_bound_s']:.1f} s")
    if result["rules_without_benchmark"]:
        print(f"rules without a benchmark file: {', '.join(result['rules_without_benchmark'])}")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
