"""Subcommands of the ``parksteer`` command line, one module per group.

Options shared by subcommands are added here, so that one option means one thing in every subcommand.
"""

QUIET_HELP = "no progress lines on stderr (what is being computed, how long it took)"


def add_quiet_option(parser) -> None:
    """``--quiet`` of a long-running subcommand: progress goes to stderr unless it is given (the command line
    applies it before the subcommand runs, parksteer.cli.main)."""
    parser.add_argument("--quiet", action="store_true", help=QUIET_HELP)
