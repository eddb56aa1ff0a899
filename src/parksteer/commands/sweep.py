"""``parksteer sweep``: expand a design sweep, run one of its points, or gather its outputs.

The pipeline runs a sweep in batches of points, one Snakemake job per batch (workflow/rules/sweep.smk);
these subcommands give the same steps by hand, e.g. to rerun one failed point of a cluster run.
"""

from __future__ import annotations

import json
import sys

from ..parameters import DEFAULT_PATH, load_parameters
from . import add_quiet_option


def register(sub) -> None:
    p = sub.add_parser("sweep", help="design sweeps: expand a declaration, run a point, gather the maps")
    actions = p.add_subparsers(dest="sweep_action", required=True, parser_class=type(p))

    q = actions.add_parser("expand", help="validate a sweep declaration and list its points")
    q.add_argument("declaration", help="sweep YAML, e.g. config/sweeps/design.yaml")
    q.add_argument("--full", action="store_true", help="the declaration's full_axes (the large sweep)")
    q.add_argument("--json", action="store_true", help="print JSON instead of one line per point")
    q.add_argument("--parameters", default=str(DEFAULT_PATH))
    q.set_defaults(func=_expand)

    q = actions.add_parser("point", help="simulate one point (as its pipeline job does) and write its JSON")
    q.add_argument("declaration")
    q.add_argument("point", help="point id as listed by `parksteer sweep expand`")
    q.add_argument("--out", required=True, help="output JSON")
    q.add_argument("--full", action="store_true")
    q.add_argument("--parameters", default=str(DEFAULT_PATH))
    add_quiet_option(q)
    q.set_defaults(func=_point)

    q = actions.add_parser("gather", help="write the table, key numbers and torque maps from point JSONs")
    q.add_argument("declaration")
    q.add_argument("points", nargs="+", help="point JSON files (or the pipeline's batch files)")
    q.add_argument("--svg", required=True)
    q.add_argument("--csv", required=True)
    q.add_argument("--json", required=True)
    q.add_argument("--full", action="store_true")
    q.add_argument("--parameters", default=str(DEFAULT_PATH))
    add_quiet_option(q)
    q.set_defaults(func=_gather)


def _expand(args) -> int:
    from ..sweep import load_sweep

    sweep = load_sweep(args.declaration, load_parameters(args.parameters), full=args.full)
    if args.json:
        json.dump([sweep.point_spec(i) for i in sweep.point_ids], sys.stdout, indent=1)
        sys.stdout.write("\n")
        return 0
    for point in sweep.points:
        values = " ".join(f"{k}={v:g}" for k, v in point.values.items())
        print(f"{point.id} {values}")
    print(f"{sweep.name}: {len(sweep.points)} points{' (full)' if sweep.full else ''}", file=sys.stderr)
    return 0


def _point(args) -> int:
    from ..sweep import load_sweep
    from ..sweep.run import run_point

    sweep = load_sweep(args.declaration, load_parameters(args.parameters), full=args.full)
    run_point(sweep.point_spec(args.point), args.parameters, args.out)
    return 0


def _gather(args) -> int:
    from ..figures.sweep import make_sweep_figure

    make_sweep_figure(args.declaration, args.parameters, args.points, args.svg, args.csv, args.json, full=args.full)
    return 0
