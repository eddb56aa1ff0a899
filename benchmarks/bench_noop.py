"""No-op rerun: the cost of `snakemake --cores 2` on a fully built checkout with nothing changed.

Runs, in the repository (which must be fully built: every run must plan nothing), --repeats times each:

* dry: `snakemake --cores 2 --dry-run --quiet rules` (what CI's second-run check runs);
* run: `snakemake --cores 2` (a real run that finds nothing to do);
* repair: `parksteer repair` (what CI runs before the pipeline; it reads every output).

For each it reports the wall time and the CPU time (user + system, of the process and its children) of every run
and their medians, and the machine's load average before the first run: on a shared machine the wall time follows
the load, the CPU time much less. Nothing is written in the checkout but Snakemake's own .snakemake/ records.

    python benchmarks/bench_noop.py results/bench_noop.json [--repeats 5] [--commands dry run repair]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
COMMANDS = {
    "dry": [str(BIN / "snakemake"), "--cores", "2", "--dry-run", "--quiet", "rules"],
    "run": [str(BIN / "snakemake"), "--cores", "2"],
    "repair": [str(BIN / "parksteer"), "repair"],
}


def _timed(command: list[str]) -> dict:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(command, cwd=REPO, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    output = done.stdout + done.stderr
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed:\n{output[-2000:]}")
    if command[0].endswith("snakemake") and "Nothing to be done" not in output and output.strip():
        sys.exit(f"{' '.join(command)} is not a no-op (build the checkout first: snakemake --cores 2):\n{output[-2000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall_s": round(wall, 3), "cpu_s": round(cpu, 3)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON report")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--commands", nargs="+", choices=list(COMMANDS), default=list(COMMANDS))
    args = parser.parse_args()
    report = {"machine": platform.platform(), "cpus": os.cpu_count(), "load_average": os.getloadavg(), "runs": {}}
    for name in args.commands:
        command = COMMANDS[name]
        runs = [_timed(command) for _ in range(args.repeats)]
        report["runs"][name] = {
            "command": " ".join(Path(command[0]).name if i == 0 else part for i, part in enumerate(command)),
            "median_wall_s": statistics.median(r["wall_s"] for r in runs),
            "median_cpu_s": statistics.median(r["cpu_s"] for r in runs),
            "each": runs,
        }
        print(f"{name:7s} wall {report['runs'][name]['median_wall_s']:.2f} s, cpu {report['runs'][name]['median_cpu_s']:.2f} s"
              f" (median of {args.repeats}; load average {report['load_average'][0]:.1f})")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
