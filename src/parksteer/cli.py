"""The ``parksteer`` command line.

Each subcommand lives in the module that owns its logic and exposes
``register(subparsers)``; this file only lists those modules. A
:class:`~parksteer.errors.UsageError` (bad argument, bad file, bad value) is printed as
one line on stderr with exit status 2, and no output file is written.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from importlib import metadata

from .commands import add_quiet_option
from .commands.effect_files import effect_files_checked
from .errors import UsageError
from .progress import quiet_while

# Modules that add subcommands, in the order they appear in --help.
COMMAND_MODULES = [
    "parksteer.commands.pipeline",
    "parksteer.commands.workflow",
    "parksteer.commands.model",
    "parksteer.commands.sweep",
    "parksteer.commands.measure",
    "parksteer.commands.vehicle",
    "parksteer.commands.assist",
]


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, status 2, like every other usage error
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="parksteer", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    _quiet_everywhere(parser)
    return parser


def _quiet_everywhere(parser: argparse.ArgumentParser) -> None:
    """Give every subcommand ``--quiet`` (a command with no progress lines takes it too, so that one option works
    across a script of commands), where its module did not add it."""
    groups = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not groups:
        if not any("--quiet" in a.option_strings for a in parser._actions):
            add_quiet_option(parser)
        return
    for child in groups[0].choices.values():
        _quiet_everywhere(child)


def _version() -> str:
    """The installed distribution's version (pyproject.toml is its one source)."""
    try:
        return metadata.version("parksteer")
    except metadata.PackageNotFoundError:  # run from src/ on the path, never installed
        return "unknown (not installed)"


# Options whose value may start with "-" (an effects spec such as "-rack_friction,+hooke_joint", boost points
# such as "-0.5:0,...", refused by the table's own check with its reason rather than by argparse).
DASH_VALUE_OPTIONS = ("--effects", "--assist-boost")


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
        with quiet_while(getattr(args, "quiet", False)):  # --quiet means the same in every subcommand that has it
            with effect_files_checked(getattr(args, "effects", None),  # a user's effect files, at the door
                                      {"--suggest-effect": getattr(args, "suggest_effect", None)}):
                status = int(args.func(args) or 0)
        sys.stdout.flush()  # a closed pipe shows here, inside the handler, not at interpreter exit
        return status
    except UsageError as exc:
        print(f"parksteer {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader went away (`parksteer sweep expand ... | head`). As the Python docs advise for SIGPIPE:
        # point stdout at devnull so the flush at exit cannot raise again, and end quietly.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
