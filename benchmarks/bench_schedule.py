"""How the order of the pipeline's jobs on few cores costs wall time: its DAG scheduled again from a build's times.

A cold build on 2 cores is bound by its work; what its order can lose is a core left idle while one long job runs
alone (at the end, or while the jobs waiting on the models cannot start). This reads, in a checkout where the
pipeline has been built (default: this one), the DAG (`snakemake --forceall --dag`), each job's `priority:`
(`snakemake --forceall -n`) and each job's wall time from its benchmark file (results/benchmarks/<rule>/), then
schedules the jobs again on N cores as Snakemake does (a job starts when its inputs are made and a core is free;
among the ready jobs the highest priority first), the ties broken at random over many seeds, once with the
workflow's priorities and once without any. It prints the median and range of the wall time each gives beside
the lower bound (the jobs' summed time over N, or the longest chain if longer).

    python benchmarks/bench_schedule.py out.json [--work CHECKOUT] [--times BUILT_CHECKOUT] [--cores 2] [--seeds 200]

`--times` takes the job times from another checkout's build (this workflow's order, that build's times: an order
tried on the times of a build made before it).

It runs no job: the times are the build's own (a build on a busy machine gives longer times, in proportion).
"""

from __future__ import annotations

import argparse
import csv
import itertools
import json
import random
import re
import statistics
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).with_name("snakemake")


def job_key(rule: str, wildcards: dict[str, str]) -> tuple:
    """A job's rule and wildcards, in the order given; :func:`ranked_key` compares them whatever their order."""
    return rule, tuple(wildcards.items())


def ranked_key(key: tuple) -> tuple:
    return key[0], tuple(sorted(key[1]))


def dag(work: Path) -> tuple[dict[str, tuple], list[tuple[str, str]]]:
    """(node -> job key, edges (input job, job that reads it)) of the whole DAG."""
    dot = subprocess.run([str(SNAKEMAKE), "--forceall", "--dag", "--quiet", "all"], cwd=work, capture_output=True,
                         text=True, check=True).stdout
    nodes = {}
    for node, label in re.findall(r'^\s*(\d+)\[label = "([^"]*)"', dot, re.M):
        rule, *wildcards = label.split("\\n")
        nodes[node] = job_key(rule, dict(w.split(": ", 1) for w in wildcards))
    return nodes, re.findall(r"^\s*(\d+) -> (\d+)", dot, re.M)


def priorities(work: Path, cores: int) -> dict[tuple, int]:
    """Job key -> its priority, from a dry run of every job (a job the dry run shows no priority for has 0)."""
    text = subprocess.run([str(SNAKEMAKE), "--forceall", "-n", "--cores", str(cores)], cwd=work, capture_output=True,
                          text=True, check=True).stdout
    found = {}
    for block in re.split(r"\n(?=rule \S+:|localrule \S+:)", text):
        head = re.match(r"(?:local)?rule (\S+):", block)
        if not head:
            continue
        wildcards = re.search(r"^\s+wildcards: (.*)$", block, re.M)
        pairs = dict(p.split("=", 1) for p in wildcards.group(1).split(", ")) if wildcards else {}
        priority = re.search(r"^\s+priority: (-?\d+)$", block, re.M)
        found[ranked_key(job_key(head.group(1), pairs))] = int(priority.group(1)) if priority else 0
    return found


def wall_s(times_from: Path, key: tuple) -> float:
    """The job's wall time from its benchmark file (0 for a job without one: `all`, the named figure targets)."""
    rule, wildcards = key
    # the stem joins the wildcards in the order the rule's benchmark_file names them, which the DAG does not say
    stems = ["__".join(order) for order in itertools.permutations(v for _, v in wildcards)] if wildcards else [rule]
    path = next((p for p in (times_from / "results" / "benchmarks" / rule / f"{s}.tsv" for s in stems) if p.is_file()),
                None)
    if path is None:
        return 0.0
    with path.open(encoding="utf-8") as f:
        return max((float(row["s"]) for row in csv.DictReader(f, delimiter="\t")), default=0.0)


def schedule(times: dict[str, float], before: dict[str, set], ranks: dict[str, int], cores: int, seed: int) -> float:
    """The wall time of list scheduling on `cores`: ready jobs by rank (highest first), ties in a random order."""
    rng = random.Random(seed)
    waiting = {node: set(inputs) for node, inputs in before.items()}
    readers: dict[str, list[str]] = {node: [] for node in before}
    for node, inputs in before.items():
        for source in inputs:
            readers[source].append(node)
    ready = [node for node, inputs in waiting.items() if not inputs]
    running: list[tuple[float, str]] = []
    now, done = 0.0, 0
    while done < len(before):
        rng.shuffle(ready)
        ready.sort(key=lambda node: -ranks[node])
        while ready and len(running) < cores:
            node = ready.pop(0)
            running.append((now + times[node], node))
        running.sort()
        now, finished = running.pop(0)
        done += 1
        for reader in readers[finished]:
            waiting[reader].discard(finished)
            if not waiting[reader]:
                ready.append(reader)
    return now


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("--work", default=str(REPO), help="a checkout where the pipeline was built (default: this)")
    parser.add_argument("--times", help="the built checkout whose benchmark files give the times (default: --work)")
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--seeds", type=int, default=200)
    args = parser.parse_args(argv)
    work = Path(args.work)
    nodes, edges = dag(work)
    ranked = priorities(work, args.cores)
    times_from = Path(args.times) if args.times else work
    times = {node: wall_s(times_from, key) for node, key in nodes.items()}
    before = {node: set() for node in nodes}
    for source, reader in edges:
        before[reader].add(source)
    with_priority = {node: ranked.get(ranked_key(key), 0) for node, key in nodes.items()}
    without = {node: 0 for node in nodes}
    runs = {name: [schedule(times, before, ranks, args.cores, seed) for seed in range(args.seeds)]
            for name, ranks in (("priorities", with_priority), ("no_priorities", without))}
    longest: dict[str, float] = {}

    def chain(node: str) -> float:
        if node not in longest:
            longest[node] = times[node] + max((chain(n) for n in before[node]), default=0.0)
        return longest[node]

    sys.setrecursionlimit(max(10_000, sys.getrecursionlimit()))
    total = sum(times.values())
    result = {"work": str(work), "times": str(times_from), "cores": args.cores, "jobs": len(nodes), "jobs_wall_s": total,
              "critical_path_s": max(map(chain, nodes), default=0.0),
              "lower_bound_s": max(total / args.cores, max(map(chain, nodes), default=0.0)),
              "jobs_without_time": sorted(" ".join([k[0], *(v for _, v in k[1])]) for n, k in nodes.items()
                                          if times[n] == 0.0),
              **{name: {"median_s": statistics.median(w), "min_s": min(w), "max_s": max(w)}
                 for name, w in runs.items()}}
    print(f"{len(nodes)} jobs, {total:.0f} job-seconds on {args.cores} cores: lower bound {result['lower_bound_s']:.0f} s "
          f"(critical path {result['critical_path_s']:.0f} s)")
    for name in runs:
        r = result[name]
        print(f"{name:<14} median {r['median_s']:.0f} s, {r['min_s']:.0f}-{r['max_s']:.0f} s over {args.seeds} tie orders")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
