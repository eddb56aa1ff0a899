"""The assisted benchmark outside the DAG (not a test): records of an assisted car diagnosed, the table printed.

    python benchmarks/bench_assisted.py OUT.json [--vehicle data/vehicles/polo_vi.toml] [--only NAME,NAME]

The logic is :mod:`parksteer.experiments.assisted_benchmark` (the design, the scoring and the targets are there).
Prints one line per case as it is diagnosed (what was hidden, its size in torsion-bar converter steps, the verdict,
the effect named and its group), then the targets: named rate, nulls called adequate, confident wrong answers out
of class; writes the summary and every case's outcome as JSON, with the wall time.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("--vehicle", default=str(ROOT / "data/vehicles/polo_vi.toml"), help="an assisted car's file")
    parser.add_argument("--only", default="", help="comma-separated case names (default: all)")
    args = parser.parse_args(argv)

    from parksteer.experiments.assisted_benchmark import AssistedDesign, run
    from parksteer.model.symbolic.components import discover_effects
    from parksteer.tables import write_json
    from parksteer.vehicle import load_vehicle

    discover_effects()
    params = load_vehicle(args.vehicle)
    design = AssistedDesign()

    def line(row: dict) -> None:
        said = row["verdict"] + (f" {row['effect']}" if row["effect"] else "")
        group = f" [{row['indistinguishable']}]" if row["indistinguishable"] else ""
        mark = {"hidden": "named" if row.get("named") else "MISSED",
                "outclass": "WRONG" if row.get("confident_wrong") else row.get("relation", ""),
                "null": "ok" if row["verdict"] == "adequate" else "FALSE ALARM"}[row["kind"]]
        print(f"{row['name']:<44} {row['steps']:5.2f} steps  {said:<32}{group}  {mark}  "
              f"({row['generation_s']:.1f} + {row['wall_s']:.1f} s)", flush=True)

    start = time.perf_counter()
    rows, summary = run(params, design, set(filter(None, args.only.split(","))), line)
    summary["wall_s"] = time.perf_counter() - start
    print()
    for key, target in summary["targets"].items():
        print(f"{key:<30} {target['value']!s:<22} target {target['target']}  {'met' if target['met'] else 'NOT MET'}"
              + (f"  {target['count']}" if "count" in target else ""))
    print(f"named by hidden effect: {summary['named_by_hidden']}; rack friction's interval holding the truth: "
          f"{summary['rack_friction_covered']}")
    print(f"nulls' calibrated error over floor: {summary['null_over_floor']}; wall {summary['wall_s']:.0f} s")
    write_json(args.out, {"summary": summary, "rows": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
