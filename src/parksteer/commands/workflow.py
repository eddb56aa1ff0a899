"""``parksteer plan`` and ``parksteer repair``: what the Snakemake workflow reads, and what it needs repaired.

``plan`` writes workflow/code_inputs.yaml, the package files each workflow script can run, which the rules list as
inputs (``--check`` only says whether it is current). ``repair`` removes damaged outputs and what killed runs left
(parksteer.outputs), so that the next ordinary ``snakemake`` run rebuilds them; CI runs it before the pipeline.
"""

from __future__ import annotations

from pathlib import Path


def register(sub) -> None:
    p = sub.add_parser("plan", help="write workflow/code_inputs.yaml (the package files each rule's script runs)")
    p.add_argument("--root", default=".", help="the checkout (default: the working directory)")
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 if the file is not current")
    p.set_defaults(func=_plan)

    p = sub.add_parser("repair", help="remove damaged outputs and leftovers of killed runs, so the next run rebuilds them")
    p.add_argument("--root", default=".", help="the checkout (default: the working directory)")
    p.set_defaults(func=_repair)


def _plan(args) -> int:
    from ..code_inputs import DECLARATION, render, stale_scripts, trace
    from ..errors import UsageError
    from ..tables import atomic_path

    root = Path(args.root)
    if not (root / "workflow" / "Snakefile").is_file():
        raise UsageError(f"{root}: not a parksteer checkout (no workflow/Snakefile)")
    target = root / DECLARATION
    if args.check:
        stale = stale_scripts(root)
        for script in stale:
            print(f"{target}: the entry of {script} is not current")
        if stale:
            print("run `parksteer plan` and commit the file")
            return 1
        print(f"{target}: current")
        return 0
    inputs = trace(root)
    with atomic_path(target) as scratch:
        scratch.write_text(render(inputs), encoding="utf-8")
    print(f"{target}: {len(inputs)} scripts, {len({f for files in inputs.values() for f in files})} package files")
    return 0


def _repair(args) -> int:
    from ..outputs import repair

    lines, checked = repair(args.root)
    for line in lines:
        print(line)
    print(f"{checked} outputs read, {sum(line.startswith('removed') for line in lines)} removed")
    return 0
