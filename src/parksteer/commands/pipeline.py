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
    p = sub.add_parser("checksums", help="verify or refresh figures/SHA256SUMS",
                       description="verify: say for each file whether it is identical to its stored sum, within "
                                   "its figure family's tolerance (docs/reproducibility.md) or changed; fail on "
                                   "changed (and with --strict on within tolerance). refresh: write the sums, the "
                                   "reference copies and figures/PLATFORM.json.")
    p.add_argument("action", choices=["verify", "refresh"])
    p.add_argument("files", nargs="+", help="figure and data files (paths relative to --root)")
    p.add_argument("--sums", default="figures/SHA256SUMS")
    p.add_argument("--root", default=".")
    p.add_argument("--report", help="write the verification result here as well (when it passes)")
    p.add_argument("--strict", action="store_true",
                   help="fail on a file within tolerance too: only byte-identical figures pass (CI)")
    p.add_argument("--complete", action="store_true",
                   help="the files given are every file the pipeline makes: a stored sum without one is reported "
                        "(the verify rule); without it only the files given are checked")
    p.set_defaults(func=_checksums)


def _checksums(args) -> int:
    from pathlib import Path

    from ..checksums import failures, refresh, summary, verify
    from ..errors import UsageError
    from ..tables import atomic_path

    root, sums = Path(args.root), Path(args.root) / args.sums
    if args.action == "refresh":
        refresh(root, sums, args.files)
        print(f"{sums}: {len(args.files)} sums written; reference data and drawings in {sums.parent / 'reference'}, "
              f"the platform in {sums.parent / 'PLATFORM.json'}")
        return 0
    if not sums.exists():
        raise UsageError(f"{sums}: no stored checksums (run: snakemake --cores 2 refresh_checksums)")
    checks = verify(root, sums, args.files, complete=args.complete)
    failing = failures(checks, strict=args.strict)
    lines = [check.line for check in checks]
    lines.append(summary(checks) + (" (strict: only identical passes)" if args.strict else ""))
    if failing:
        lines.append(f"verification failed: {len(failing)} file(s) "
                     + ("not identical" if args.strict else "changed"))
    print("\n".join(lines))
    if args.report and not failing:
        with atomic_path(args.report) as tmp:
            tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return 1 if failing else 0
