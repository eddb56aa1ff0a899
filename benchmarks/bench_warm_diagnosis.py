"""Benchmark (not a test): what a warm diagnosis costs, and where: imports, replays, wall; as ratios to a reference.

    python benchmarks/bench_warm_diagnosis.py [--reference [NAME=]SRC ...] [--repeats 5] [--jobs N]

For this tree's ``src`` and each ``--reference`` tree's (e.g. ``git archive 53f1b0c`` unpacked; repeatable), in fresh
interpreters with that ``src`` first on the path, on the model cache the first (unmeasured) run fills:

- **import**: ``import parksteer.cli, parksteer.commands.measure, parksteer.diagnose.select``, timed inside the
  interpreter (what every ``parksteer diagnose`` pays before it reads a file);
- **help**: the process ``parksteer diagnose --help``, wall;
- **manual**: the README's example, ``parksteer diagnose data/measurements/example_unladen.csv --json --quiet``,
  wall, with the replays and the stage times its JSON reports (``cost``);
- **assisted**: an assisted record, ``parksteer diagnose data/samples/polo_drag.csv --with-assist --vehicle
  data/vehicles/polo_vi.toml --json --quiet``;
- **each stage** of both (``manual.<stage>_s``, ``assisted.<stage>_s``): its wall time as the JSON's
  ``cost.timings_s`` gives it, where the stage took 5 ms or more in some tree.

Warm means the bytecode too: each interpreter compiles a module's source only once, into a cache of this run's
own (``PYTHONPYCACHEPREFIX``, a temporary folder, so that no tree is written into), whatever
``PYTHONDONTWRITEBYTECODE`` says; an installed package has its bytecode, and so has the README's editable install
(its quick start runs ``compileall``); without it every process compiles some 140 modules again.

Each is repeated ``--repeats`` times in turn (tree by tree within a repeat, so a machine's drift touches every tree
alike) and reported as its median, and as the ratio of this tree's median to each reference's. Time per replay is
the wall of the diagnosis's own stages (``cost.timings_s``, the method without the process around it) over its
replays. Beside each wall, ``*_cpu_s`` is the CPU time (user + system) of the process and the workers it waited
for: on a machine shared with other work the wall waits for the CPU, the CPU time much less.

The output names each reference tree first. Against the main branch before this round's speed work:

    mkdir /tmp/ref && git archive 755c37a | tar -x -C /tmp/ref
    python benchmarks/bench_warm_diagnosis.py --reference before=/tmp/ref/src --repeats 5
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IMPORT_PROBE = ("import time\nt = time.perf_counter()\nimport parksteer.cli, parksteer.commands.measure, "
                "parksteer.diagnose.select\nprint(time.perf_counter() - t)")
DIAGNOSES = {
    "manual": ["diagnose", "data/measurements/example_unladen.csv", "--json", "--quiet"],
    "assisted": ["diagnose", "data/samples/polo_drag.csv", "--with-assist", "--vehicle", "data/vehicles/polo_vi.toml",
                 "--json", "--quiet"],
}


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(src: Path, args: list[str], bytecode: Path) -> tuple[float, float, str]:
    """One fresh interpreter on `src`, its bytecode cached under `bytecode`: its wall time, its CPU time (with the
    workers it waited for) and its stdout."""
    env = {**os.environ, "PYTHONPATH": str(src), "PYTHONPYCACHEPREFIX": str(bytecode)}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    cpu, start = _children_cpu_s(), time.perf_counter()
    out = subprocess.run([sys.executable, *args], cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    return time.perf_counter() - start, _children_cpu_s() - cpu, out.stdout


def measure(src: Path, jobs: int, bytecode: Path) -> dict[str, float]:
    help_wall, help_cpu, _ = run(src, ["-m", "parksteer.cli", "diagnose", "--help"], bytecode)
    out = {"import_s": float(run(src, ["-c", IMPORT_PROBE], bytecode)[2].strip()), "help_s": help_wall,
           "help_cpu_s": help_cpu}
    for name, args in DIAGNOSES.items():
        wall, cpu, stdout = run(src, ["-m", "parksteer.cli", *args, "--jobs", str(jobs)], bytecode)
        cost = json.loads(stdout)["cost"]
        out[f"{name}_s"] = wall
        out[f"{name}_cpu_s"] = cpu
        out[f"{name}_replays"] = float(cost["replays"])
        out[f"{name}_per_replay_ms"] = 1e3 * sum(cost["timings_s"].values()) / max(cost["replays"], 1)
        for stage, seconds in cost["timings_s"].items():
            out[f"{name}.{stage}_s"] = seconds
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", action="append", default=[], help="[NAME=]SRC of a tree to compare with")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    trees = {"this": ROOT / "src"}
    for ref in args.reference:
        name, _, src = ref.rpartition("=")
        trees[name or "reference"] = Path(src).resolve()
    bytecode = Path(tempfile.mkdtemp(prefix="bench_warm_bytecode_"))
    try:
        for name, src in trees.items():  # the warm-up: fills the model cache for each tree's keys, and the bytecode
            print(f"warm-up {name}", file=sys.stderr, flush=True)
            measure(src, args.jobs, bytecode)
        samples: dict[str, list[dict[str, float]]] = {name: [] for name in trees}
        for repeat in range(args.repeats):
            for name, src in trees.items():
                print(f"repeat {repeat + 1}/{args.repeats}: {name}", file=sys.stderr, flush=True)
                samples[name].append(measure(src, args.jobs, bytecode))
    finally:
        shutil.rmtree(bytecode, ignore_errors=True)
    for name, src in trees.items():
        print(f"{name}: {src}")
    medians = {name: {k: statistics.median(s[k] for s in runs) for k in runs[0]} for name, runs in samples.items()}
    # a stage whose time is under 5 ms in every tree is left out (the table is long enough); a stage one tree lacks
    # shows nan there
    keys = [k for k in medians["this"] if "." not in k or max(m.get(k, 0.0) for m in medians.values()) >= 0.005]
    for m in medians.values():
        for k in keys:
            m.setdefault(k, float("nan"))
    width = max(24, *(len(k) + 2 for k in keys))
    print(f"{'median':<{width}}" + "".join(f"{name:>12}" for name in trees)
          + "".join(f"{'this/' + name:>14}" for name in trees if name != "this"))
    for k in keys:
        row = f"{k:<{width}}" + "".join(f"{medians[name][k]:>12.3f}" for name in trees)
        row += "".join(f"{medians['this'][k] / medians[name][k] if medians[name][k] else float('nan'):>14.2f}"
                       for name in trees if name != "this")
        print(row)


if __name__ == "__main__":
    main()
