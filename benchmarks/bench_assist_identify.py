"""`assist identify` on records the model did not make (not a test): how close each identified number comes.

    python benchmarks/bench_assist_identify.py [--seeds 8] [--angle-only]

The records are tests/diagnose/eps_truth.py's quasi-static column EPS (a power-law map of its own, the sensor read in
0.01 N m steps with a zero offset, the current in 0.1 A steps, the motor's friction and rotor through the worm, the
worm's two efficiencies) on the Polo's vehicle file, one per seed, with the offset at -0.03, 0, 0.04 and 0.08 N m and
the motor friction at 0, 0.01, 0.03 and 0.05 N m in turn. Prints each seed's numbers, then per quantity the largest
error and how many 95 % intervals hold the truth (docs/assist_identify.md quotes the table).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "diagnose"))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--angle-only", action="store_true", help="the handwheel angle in 0.1 deg steps, no rack")
    args = parser.parse_args(argv)

    import eps_truth as et
    from parksteer.diagnose.identify.assist_identify import identify_boost
    from parksteer.errors import UsageError
    from parksteer.model.symbolic.components import discover_effects

    discover_effects()
    rows, failed = [], 0
    with tempfile.TemporaryDirectory() as folder:
        for seed in range(1, args.seeds + 1):
            truth = dataclasses.replace(et.Truth(), offset=[0.04, -0.03, 0.0, 0.08][seed % 4],
                                        motor_friction=[0.03, 0.0, 0.05, 0.01][seed % 4])
            path = et.truth_record(truth, Path(folder) / f"seed{seed}.csv", seed=seed, angle_only=args.angle_only)
            clock = time.perf_counter()
            try:
                f = identify_boost([path], et.POLO)
            except UsageError as exc:  # a replay that fails on the record's rack: counted, not fatal
                print(f"seed {seed}: failed: {exc}")
                failed += 1
                continue
            seconds = time.perf_counter() - clock
            current = truth.current(np.array(f.torques))[2:]
            row = {
                "map current A": (max(abs(a - c) for a, c in zip(f.current_A[2:], current)),
                                  sum(lo <= c <= hi for c, (lo, hi) in zip(current, f.current_ci95[2:])),
                                  len(current)),
                "product %": ((f.product.value / truth.product - 1) * 100, _holds(f.product, truth.product), 1),
                "motor friction N m": (f.motor_friction.value - truth.motor_friction,
                                       _holds(f.motor_friction, truth.motor_friction), 1),
                "offset N m": (f.offset.value - truth.offset, _holds(f.offset, truth.offset), 1),
                "rack friction N": (f.rack_friction.value - 730.0, _holds(f.rack_friction, 730.0), 1),
                "rotor inertia %": ((f.motor_inertia.value / truth.rotor_inertia - 1) * 100,
                                    _holds(f.motor_inertia, truth.rotor_inertia), 1),
                "back efficiency": (f.back_efficiency.value - truth.back_efficiency,
                                    _holds(f.back_efficiency, truth.back_efficiency), 1),
                "dead band N m": (f.dead_band.value - truth.dead_band, _holds(f.dead_band, truth.dead_band), 1),
            }
            rows.append(row)
            print(f"seed {seed} ({seconds:.1f} s): " + "; ".join(f"{k} {v[0]:+.4g}" for k, v in row.items()))
    print(f"quantity: error min to max, intervals holding the truth ({len(rows)} records; {failed} failed)")
    for key in rows[0]:
        errors = [r[key][0] for r in rows]
        print(f"  {key}: {min(errors):+.4g} to {max(errors):+.4g}, {sum(r[key][1] for r in rows)} of "
              f"{sum(r[key][2] for r in rows)}")
    return 0


def _holds(estimate, value: float) -> int:
    return int(estimate.ci95[0] <= value <= estimate.ci95[1])


if __name__ == "__main__":
    sys.exit(main())
