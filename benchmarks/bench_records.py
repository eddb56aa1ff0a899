"""Seconds of `parksteer compare` per second of record, at 50 Hz, 1 kHz and 10 kHz.

The example record (data/measurements/example_unladen.csv, 50 Hz, 18 s) is resampled by linear interpolation to
each rate, with white noise of the logger's size added so the fast records are not smoother than real ones, and
written as a native CSV. Each rate is run REPEATS times in a fresh process; the median wall time divided by the
record's duration is the rate, and the ratio to the 50 Hz rate shows what the sample rate costs. Run:

    PYTHONPATH=src python benchmarks/bench_records.py

Measured on the 2-core development machine (shared, `nice`), medians of 3: 0.197 s per record-second at 50 Hz,
0.426 at 1 kHz, 0.468 at 10 kHz (ratios to 50 Hz: 2.17 and 2.38; the faster records are decimated to 100 Hz,
twice the 50 Hz record's samples). A 10 kHz `diagnose` of the same 18 s record took 21.5 s, against 20.4 s at 50 Hz.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "data" / "measurements" / "example_unladen.csv"
RATES_HZ = (50, 1000, 10000)
REPEATS = 3


def write_record(path: Path, rate_hz: float) -> float:
    lines = EXAMPLE.read_text(encoding="utf-8").splitlines()
    meta = [line for line in lines if line.startswith("#") and "sample_rate" not in line]
    rest = [line for line in lines if line.strip() and not line.startswith("#")]
    header = rest[0].split(",")
    data = np.array([[float(c) for c in row.split(",")] for row in rest[1:]])
    t = np.arange(data[0, 0], data[-1, 0], 1.0 / rate_hz)
    rng = np.random.default_rng(1)
    cols = [t] + [np.interp(t, data[:, 0], data[:, j]) for j in range(1, data.shape[1])]
    cols[2] = cols[2] + rng.normal(0.0, 0.05, len(t))  # torque noise, N m
    body = "\n".join(",".join(f"{v:.7g}" for v in row) for row in zip(*cols))
    path.write_text("\n".join(meta + [",".join(header)]) + "\n" + body + "\n", encoding="utf-8")
    return float(t[-1] - t[0])


def main() -> None:
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for rate in RATES_HZ:
            path = Path(tmp) / f"record_{rate}.csv"
            duration = write_record(path, rate)
            times = []
            for _ in range(REPEATS):
                start = time.perf_counter()
                subprocess.run([sys.executable, "-m", "parksteer.cli", "compare", str(path)], check=True,
                               capture_output=True)
                times.append(time.perf_counter() - start)
            results[rate] = statistics.median(times) / duration
            print(f"{rate:>6} Hz: {duration:.1f} s record, median {statistics.median(times):.2f} s "
                  f"-> {results[rate]:.3f} s per record-second")
    for rate in RATES_HZ[1:]:
        print(f"{rate} Hz / {RATES_HZ[0]} Hz: {results[rate] / results[RATES_HZ[0]]:.2f}")


if __name__ == "__main__":
    main()
