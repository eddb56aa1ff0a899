"""Check (not a test, not timed): do two trees give the same diagnosis JSON, byte for byte but the timings?

    python benchmarks/compare_diagnosis_json.py REFERENCE_SRC [--jobs N] [--case NAME ...]

Runs each case below with this tree's ``src`` and with REFERENCE_SRC (e.g. ``git archive main`` unpacked) first on
the path, in fresh interpreters, from the repository's root, and compares the JSON each prints with its cost
(``cost``: wall times, which differ from run to run) left out. Prints one line per case, ``same`` or the keys that
differ, and exits 1 when any differs. A speed change that leaves every diagnosis's bits alone passes here; one that
does not shows which numbers moved (and ``--show`` prints them).

The cases: the README's example; an assisted record (docs/assist_diagnosis.md); an angle-only record (a raw CAN log
decoded with the car's DBC: the rack derived from the handwheel angle, docs/bus.md); and a diagnosis against the
car's baseline (README.md), the baseline learnt in memory from the healthy record.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
POLO = ["--vehicle", "data/vehicles/polo_vi.toml", "--with-assist"]
CASES = {
    "manual": ["data/measurements/example_unladen.csv"],
    "assisted": ["data/measurements/example_polo_assisted.csv", *POLO],
    "angle_only": ["data/samples/polo_kerb.log", "--bus", "vw_mqb", *POLO, "--case", "kerb", "--surface", "ground"],
    "baseline": ["data/samples/polo_drag.csv", *POLO, "--baseline", "data/samples/polo_baseline.csv"],
}


def diagnosis(src: Path, args: list[str], jobs: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(src)}
    out = subprocess.run([sys.executable, "-m", "parksteer.cli", "diagnose", *args, "--json", "--quiet",
                          "--jobs", str(jobs)], cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    result = json.loads(out.stdout)
    result.pop("cost", None)
    return result


def differences(a, b, path: str = "") -> list[str]:
    """The paths where `a` and `b` differ (a float compared by its repr, so by its bits)."""
    if isinstance(a, dict) and isinstance(b, dict):
        keys = sorted(set(a) | set(b))
        return [d for k in keys for d in differences(a.get(k), b.get(k), f"{path}.{k}")]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in differences(x, y, f"{path}[{i}]")]
    return [] if json.dumps(a) == json.dumps(b) else [path or "."]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reference", type=Path, help="the other tree's src")
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--case", action="append", choices=sorted(CASES), help="only these cases (repeatable)")
    parser.add_argument("--show", action="store_true", help="print the differing values")
    args = parser.parse_args(argv)
    failed = False
    for name in args.case or CASES:
        mine = diagnosis(ROOT / "src", CASES[name], args.jobs)
        theirs = diagnosis(args.reference.resolve(), CASES[name], args.jobs)
        same_bytes = json.dumps(mine, sort_keys=True) == json.dumps(theirs, sort_keys=True)
        found = differences(mine, theirs)
        print(f"{name:<12} {'same' if same_bytes else f'{len(found)} values differ: ' + ', '.join(found[:8])}")
        if args.show:
            for path in found:
                print(f"    {path}")
        failed |= not same_bytes
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
