"""``parksteer check-params``: validate a parameter file."""

from __future__ import annotations

from ..parameters import DEFAULT_PATH, load_parameters


def register(sub) -> None:
    p = sub.add_parser("check-params", help="validate a parameter file against the schema")
    p.add_argument("path", nargs="?", default=str(DEFAULT_PATH))
    p.set_defaults(func=_check_params)
    register_checksums(sub)


def _check_params(args) -> int:
    params = load_parameters(args.path)
    n = sum(len(s) for s in params.sections.values()) + sum(len(c) for c in params.cases.values())
    print(f"{args.path}: {n} values valid; cases: {', '.join(params.case_names)}")
    return 0


def register_checksums(sub) -> None:
    p = sub.add_parser("checksums", help="verify or refresh figures/SHA256SUMS")
    p.add_argument("action", choices=["verify", "refresh"])
    p.add_argument("files", nargs="+", help="figure and data files (paths relative to --root)")
    p.add_argument("--sums", default="figures/SHA256SUMS")
    p.add_argument("--root", default=".")
    p.add_argument("--report", help="write the verification result here as well")
    p.set_defaults(func=_checksums)


def _checksums(args) -> int:
    from pathlib import Path

    from ..checksums import refresh, verify
    from ..errors import UsageError
    from ..tables import atomic_path

    root, sums = Path(args.root), Path(args.root) / args.sums
    if args.action == "refresh":
        refresh(root, sums, args.files)
        print(f"{sums}: {len(args.files)} sums written; reference data in {sums.parent / 'reference'}")
        return 0
    if not sums.exists():
        raise UsageError(f"{sums}: no stored checksums (run: snakemake --cores 2 refresh_checksums)")
    problems = verify(root, sums, args.files)
    for line in problems:
        print(line)
    summary = f"{len(args.files) - len(problems)} passed, {len(problems)} failed"
    print(summary)
    if args.report and not problems:
        with atomic_path(args.report) as tmp:
            tmp.write_text(summary + "\n", encoding="utf-8")
    return 1 if problems else 0
