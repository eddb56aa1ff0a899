"""The ``parksteer`` command line.

Each subcommand lives in the module that owns its logic and exposes
``register(subparsers)``; this file only lists those modules. A
:class:`~parksteer.errors.UsageError` (bad argument, bad file, bad value) is printed as
one line on stderr with exit status 2, and no output file is written.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .errors import UsageError

# Modules that add subcommands, in the order they appear in --help.
COMMAND_MODULES = [
    "parksteer.commands.pipeline",
    "parksteer.commands.model",
    "parksteer.commands.sweep",
    "parksteer.commands.measure",
]


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, status 2, like every other usage error
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="parksteer", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


# Options whose value may start with "-" (an effects spec such as "-rack_friction,+hooke_joint").
DASH_VALUE_OPTIONS = ("--effects",)


def _join_dash_values(argv: list[str]) -> list[str]:
    """Rewrite ``--effects -x`` as ``--effects=-x`` so argparse does not read the spec as an option."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        if argv[i] in DASH_VALUE_OPTIONS and i + 1 < len(argv) and argv[i + 1].startswith("-"):
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
        else:
            out.append(argv[i])
            i += 1
    return out


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(_join_dash_values(sys.argv[1:] if argv is None else list(argv)))
    try:
        return int(args.func(args) or 0)
    except UsageError as exc:
        print(f"parksteer {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
