"""The variation benchmark outside the DAG (not a test): run its cases in a scratch folder, print the table.

    python benchmarks/bench_variations.py OUT.json [--full] [--only pauses,lock_overshoot] [--hidden kingpin_friction]
        [--confound-tests] [--sizes]

The logic is :mod:`parksteer.experiments.variations` (rules ``diag_variation_batch`` and ``diag_variations`` run
the same cases in the DAG); the grid is config/config.yaml's ``variations`` section (``--full``: its full grid).
Prints one line per case as it is diagnosed, then per variation the named rate, the nulls called adequate, the
coverage of the 95 % intervals, the nulls' calibrated error in noise floors and the median diagnosis time; writes
the summary and every case's outcome as JSON. With ``--sizes``, no record is made or diagnosed: each hidden case's
strength, its whole change and the part of it a calibration cannot absorb (to first order) are found, and per
hidden effect the median and range of that observable share are printed (a minute for the full grid). With
``--hidden``, only those effects are hidden (the angle's cases too). With ``--confound-tests``, the diagnoses name
where each confounded candidate would show (off in the DAG's benchmarks), and the summary counts, per hidden
effect, the measurements named for its misses flagged as confounded.
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("--full", action="store_true", help="the configuration's full grid")
    parser.add_argument("--only", default="", help="comma-separated variation names (default: the grid's)")
    parser.add_argument("--hidden", default="", help="comma-separated effects to hide (default: the grid's)")
    parser.add_argument("--confound-tests", action="store_true",
                        help="name where each confounded candidate would show, as a user's diagnosis does")
    parser.add_argument("--sizes", action="store_true", help="only the hidden sizes, whole and observable")
    args = parser.parse_args(argv)

    import yaml

    from parksteer.experiments.benchmark import BENCHMARK_SETTINGS
    from parksteer.diagnose.settings import DEFAULT_SETTINGS
    from parksteer.experiments.rows import as_dict
    from parksteer.experiments.variation_summary import outcome, summarise
    from parksteer.experiments.variations import VariationDesign, case_names, run_case
    from parksteer.parameters import DEFAULT_PATH
    from parksteer.tables import write_json

    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text("utf-8"))
    section = copy.deepcopy(config["variations"])
    section["full_grid"] = bool(args.full)
    grid = section["full" if args.full else "small"]
    if args.only:
        grid["variations"] = args.only.split(",")
    if args.hidden:
        grid["hidden"] = grid["hidden_with_angle"] = args.hidden.split(",")
    design = VariationDesign.from_config(section)
    if args.sizes:
        return _sizes(design, args.out)
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for name in case_names(design):
            folder = Path(scratch) / name
            folder.mkdir()
            start = time.perf_counter()
            result = run_case(DEFAULT_PATH, design, name, folder, folder / "truth.json", folder / "diagnosis.json",
                              DEFAULT_SETTINGS if args.confound_tests else BENCHMARK_SETTINGS)
            truth = json.loads((folder / "truth.json").read_text("utf-8"))
            row = outcome(truth, result)
            rows.append(row)
            print(f"{name:48s} -> {row.verdict:11s} {row.effect:16s} {row.calibrated_over_floor:5.2f} floors "
                  f"covered {row.covered}/{row.intervals}  diagnosis {row.wall_s:5.1f} s, "
                  f"case {time.perf_counter() - start:5.1f} s", file=sys.stderr, flush=True)
    summary = summarise(rows, design)
    write_json(args.out, {"summary": summary, "records": [as_dict(r) for r in rows]})
    print(f"{'variation':24s} {'named':>7s} {'adequate':>8s} {'cover':>7s} {'null/floor':>12s} {'time':>6s}")
    for v in summary["variations"]:
        print(f"{v['variation']:24s} {_count(v['named_count']):>7s} {_count(v['null_adequate_count']):>8s} "
              f"{_count(v['coverage_count']):>7s} {' '.join(f'{x:.2f}' for x in v['null_over_floor']):>12s} "
              f"{v['wall_s_median']:5.1f}s")
    for effect, h in summary["by_hidden"].items():
        if h.get("flagged_separated_by"):
            print(f"{effect}: {h['missed_flagged_confounded']} misses flagged confounded, would show in "
                  + ", ".join(f"{k} ({n})" for k, n in h["flagged_separated_by"].items()))
    for key, t in summary["targets"].items():
        print(f"{key:14s} {_count(t['count'])} = {t['value']:.3f} against {t['target']:.2f}: "
              f"{'met' if t['met'] else 'MISSED'}")
    return 0


def _sizes(design, out: str) -> int:
    """Each hidden case's whole and observable change (case_truth), and per hidden effect the observable share."""
    from parksteer.experiments.variation_summary import spread
    from parksteer.experiments.variations import case_truth, variation_cases
    from parksteer.parameters import load_parameters
    from parksteer.tables import write_json

    params = load_parameters()
    rows = []
    for case in variation_cases(design):
        if case.hidden is None:
            continue
        _files, truth = case_truth(params, design, case)
        rows.append({k: truth[k] for k in ("name", "variation", "hidden", "steps_requested", "steps",
                                           "steps_observable", "strength_key", "strength")})
        print(f"{case.name:48s} {truth['steps']:5.2f} steps, observable {truth['steps_observable']:5.2f}",
              file=sys.stderr, flush=True)
    table = {}
    for effect in dict.fromkeys(r["hidden"] for r in rows):
        share = [r["steps_observable"] / r["steps"] for r in rows if r["hidden"] == effect]
        table[effect] = {"records": len(share), **spread(share)}
        print(f"{effect:20s} {len(share):4d} records, observable share median {table[effect]['median']:.3f} "
              f"({table[effect]['min']:.3f}-{table[effect]['max']:.3f})")
    write_json(out, {"observable_share": table, "records": rows})
    return 0


def _count(kn) -> str:
    return f"{kn[0]}/{kn[1]}" if kn[1] else "-"


if __name__ == "__main__":
    sys.exit(main())
