"""Benchmark (not a test): the README example's diagnosis with the fits' Jacobians from finite differences and
Broyden's update (the default) and exact from the replays' forward sensitivities (``DiagnosisSettings.exact_jacobian``).

    python benchmarks/bench_exact_jacobian.py [--repeats 5] [--file data/measurements/example_unladen.csv]

Each run is a fresh interpreter (``--child``) that diagnoses the file in line (one job, models compiled: the first,
unmeasured run of each setting fills the cache) and prints its wall (the diagnosis alone, imports and intake left
out), the calibration's replays and wall (``replays_by_stage`` and ``timings_s`` of the calibration stage), every
replay, the verdict, the missing effect and the calibrated values. The settings alternate within a repeat, so a
machine's drift touches both alike; the table gives the medians (the stages' too) and says whether every run's
verdict and effect agree between the settings. An exact Jacobian's integration with sensitivities counts as one replay.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def child(file: str, exact: bool) -> dict:
    import dataclasses

    from parksteer.diagnose.intake import Request, car_parameters, intake
    from parksteer.diagnose.settings import DEFAULT_SETTINGS

    settings = dataclasses.replace(DEFAULT_SETTINGS, exact_jacobian=exact)
    taken = intake(Request([file], car_parameters(), settings=settings, jobs=1))
    start = time.perf_counter()
    diagnosis = taken.diagnose(quiet=True)
    wall = time.perf_counter() - start
    return {"wall_s": wall, "replays": diagnosis.replays, "replays_by_stage": dict(diagnosis.replays_by_stage),
            "timings_s": dict(diagnosis.timings_s), "verdict": diagnosis.verdict, "effect": diagnosis.effect,
            "calibrated": {k: float(v) for k, v in diagnosis.calibration.values.items()},
            "calibration_evaluations": diagnosis.calibration.evaluations}


def run(file: str, exact: bool) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", file, "--exact" if exact else "--fd"], cwd=ROOT,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--file", default="data/measurements/example_unladen.csv")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--exact", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--fd", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args.child, args.exact)))
        return
    runs = {False: [], True: []}
    for exact in (False, True):  # fill the model cache, unmeasured
        run(args.file, exact)
    for _ in range(args.repeats):
        for exact in (False, True):
            runs[exact].append(run(args.file, exact))
    for exact, label in ((False, "finite differences"), (True, "exact")):
        r = runs[exact]
        stages = {name: statistics.median(x["timings_s"].get(name, 0.0) for x in r) for name in r[0]["timings_s"]}
        print(f"{label:20s} wall {statistics.median(x['wall_s'] for x in r):.3f} s  "
              f"calibration replays {statistics.median(x['calibration_evaluations'] for x in r):.0f}  "
              f"replays {statistics.median(x['replays'] for x in r):.0f}  verdict {r[0]['verdict']} {r[0]['effect']}")
        print(f"{'':20s} stages (s) " + ", ".join(f"{name} {t:.3f}" for name, t in stages.items() if t >= 0.001))
        print(f"{'':20s} calibrated {r[0]['calibrated']}")
    same = all(a["verdict"] == b["verdict"] and a["effect"] == b["effect"] for a, b in zip(runs[False], runs[True]))
    print(f"verdicts and effects the same in every run: {same}")


if __name__ == "__main__":
    main()
