"""Benchmark (not a test): the cost of the prescribed-rack solve's forward sensitivities against a plain solve.

    python benchmarks/bench_sensitivities.py [--repeats 7]

The default model's unladen run, its rack swept over 18 s (30 mm each way, 1,801 outputs, the replays' default
tolerances); a plain solve (``prescribed.solve``) and solves with sensitivities (``solve_sensitivities``) along one
key (the surface grip) and the three a calibration fits (carcass stiffness, rack friction, surface grip), each
timed `repeats` times in turn after one unmeasured call (the model compiled and loaded). Prints the medians and
each solve with sensitivities as a multiple of the plain solve's median.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

ONE_KEY = ["derived.surface_grip"]
THREE_KEYS = ["tyre.carcass_torsional_stiffness", "steering.rack_friction_force", "derived.surface_grip"]


def main() -> None:
    from parksteer.measure.rack_spline import interpolate_rack
    from parksteer.model.numeric.prescribed import solve
    from parksteer.model.numeric.sensitivities import parameter_directions, solve_sensitivities
    from parksteer.model.numeric.simulate import prepare

    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    run = prepare("unladen")
    t = np.linspace(0.0, 18.0, 1801)
    rack = interpolate_rack(t, 0.03 * np.sin(2.0 * np.pi * t / 9.0))
    p = run.p.copy()
    cases = {"plain": lambda: solve(run, p, rack, t)}
    for label, keys in (("1 direction", ONE_KEY), ("3 directions", THREE_KEYS)):
        directions = parameter_directions(run, keys)
        cases[label] = lambda directions=directions: solve_sensitivities(run, p, rack, t, directions)
    times: dict[str, list[float]] = {label: [] for label in cases}
    for call in cases.values():
        call()
    for _ in range(args.repeats):
        for label, call in cases.items():
            start = time.perf_counter()
            call()
            times[label].append(time.perf_counter() - start)
    plain = statistics.median(times["plain"])
    for label, values in times.items():
        median = statistics.median(values)
        print(f"{label:14s} median {median * 1e3:8.2f} ms  ({median / plain:5.2f} plain solves)")


if __name__ == "__main__":
    main()
