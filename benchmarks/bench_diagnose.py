"""Benchmark of compare and diagnose (not a test): wall time and replays for one and for two files.

    python benchmarks/bench_diagnose.py OUT.json [--repeats 3]

Times, with the compiled models already in the cache (derived first, untimed):

- one replay of an 18 s measured cycle (rack smoothing excluded), median of 20;
- ``compare`` of one file (replay, rack ensemble for the replay uncertainty, phases, metrics);
- ``diagnose`` of one file against every candidate of the registry (target: 20 s on 2 cores),
  and of the paper's Fig. 5 pair (unladen and part laden), with the replays each used;
- the same with a candidate hidden (rack stiction at 3.5 converter steps RMS): a ``missing``
  verdict costs more (refits that converge further, a second replay-uncertainty estimate).

The data are synthetic (parksteer.synthetic.datasets), base parameters moved off the
parameter file's values, so that the calibration has work to do. Prints a table and writes
the numbers as JSON.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("--repeats", type=int, default=3, help="repeats of each diagnosis (default 3)")
    args = parser.parse_args(argv)

    from parksteer.diagnose.candidates import candidate_models
    from parksteer.model.codegen.cache import ensure
    from parksteer.diagnose.compare import compare_files
    from parksteer.diagnose.problem import Problem, prepare_file
    from parksteer.diagnose.select import diagnose
    import yaml

    from parksteer.synthetic.datasets import BenchmarkDesign, DatasetSpec, make_dataset, perturbed_base
    from parksteer.model.symbolic.components import discover_effects, resolve_effects
    from parksteer.parameters import load_parameters
    from parksteer.tables import write_json

    params = load_parameters()
    start = time.perf_counter()
    for spec in candidate_models().values():
        ensure(resolve_effects(spec))
    derive_s = time.perf_counter() - start
    config = yaml.safe_load((Path(__file__).resolve().parents[1] / "config" / "config.yaml").read_text("utf-8"))
    design = BenchmarkDesign.from_config(config["benchmark"])
    spec = DatasetSpec("bench", 777, (("unladen", "ground"), ("part_laden", "ground")), "null", None, None,
                       perturbed_base(params, 777, design.perturbation))
    measurements = make_dataset(params, spec).measurements
    hidden_spec = DatasetSpec("bench_hidden", 778, spec.files, "candidate", "rack_stiction", 3.5,
                              perturbed_base(params, 778, design.perturbation), search=design.search)
    hidden_measurements = make_dataset(params, hidden_spec).measurements
    candidates = sorted(n for n, e in discover_effects().items() if not e.in_default_set)

    one = [prepare_file(measurements[0], label="unladen")]
    base = resolve_effects(None)
    replay = Problem(one, params).replay(base, 0)
    replay.torque()
    times = []
    for _ in range(20):
        t0 = time.perf_counter()
        replay.torque()
        times.append(time.perf_counter() - t0)
    replay_s = statistics.median(times)

    compare_times = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        compare_files([prepare_file(measurements[0], label="unladen")], params)
        compare_times.append(time.perf_counter() - t0)

    def timed_diagnosis(count: int, data=measurements):
        walls, replays, verdicts = [], [], []
        for _ in range(args.repeats):
            files = [prepare_file(m, label=str(i)) for i, m in enumerate(data[:count])]
            t0 = time.perf_counter()
            d = diagnose(files, params)
            walls.append(time.perf_counter() - t0)
            replays.append(d.problem.evaluations)
            verdicts.append(d.verdict)
        return {"wall_s_median": statistics.median(walls), "wall_s": walls, "replays": replays,
                "verdicts": verdicts, "timings_s_last": d.timings_s}

    one_file = timed_diagnosis(1)
    two_files = timed_diagnosis(2)
    one_hidden = timed_diagnosis(1, hidden_measurements)
    two_hidden = timed_diagnosis(2, hidden_measurements)
    result = {
        "machine": {"python": sys.version.split()[0], "platform": platform.platform(), "cpus": os.cpu_count()},
        "candidates": candidates,
        "model_derivation_s (cache cold only)": derive_s,
        "replay_s_median": replay_s,
        "compare_one_file_s_median": statistics.median(compare_times),
        "diagnose_one_file": one_file,
        "diagnose_two_files": two_files,
        "diagnose_one_file_stiction_hidden": one_hidden,
        "diagnose_two_files_stiction_hidden": two_hidden,
        "target_one_file_s": 20.0,
    }
    write_json(args.out, result)
    print(f"candidates: {len(candidates)} ({', '.join(candidates)})")
    print(f"one replay (18 s cycle):          {1000 * replay_s:8.1f} ms")
    print(f"compare, one file:                {statistics.median(compare_times):8.2f} s")
    print(f"diagnose, one file, all candidates: {one_file['wall_s_median']:6.2f} s "
          f"({statistics.median(one_file['replays']):.0f} replays; target 20 s)")
    for label, r in (("diagnose, two files:", two_files), ("one file, stiction hidden:", one_hidden),
                     ("two files, stiction hidden:", two_hidden)):
        print(f"{label:<34}{r['wall_s_median']:6.2f} s ({statistics.median(r['replays']):.0f} replays, "
              f"verdict {r['verdicts'][-1]})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
