"""Benchmark of the hidden-size search of the benchmark's data sets (not a test): secant steps against bisection.

    python benchmarks/bench_size_search.py OUT.json [--cases rack_stiction:3.5,column_friction:2]

For each case (a library candidate hidden at a number of converter steps of torque RMS, in the
benchmark's first file, unladen on the ground), the size is found twice on the same simulations:
by :func:`parksteer.synthetic.size_search.strength_for_rms` (a linearised estimate from a probe, then
secant steps in log-log) and by the bisection it replaced (the bracket grown by factors of 4, then
bisection in the logarithm; kept below as the reference). Each evaluation is a full handwheel-driven
simulation, so the wall time is in proportion to the evaluations; both are reported per case, with
the ratio, and the RMS change each size makes against the target.
"""

from __future__ import annotations

import argparse
import math
import sys
import time


def bisection(torque_of, target_Nm, start, upper, search, rms):
    """The search as it was: bracket by factors of 4 from `start`, then bisection in the logarithm."""
    reference = torque_of(0.0)

    def change(s):
        return rms(torque_of(s), reference)

    low, high = 0.0, float(min(start, upper))
    while change(high) < target_Nm:
        if high >= upper:
            return upper
        low, high = high, min(high * 4.0, upper)
    for _ in range(search.iterations):
        middle = math.sqrt(low * high) if low > 0 else high / 4.0
        value = change(middle)
        if abs(value - target_Nm) <= search.tolerance * target_Nm:
            return middle
        low, high = (middle, high) if value < target_Nm else (low, middle)
    return math.sqrt(low * high) if low > 0 else high


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("--cases", default="rack_stiction:3.5,column_friction:2,kingpin_friction:5,rack_damping:1",
                        help="comma-separated effect:steps")
    args = parser.parse_args(argv)
    from pathlib import Path

    import yaml

    from parksteer.model.symbolic.components import discover_effects, strength_parameter
    from parksteer.parameters import load_parameters
    from parksteer.synthetic.datasets import BenchmarkDesign, clean_run, hand, perturbed_base, torque_step_Nm
    from parksteer.synthetic.size_search import rms_difference, strength_for_rms
    from parksteer.tables import write_json

    params = load_parameters()
    config = yaml.safe_load((Path(__file__).resolve().parents[1] / "config" / "config.yaml").read_text("utf-8"))
    design = BenchmarkDesign.from_config(config["benchmark"])
    base = perturbed_base(params, design.seed, design.perturbation)
    hand_profile = hand(params, design.seed * 100)
    registry = discover_effects()
    rows = []
    for item in args.cases.split(","):
        name, steps = item.split(":")
        key = strength_parameter(registry[name], params)
        target = float(steps) * torque_step_Nm(params)
        result = {"case": f"{name} at {steps} steps"}
        for label, search in (("secant", strength_for_rms), ("bisection", None)):
            calls = []

            def torque_of(s):
                calls.append(s)
                overrides = {**base, key.key: s}
                return clean_run(params, "unladen", "ground", hand_profile, f"+{name}", overrides)["handwheel_torque_Nm"]

            t0 = time.perf_counter()
            if search is None:
                found = bisection(torque_of, target, key.upper * 1e-3, key.upper, design.search, rms_difference)
            else:
                found = search(torque_of, target, key.upper * 1e-3, key.upper, design.search)
            wall = time.perf_counter() - t0
            reached = rms_difference(torque_of(found), torque_of(0.0)) / target
            result[label] = {"strength": found, "evaluations": len(calls) - 2, "wall_s": wall,
                             "change_over_target": reached}
        result["evaluation_ratio"] = result["bisection"]["evaluations"] / result["secant"]["evaluations"]
        result["wall_ratio"] = result["bisection"]["wall_s"] / result["secant"]["wall_s"]
        rows.append(result)
        print(f"{result['case']:30s} secant {result['secant']['evaluations']:2d} sims {result['secant']['wall_s']:6.1f} s"
              f" ({result['secant']['change_over_target']:.3f} of target) | bisection "
              f"{result['bisection']['evaluations']:2d} sims {result['bisection']['wall_s']:6.1f} s "
              f"({result['bisection']['change_over_target']:.3f}) | x{result['wall_ratio']:.1f}", flush=True)
    write_json(args.out, {"rows": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
