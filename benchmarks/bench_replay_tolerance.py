"""Benchmark (not a test): what a replay's tolerance buys, in time and in torque error.

    python benchmarks/bench_replay_tolerance.py [--file data/measurements/example_unladen.csv] [--repeats 15]

The file's nominal replay (its rack, the car's parameters, the base model: the first replay of its diagnosis) is
solved by the prescribed-rack solver (:func:`parksteer.model.numeric.prescribed.solve`) at the shipped tolerances
(``PRESCRIBED_RTOL``, ``PRESCRIBED_ATOL_FACTOR``) and at looser ones, the settings interleaved within each repeat so
that the machine's drift touches all alike. Each row gives the median time of a solve, as a ratio to the shipped
one's, and the torque's largest and RMS difference from a converged solve (rtol 1e-10, a hundredth of the
project's absolute tolerances), beside the resolution of a steering-torque channel on a vehicle bus (0.01 N m).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from parksteer.diagnose.engine import ReplayEngine
from parksteer.diagnose.intake import Request, car_parameters, intake
from parksteer.model.numeric.prescribed import solve
from parksteer.model.numeric.tolerances import PRESCRIBED_ATOL_FACTOR, PRESCRIBED_RTOL

BUS_RESOLUTION_NM = 0.01
SETTINGS = [(PRESCRIBED_RTOL, PRESCRIBED_ATOL_FACTOR), (1e-4, 100.0), (1e-5, 1000.0), (1e-4, 1000.0),
            (3e-4, 1000.0), (1e-4, 3000.0), (1e-3, 1000.0)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--file", default="data/measurements/example_unladen.csv")
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()
    taken = intake(Request([args.file], car_parameters(), jobs=1))
    f = taken.files[0]
    replay = ReplayEngine().new_replay(taken.effects, f.case, f.surface, taken.params, f.rack, f.replay_time_s)
    run, p = replay.parameter_vector()

    def solved(rtol, factor):
        return solve(run, p, replay.rack, replay.time_s, rtol=rtol, atol_factor=factor).torque_Nm

    converged = solved(1e-10, 0.01)
    errors = {s: solved(*s) - converged for s in SETTINGS}
    times = {s: [] for s in SETTINGS}
    for _ in range(args.repeats):
        for s in SETTINGS:
            start = time.perf_counter()
            solved(*s)
            times[s].append(time.perf_counter() - start)
    shipped = statistics.median(times[SETTINGS[0]])
    print(f"{args.file}: {len(converged)} samples, torque range {np.ptp(converged):.1f} N m; medians of "
          f"{args.repeats}; bus resolution {BUS_RESOLUTION_NM} N m")
    print(f"{'rtol':>8} {'atol x':>7} {'ms':>7} {'ratio':>6} {'max err N m':>12} {'RMS err N m':>12}")
    for s in SETTINGS:
        t, e = statistics.median(times[s]), errors[s]
        print(f"{s[0]:8.0e} {s[1]:7.0f} {1e3 * t:7.2f} {t / shipped:6.2f} {np.max(np.abs(e)):12.5f} "
              f"{np.sqrt(np.mean(e * e)):12.5f}" + ("   (shipped)" if s == SETTINGS[0] else ""))


if __name__ == "__main__":
    main()
