"""Benchmark (not a test): the first diagnosis of a new car, as a whole process, cold and warm.

    python benchmarks/bench_first_diagnosis.py [--reference [NAME=]SRC ...] [--repeats 3] [--record FILE.csv]
                                               [--jobs N]

The car is data/vehicles/polo_vi.toml; its DAQ file is made once (unless --record names one) by the synthetic
logger of the variation benchmark (rate_8pc_50Hz, seed 5: an 8 % hand-rate variation logged at 50 Hz with 8-bit
converters) on the car's kerb case, nothing hidden: what a new user's first record of a sound car looks like. Each
repeat runs, for each ``--reference`` tree's ``src`` (e.g. a ``git archive main`` unpacked; repeatable, named
NAME or ``reference``) and this tree in turn:

    PARKSTEER_MODEL_CACHE=<new empty folder> parksteer diagnose RECORD --vehicle data/vehicles/polo_vi.toml \\
        --json --quiet [--jobs N]          # cold: every model derived, generated and compiled
    (the same command again on the cache the cold run filled)   # warm

and times the process: wall, and the CPU (user + system) of it and every process it waited for (its workers and
background builds), which on a machine other work shares is the steadier number (wall >= CPU / cores). It prints
every time, the medians, the cold run's CPU over the cores as a multiple of the warm wall (the least cold / warm
ratio its work allows, however its compiles are ordered), and whether each tree gave the same verdict and
ranking in every run; the cold runs' model builds (derive, codegen, compile: their model.json timings) are summed
per tree, to show where the cold time goes (their wall times, so only as steady as the machine is quiet). The package's
pre-derived models (src/parksteer/model/prebuilt) make a cold run compile without deriving; to time the cold run
that derives them (an edited effect, a set not shipped), give a copy of this tree's src without them:

    cp -r src /tmp/derived-src && rm -r /tmp/derived-src/parksteer/model/prebuilt
    python benchmarks/bench_first_diagnosis.py --reference derived=/tmp/derived-src --repeats 3

Against main, unpacked beside this tree:

    mkdir /tmp/ref-main && git archive main | tar -x -C /tmp/ref-main
    python benchmarks/bench_first_diagnosis.py --reference main=/tmp/ref-main/src --repeats 3
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VEHICLE = ROOT / "data" / "vehicles" / "polo_vi.toml"


def make_record(path: Path) -> None:
    from parksteer.measure.io import write_measurement
    from parksteer.model.symbolic.components import discover_effects
    from parksteer.parameters import load_parameters
    from parksteer.synthetic.variations import variation_by_name, variation_record
    from parksteer.vehicle import load_vehicle

    discover_effects()  # the effects' own quantities join the registry (the car file sets ackermann's)
    params = load_vehicle(VEHICLE, load_parameters())
    hand, logger = variation_by_name("rate_8pc_50Hz").settings(5)
    write_measurement(path, variation_record(params, hand, logger, case="kerb"), params)


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(src: Path, record: Path, cache: Path, jobs: int | None) -> tuple[float, float, dict]:
    env = {**os.environ, "PYTHONPATH": str(src), "PARKSTEER_MODEL_CACHE": str(cache)}
    command = [sys.executable, "-m", "parksteer.cli", "diagnose", str(record), "--vehicle", str(VEHICLE), "--json",
               "--quiet", *(["--jobs", str(jobs)] if jobs else [])]
    start, cpu = time.perf_counter(), _children_cpu()
    done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=ROOT)
    elapsed, cpu = time.perf_counter() - start, _children_cpu() - cpu
    if done.returncode != 0:
        raise SystemExit(f"{src}: diagnose failed:\n{done.stderr}")
    return elapsed, cpu, json.loads(done.stdout)


def build_times(cache: Path) -> dict[str, float]:
    """Seconds of derive, codegen and compile summed over the models a cold run built into `cache`."""
    total = {"models": 0, "derive": 0.0, "codegen": 0.0, "compile": 0.0}
    for info in cache.glob("*/model.json"):
        timings = json.loads(info.read_text(encoding="utf-8"))["timings_s"]
        total["models"] += 1
        for stage in ("derive", "codegen", "compile"):
            total[stage] += timings[stage]
    return total


def answer(result: dict) -> tuple:
    return result["verdict"], result.get("effect"), tuple(r["effect"] for r in result["ranking"])


def main() -> None:
    global VEHICLE  # --vehicle replaces the default car for every tree
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", action="append", default=[], metavar="[NAME=]SRC",
                        help="another tree's src (e.g. /tmp/ref-main/src); repeatable")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--record", type=Path, default=None, help="the DAQ file (default: made once, see above)")
    parser.add_argument("--jobs", type=int, default=None, help="parksteer diagnose --jobs (default: its own)")
    parser.add_argument("--vehicle", type=Path, default=VEHICLE,
                        help="the car's file (default: the Polo's; an older tree may need its own version of it)")
    args = parser.parse_args()
    VEHICLE = args.vehicle.resolve()
    trees = {}
    for item in args.reference:
        name, _, src = item.rpartition("=")
        trees[name or "reference"] = Path(src).resolve()
    trees["this"] = ROOT / "src"
    with tempfile.TemporaryDirectory(prefix="first-diagnosis-") as scratch:
        scratch = Path(scratch)
        record = args.record or scratch / "polo_kerb.csv"
        if args.record is None:
            make_record(record)
        times = {name: {"cold": [], "warm": []} for name in trees}
        cpus = {name: {"cold": [], "warm": []} for name in trees}
        builds = {name: [] for name in trees}
        answers = {name: set() for name in trees}
        for repeat in range(args.repeats):
            for name, src in trees.items():
                cache = scratch / f"cache-{name}-{repeat}"
                cache.mkdir()
                for kind in ("cold", "warm"):
                    elapsed, cpu, result = run(src, record, cache, args.jobs)
                    times[name][kind].append(elapsed)
                    cpus[name][kind].append(cpu)
                    answers[name].add(answer(result))
                    print(f"{name} {kind} {elapsed:.2f} s wall, {cpu:.2f} s CPU  ({result['verdict']}, "
                          f"{result['cost']['replays']} replays; load {os.getloadavg()[0]:.1f})", flush=True)
                builds[name].append(build_times(cache))
    from parksteer.diagnose.parallel import available_workers

    cores = available_workers()
    print(f"\nparksteer diagnose, one record of {VEHICLE.name}, whole process, {args.repeats} repeats "
          f"(median s, wall / CPU; cold = empty model cache)")
    for name in trees:
        b = builds[name][0]
        print(f"  {name:9s} cold {statistics.median(times[name]['cold']):6.2f} / {statistics.median(cpus[name]['cold']):6.2f}"
              f"  warm {statistics.median(times[name]['warm']):5.2f} / {statistics.median(cpus[name]['warm']):5.2f}"
              f"   models built {b['models']}, summed over them: "
              f"derive {b['derive']:.1f} s, codegen {b['codegen']:.1f} s, compile {b['compile']:.1f} s   "
              f"same answer in every run: {len(answers[name]) == 1}")
        cold, warm = statistics.median(times[name]["cold"]), statistics.median(times[name]["warm"])
        # a cold run's CPU spread over every core is the least wall it can take, however its compiles are ordered
        floor = statistics.median(cpus[name]["cold"]) / cores
        print(f"  {'':9s} cold / warm {cold / warm:.2f}; the cold run's CPU over {cores} cores {floor:.2f} s, "
              f"{floor / warm:.2f} x warm")
    if len(trees) > 1:
        same = all(answers[name] == answers["this"] for name in trees)
        print(f"  verdict, named effect and ranking order the same in every tree: {same}")


if __name__ == "__main__":
    main()
