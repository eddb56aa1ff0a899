"""Benchmark of diagnose (not a test): wall time, replays and verdicts, against a reference source tree.

    python benchmarks/bench_diagnose.py OUT.json [--repeats 3] [--eight-repeats 1] [--reference SRC] [--workers N]
                                                 [--car DIR]

Measures, each in a fresh process per source tree and worker count, compiled models already in the cache
(derived first, untimed):

- one replay of an 18 s measured cycle (rack smoothing excluded), median of 20;
- ``compare`` of one file;
- one case of the hidden-effect benchmark (rack stiction hidden at 3.5 converter steps RMS in the
  benchmark's files, base parameters perturbed as the benchmark does), as a ``diag_bench_batch`` job
  diagnoses it (one worker: the DAG runs cases side by side);
- ``diagnose`` of one car file (the unladen car on the ground) against every candidate
  (target: 5 s on 2 cores);
- ``diagnose`` of the paper's eight car files together (target: 20 s on 2 cores).

Variants (each repeat a fresh process, the variants taking turns): this tree with one worker and with ``--workers`` (default: the CPUs available), and, with
``--reference SRC``, another tree's ``src`` (e.g. ``git worktree add /tmp/ref <commit>``; a tree whose
``diagnose`` has no workers runs in line). The car files are the DAG's (``snakemake --cores 1
diag_car_data``, results/diagnose/car); without them the car rows are left out. Reports medians,
the ratio of each variant's median to the reference's (or to this tree's one worker), and whether
every variant reached the same verdicts, named effects and calibrated values (to 1e-6 relative).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CAR_FILES = ("unladen__ground.csv", "part_laden__ground.csv", "offset_12_7mm__ground.csv",
             "offset_12_7mm__air_bearing.csv", "offset_44_5mm__ground.csv", "offset_44_5mm__air_bearing.csv",
             "offset_68_5mm__ground.csv", "offset_68_5mm__air_bearing.csv")


def _measure(repeats: int, workers: int, car: Path | None, eight_repeats: int) -> dict:
    """Every timing of the module docstring in this process (the source tree on sys.path)."""
    import inspect

    import yaml

    from parksteer.diagnose.candidates import candidate_models
    from parksteer.diagnose.compare import compare_files
    from parksteer.diagnose.engine import ReplayEngine
    from parksteer.diagnose.problem import Problem, load_files, prepare_file
    from parksteer.diagnose.select import diagnose
    from parksteer.model.codegen.cache import ensure
    from parksteer.model.symbolic.components import resolve_effects
    from parksteer.parameters import load_parameters
    from parksteer.synthetic.datasets import BenchmarkDesign, benchmark_specs, make_dataset

    params = load_parameters()
    for spec in candidate_models().values():
        ensure(resolve_effects(spec))
    takes_workers = "workers" in inspect.signature(diagnose).parameters
    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text("utf-8"))
    design = BenchmarkDesign.from_config(config["benchmark"])
    case = next(s for s in benchmark_specs(params, design) if s.hidden == "rack_stiction" and s.steps == 3.5)
    bench_measurements = make_dataset(params, case).measurements

    one = [prepare_file(bench_measurements[0], label="unladen")]
    replay = ReplayEngine().replay(Problem(one, params), resolve_effects(None), 0)
    replay.torque()
    times = []
    for _ in range(20):
        t0 = time.perf_counter()
        replay.torque()
        times.append(time.perf_counter() - t0)
    compare_times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        compare_files([prepare_file(bench_measurements[0], label="unladen")], params)
        compare_times.append(time.perf_counter() - t0)

    def timed(make_files, count_workers: int, times: int = repeats) -> dict:
        walls, replays, outcomes = [], [], []
        for _ in range(times):
            files = make_files()
            kwargs = {"workers": count_workers} if takes_workers else {}
            t0 = time.perf_counter()
            d = diagnose(files, params, **kwargs)
            walls.append(time.perf_counter() - t0)
            replays.append(d.replays)
            outcomes.append({"verdict": d.verdict, "effect": d.effect,
                             "best": d.best.name if d.best is not None else None,
                             "calibrated": d.calibration.values,
                             "best_refit": d.best.refit.values if d.best is not None else None})
        return {"wall_s_median": statistics.median(walls), "wall_s": walls, "replays": replays,
                "outcome": outcomes[-1], "timings_s_last": d.timings_s}

    result = {
        "replay_s_median": statistics.median(times),
        "compare_one_file_s_median": statistics.median(compare_times),
        "bench_case": timed(lambda: [prepare_file(m, label=str(i)) for i, m in enumerate(bench_measurements)], 1),
        "bench_case_name": case.name,
    }
    if car is not None:
        result["one_car_file"] = timed(lambda: load_files([car / CAR_FILES[0]], params), workers)
    if car is not None and eight_repeats > 0:
        result["eight_car_files"] = timed(lambda: load_files([car / f for f in CAR_FILES], params), workers,
                                          eight_repeats)
    return result


def _variant(src: Path, repeats: int, workers: int, car: Path | None, eight_repeats: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(src)}
    command = [sys.executable, str(Path(__file__).resolve()), "-", "--emit", "--repeats", str(repeats),
               "--workers", str(workers), "--eight-repeats", str(eight_repeats)] + (["--car", str(car)] if car is not None else [])
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"bench_diagnose: variant {src} with {workers} worker(s) failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _same(a, b, tolerance: float = 1e-6) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k], tolerance) for k in a)
    if isinstance(a, float) and isinstance(b, float):
        return abs(a - b) <= tolerance * max(abs(a), abs(b), 1e-300)
    return a == b


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results ('-' with --emit)")
    parser.add_argument("--repeats", type=int, default=3, help="repeats of each diagnosis (default 3)")
    parser.add_argument("--eight-repeats", type=int, default=1,
                        help="repeats of the eight-file diagnosis (default 1: about a minute each; 0 leaves it out)")
    parser.add_argument("--workers", type=int, default=None, help="workers of the parallel variant (default: CPUs)")
    parser.add_argument("--reference", default=None, metavar="SRC", help="a reference tree's src folder")
    parser.add_argument("--car", default=str(ROOT / "results" / "diagnose" / "car"), metavar="DIR",
                        help="the eight car files (default results/diagnose/car)")
    parser.add_argument("--emit", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    car = Path(args.car) if all((Path(args.car) / f).is_file() for f in CAR_FILES) else None
    if args.emit:
        print(json.dumps(_measure(args.repeats, args.workers or 1, car, args.eight_repeats)))
        return 0

    from parksteer.diagnose.parallel import available_workers
    from parksteer.tables import write_json

    workers = args.workers or available_workers()
    here = ROOT / "src"
    plan = {}
    if args.reference:
        plan["reference"] = (Path(args.reference), 1)
    plan["one_worker"] = (here, 1)
    plan[f"{workers}_workers"] = (here, workers)
    # One process per variant and repeat, the variants taking turns: a change of the machine's load between
    # variants (shared machines) falls on all of them alike.
    variants: dict[str, dict] = {}
    for _ in range(max(args.repeats, 1)):
        for name, (src, count) in plan.items():
            one = _variant(src, 1, count, car, args.eight_repeats)
            if name not in variants:
                variants[name] = one
                continue
            for row, value in one.items():
                if isinstance(value, dict) and "wall_s" in value:
                    merged = variants[name][row]
                    merged["wall_s"] += value["wall_s"]
                    merged["replays"] += value["replays"]
                    merged["wall_s_median"] = statistics.median(merged["wall_s"])
                    merged["same_outcome_each_repeat"] = merged.get("same_outcome_each_repeat", True) and _same(
                        merged["outcome"], value["outcome"])
                elif isinstance(value, float) and row.endswith("_median"):
                    variants[name].setdefault(row + "_all", [variants[name][row]]).append(value)
                    variants[name][row] = statistics.median(variants[name][row + "_all"])
    rows = ["replay_s_median", "compare_one_file_s_median", "bench_case", "one_car_file", "eight_car_files"]
    base_name = next(iter(variants))
    table = {}
    for row in rows:
        if row not in variants[base_name]:
            continue
        value = {name: (v[row]["wall_s_median"] if isinstance(v[row], dict) else v[row]) for name, v in variants.items()}
        table[row] = {"median_s": value, "ratio_to_" + base_name: {n: value[n] / value[base_name] for n in value},
                      "same_outcome": all(_same(v[row].get("outcome"), variants[base_name][row].get("outcome"))
                                          for v in variants.values()) if isinstance(variants[base_name][row], dict)
                      else None}
    result = {
        "machine": {"python": sys.version.split()[0], "platform": platform.platform(), "cpus": os.cpu_count(),
                    "load_average": os.getloadavg()},
        "repeats": args.repeats, "eight_repeats": args.eight_repeats, "workers": workers, "reference": args.reference,
        "targets_s": {"one_car_file": 5.0, "eight_car_files": 20.0},
        "table": table, "variants": variants,
    }
    write_json(args.out, result)
    names = list(variants)
    print(f"{'':<28}" + "".join(f"{n:>14}" for n in names) + f"{'ratio':>9}  same outcome")
    for row, t in table.items():
        last = t["ratio_to_" + base_name][names[-1]]
        print(f"{row:<28}" + "".join(f"{t['median_s'][n]:>13.3f}s" for n in names)
              + f"{last:>9.2f}  {t['same_outcome'] if t['same_outcome'] is not None else ''}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
