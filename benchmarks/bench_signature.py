"""The signature benchmark: out-of-library effects and nulls, diagnosed; the signature's class and the suggested
effect scored per signature class, and the time the signature and the suggestion add to one diagnosis.

    python benchmarks/bench_signature.py [--steps 5] [--nulls 4] [--seed 2411] [--first-variation 0] [--json OUT.json]

The grid (parksteer.experiments.outoflibrary.SignatureDesign): the twelve truth forms of
parksteer.synthetic.outoflibrary at each size, on the first six variations of the variation benchmark in
turn, and the nulls: 16 records by default, a few minutes on one core (each suggestion compiles its own model).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time

from parksteer.experiments.outoflibrary import AFTER_LIMIT, SignatureDesign, run_case, summarise
from parksteer.parameters import load_parameters


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=float, nargs="+", default=[5.0], help="truth sizes, converter steps RMS")
    parser.add_argument("--nulls", type=int, default=4)
    parser.add_argument("--seed", type=int, default=2411, help="hands, noise and base perturbation: seed + k")
    parser.add_argument("--first-variation", type=int, default=0,
                        help="the records take the six variations from this place of VARIATIONS on (0 or 6)")
    parser.add_argument("--only", nargs="*", help="case names to run (default: all)")
    parser.add_argument("--json", help="write the rows and the summary here")
    parser.add_argument("--keep", help="write the records into this folder (default: a temporary one)")
    args = parser.parse_args(argv)
    params = load_parameters()
    design = SignatureDesign(steps=tuple(args.steps), nulls=args.nulls, seed=args.seed,
                             first_variation=args.first_variation)
    cases = [c for c in design.cases() if not args.only or c.name in args.only]
    rows = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_signature_") as temporary:
        folder = args.keep or temporary
        for case in cases:
            row = run_case(params, case, design, folder)
            rows.append(row)
            after = "-" if row["after_over_floor"] is None else f"{row['after_over_floor']:.2f}"
            print(f"{row['name']:28s} {row['variation']:24s} truth {str(row['class']):11s} said "
                  f"{str(row['said_class']):11s} verdict {row['verdict']:11s} floors {row['calibrated_over_floor']:5.2f}"
                  f" -> {after:>5s}  sig {row['signature_s']:.2f} s  sugg {row['suggestion_s']:.1f} s",
                  file=sys.stderr, flush=True)
    summary = summarise(rows)
    print(f"\n{len(rows)} records ({summary['out_of_library']} out of library, {summary['nulls']} nulls), "
          f"{time.perf_counter() - start:.0f} s")
    print(f"{'class':12s} {'records':>7s} {'class right':>11s} {'or in group':>11s} {'within ' + str(AFTER_LIMIT):>10s}  said")
    for cls, t in summary["table"].items():
        print(f"{cls:12s} {t['records']:7d} {t['class_right']:11d} {t['class_in_group']:11d} {t['within']:10d}  "
              f"{', '.join(t['said'])}")
    print(f"class right {summary['class_right_rate']:.0%} (target 80 %), suggestion within {AFTER_LIMIT} floors "
          f"{summary['within_rate']:.0%} (target 70 %), suggestions on nulls: {summary['suggestions_on_nulls'] or 'none'}")
    t = summary["time_s"]
    print(f"median time per record: diagnosis {t['diagnosis_s']:.2f} s, signature {t['signature_s']:.2f} s, "
          f"suggestion {t['suggestion_s']:.1f} s (derivation and compilation of its model included)")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as out:
            json.dump({"rows": rows, "summary": summary}, out, indent=1, default=float)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
