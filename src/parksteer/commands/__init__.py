"""Subcommands of the ``parksteer`` command line, one module per group.

Options shared by subcommands are added here, so that one option means one thing in every subcommand.
"""

from pathlib import Path

QUIET_HELP = "no progress lines on stderr (what is being computed, how long it took)"


def add_quiet_option(parser) -> None:
    """``--quiet`` of a long-running subcommand: progress goes to stderr unless it is given (the command line
    applies it before the subcommand runs, parksteer.cli.main)."""
    parser.add_argument("--quiet", action="store_true", help=QUIET_HELP)


def check_writable(option: str, value: str, folder: Path) -> None:
    """Refuse an output folder nothing can be written in before the work, not after it (a probe file is made and
    removed: permissions alone do not tell, e.g. for root or a read-only mount). `option` as the user wrote it
    (``--out``)."""
    import tempfile

    from ..errors import UsageError

    try:
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".parksteer-probe-"):
            pass
    except OSError as exc:
        raise UsageError(f"{option} {value}: cannot write in folder {folder} ({exc.strerror})") from None
