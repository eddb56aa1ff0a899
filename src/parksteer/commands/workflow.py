"""``parksteer repair``: what the Snakemake workflow's outputs need repaired.

``repair`` removes damaged outputs and what killed runs left (parksteer.outputs), so that the next ordinary
``snakemake`` run rebuilds them; CI runs it before the pipeline.
"""

from __future__ import annotations


def register(sub) -> None:
    p = sub.add_parser("repair", help="remove damaged outputs and leftovers of killed runs, so the next run rebuilds them")
    p.add_argument("--root", default=".", help="the checkout (default: the working directory)")
    p.set_defaults(func=_repair)


def _repair(args) -> int:
    from ..outputs import repair

    lines, checked = repair(args.root)
    for line in lines:
        print(line)
    print(f"{checked} outputs read, {sum(line.startswith('removed') for line in lines)} removed")
    return 0
