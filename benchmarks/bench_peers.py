"""The diagnosis against its peers outside the DAG (not a test): run the comparison, print the table.

    python benchmarks/bench_peers.py OUT_FOLDER [--records results/diagnose] [--jobs 2] [--table-only]

The logic is :mod:`parksteer.experiments.peers`. The evaluation records are those the variation and out-of-class
benchmarks wrote under ``--records``
(``variations/*/`` and ``outclass/*/``, each case's truth beside its folder of files: run the DAG's
``diag_variations`` and ``diag_outclass`` first); the tuning split is made here, the variation grid of
config/config.yaml with the seed ``peers.tuning_seed``. Each case's result goes to
OUT_FOLDER/<split>/<split>__<case>.peers.json (a case already there is not run again: ``--table-only`` runs none).
Then each peer is tuned on the tuning split,
and the table prints per method: hidden library effects named, nulls called adequate, what the out-of-class rivals
were called, confident wrong answers, and the median time per record (a peer's own, and with the calibration and
signatures it needs, which the diagnosis computes); then every peer setting's tuning score.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _jobs(records: Path, design) -> list[tuple[str, str]]:
    from parksteer.experiments.variations import case_names

    jobs = [("tuning", f"tuning:{name}") for name in case_names(design)]
    for kind in ("variations", "outclass"):
        for truth in sorted((records / kind).glob("*/*.truth.json")):
            jobs.append(("evaluation", f"{kind}:{truth}"))
    return jobs


def _run(item) -> str:
    out, job, tuning_seed = item
    import yaml

    from parksteer.experiments.peers import run_peer_batch, tuning_design
    from parksteer.experiments.variations import VariationDesign
    from parksteer.parameters import DEFAULT_PATH

    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text(encoding="utf-8"))
    design = VariationDesign.from_config(config["variations"])
    run_peer_batch(DEFAULT_PATH, [job], out, tuning_design(design, tuning_seed))
    return job


def table(comparison: dict) -> str:
    lines = [f"{comparison['records']['evaluation']} evaluation records; peers tuned on "
             f"{comparison['records']['tuning']} records of another seed",
             f"{'method':32s} {'setting':28s} {'named':>7s} {'nulls ok':>8s} {'closest/rel':>11s} {'unrel':>5s} "
             f"{'unexpl':>6s} {'adeq':>4s} {'conf.wrong':>10s} {'s/record':>9s} {'+upstream':>9s} {'replays':>7s} "
             f"{'+upstream':>9s}"]
    for r in comparison["methods"]:
        o = r["outclass"]
        lines.append(f"{r['label']:32s} {r['setting'] or '':28s} {r['named'][0]:>3d}/{r['named'][1]:<3d} "
                     f"{r['null_adequate'][0]:>4d}/{r['null_adequate'][1]:<3d} {o['closest or related']:>11d} "
                     f"{o['unrelated']:>5d} {o['unexplained']:>6d} {o['adequate']:>4d} "
                     f"{r['confident_wrong']:>5d}/{r['outclass_rivals']:<4d} {r['time_s_median']:>9.3g} "
                     f"{r['time_with_upstream_s_median']:>9.3g} {r['replays_median']:>7} "
                     f"{r['replays_with_upstream_median']:>9}")
    lines.append("where a peer wins: " + ("; ".join(comparison["peer_wins"]) or "nowhere"))
    for method, grid in comparison["grids"].items():
        lines.append(f"{method} tuning (score: mean of named rate and nulls adequate), best {grid['best']}:")
        lines.append("  " + "  ".join(f"{row['setting']} {row['score']:.2f}" for row in grid["tuning"]))
        spread = grid["tied_best_evaluation"]
        lines.append(f"  tied at the best score: {', '.join(grid['tied_best'])}; on the evaluation records they name "
                     f"{spread['named'][0]}-{spread['named'][1]}, call {spread['null_adequate'][0]}-"
                     f"{spread['null_adequate'][1]} nulls adequate, {spread['confident_wrong'][0]}-"
                     f"{spread['confident_wrong'][1]} confident wrong")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="folder for the cases' results")
    parser.add_argument("--records", default=str(ROOT / "results" / "diagnose"),
                        help="the benchmarks' output folder (holds variations/ and outclass/)")
    parser.add_argument("--jobs", type=int, default=1, help="cases run side by side")
    parser.add_argument("--table-only", action="store_true", help="run no case: the table of those done")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT / "src"))
    import yaml

    from parksteer.experiments.peer_scoring import compare, read_cases
    from parksteer.experiments.peers import peers_file_name
    from parksteer.experiments.variations import VariationDesign

    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text(encoding="utf-8"))
    design = VariationDesign.from_config(config["variations"])
    out = Path(args.out)
    todo = []
    for split, job in _jobs(Path(args.records), design):
        name = Path(job.partition(":")[2]).name.split(".")[0]
        if not (out / split / peers_file_name(split, name)).exists() and not args.table_only:
            todo.append((str(out / split), job, config["peers"]["tuning_seed"]))
    if todo:
        from multiprocessing import get_context

        with get_context("fork").Pool(max(1, args.jobs)) as pool:
            for done in pool.imap_unordered(_run, todo):
                print("done", done, flush=True)
    comparison = compare(read_cases(sorted(out.glob("*/*.peers.json"))))
    (out / "comparison.json").write_text(json.dumps(comparison, indent=1), encoding="utf-8")
    print(table(comparison))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
