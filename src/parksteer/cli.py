"""The ``parksteer`` command line.

Each subcommand lives in the module that owns its logic and exposes
``register(subparsers)``; this file only lists those modules. A
:class:`~parksteer.errors.UsageError` (bad argument, bad file, bad value) is printed as
one line on stderr with exit status 2, and no output file is written.

Ctrl-C (SIGINT, to the process or to its whole group, as a terminal sends it) or SIGTERM ends a subcommand with
one line on stderr and exit status 128 + the signal's number (130, 143), after what was running has stopped: the
diagnosis's worker processes end with it (:mod:`parksteer.diagnose.parallel`), and every output is written to a
temporary file renamed onto its name only when complete (:func:`parksteer.tables.atomic_path`), so none is left
half-written.
"""

from __future__ import annotations

import argparse
import atexit
import importlib
import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from .commands import add_quiet_option
from .commands.effect_files import effect_files_checked
from .diagnose.parallel import STOPPING_SIGNALS
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
    parser.add_argument("--version", action=_VersionAction)
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


class _VersionAction(argparse.Action):
    """``--version``: the installed version, read only when asked for (importlib.metadata is a twentieth of a second
    of every start, ``--help`` included)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest, nargs=0, default=default,
                         help=help or "show program's version number and exit")

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"{parser.prog} {_version()}")  # on stdout, as argparse's own version action
        parser.exit()


def _version() -> str:
    """The installed distribution's version (pyproject.toml is its one source)."""
    from importlib import metadata

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


class Interrupt:
    """What a stopping signal does while a subcommand runs (module docstring).

    In this process it raises KeyboardInterrupt where the work is, so that every ``finally`` on the way up ends what
    it started, and again at each signal until the command has said it was interrupted (the interpreter ignores an
    exception raised in some places, a destructor, a weakref callback or a fork hook, so one may be lost: the command
    then ends as interrupted once its modules have loaded, or when it is done; what must not be cut short,
    ending worker processes, holds the signals back: :func:`parksteer.diagnose.parallel.signals_held`). A process
    forked from this one that does not ignore the signal (a background model build:
    :func:`parksteer.model.codegen.cache.start_builds`) ends quietly through SystemExit, which removes its scratch
    files and kills the compiler it waits for."""

    def __init__(self) -> None:
        self.pid = os.getpid()
        self.received: int | None = None
        self.reported = False

    def __call__(self, signum, frame) -> None:
        if os.getpid() != self.pid:
            raise SystemExit(128 + signum)
        if self.received is None:
            self.received = signum
        if not self.reported:
            raise KeyboardInterrupt

    @property
    def lost(self) -> bool:
        """Whether a signal came and its KeyboardInterrupt has not reached the command (the interpreter ignored it)."""
        return self.received is not None and not self.reported

    def unraisable(self, hook):
        """`hook` (sys.unraisablehook), silent on this handler's own KeyboardInterrupt, which the interpreter reports
        as ignored when it is raised in a weakref callback or a destructor (:attr:`lost` then says so)."""
        def report(unraisable) -> None:
            if not (isinstance(unraisable.exc_value, KeyboardInterrupt) and self.received is not None):
                hook(unraisable)
        return report

    @property
    def status(self) -> int:
        return 128 + int(self.received or signal.SIGINT)

    @property
    def line(self) -> str:
        return "interrupted" if self.received in (None, signal.SIGINT) else "terminated"


@contextmanager
def stopped_by_signals() -> Iterator[Interrupt]:
    """Answer SIGINT and SIGTERM with :class:`Interrupt` inside the block, then restore the handlers (a command run
    in-process, as the tests run them, leaves the process as it found it). Only the main thread can set a handler;
    elsewhere the block runs with the handlers as they are."""
    interrupt = Interrupt()
    if threading.current_thread() is not threading.main_thread():
        yield interrupt
        return
    before = {number: signal.signal(number, interrupt) for number in STOPPING_SIGNALS}
    hook = sys.unraisablehook
    sys.unraisablehook = interrupt.unraisable(hook)
    try:
        yield interrupt
    finally:
        sys.unraisablehook = hook
        for number, handler in before.items():
            signal.signal(number, handler)


def main(argv: list[str] | None = None) -> int:
    with stopped_by_signals() as interrupt:
        try:  # the subcommands' modules are imported here: a Ctrl-C may come while they load
            args = build_parser().parse_args(_join_dash_values(sys.argv[1:] if argv is None else list(argv)))
        except KeyboardInterrupt:
            return _interrupted(None, interrupt)
        if interrupt.lost:  # raised where the interpreter ignores it, while the modules loaded
            return _interrupted(None, interrupt)
        try:
            return _run(args, interrupt)
        except KeyboardInterrupt:  # one that arrived after the command's own handling (while reporting an error)
            return _interrupted(args, interrupt)


def _interrupted(args, interrupt: Interrupt) -> int:
    interrupt.reported = True
    name = "parksteer" if args is None else f"parksteer {args.command}"
    print(f"{name}: {interrupt.line}", file=sys.stderr, flush=True)
    return interrupt.status


def _run(args, interrupt: Interrupt) -> int:
    try:
        with quiet_while(getattr(args, "quiet", False)):  # --quiet means the same in every subcommand that has it
            with effect_files_checked(getattr(args, "effects", None),  # a user's effect files, at the door
                                      {"--suggest-effect": getattr(args, "suggest_effect", None)}):
                status = int(args.func(args) or 0)
        sys.stdout.flush()  # a closed pipe shows here, inside the handler, not at interpreter exit
        if interrupt.lost:  # the command ran on past a signal the interpreter ignored: it still ends as stopped
            return _interrupted(args, interrupt)
        return status
    except KeyboardInterrupt:
        return _interrupted(args, interrupt)
    except BaseException as exc:
        # After a signal, whatever else went wrong is its consequence (a compiler killed by the same Ctrl-C).
        if interrupt.received is not None and not isinstance(exc, SystemExit):
            return _interrupted(args, interrupt)
        if isinstance(exc, UsageError):
            print(f"parksteer {args.command}: error: {exc}", file=sys.stderr)
            return 2
        if isinstance(exc, BrokenPipeError):
            # The reader went away (`parksteer sweep expand ... | head`). As the Python docs advise for SIGPIPE:
            # point stdout at devnull so the flush at exit cannot raise again, and end quietly.
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            return 1
        raise


def run_as_main() -> None:
    """The ``parksteer`` command and ``python -m parksteer.cli``: exit with :func:`main`'s status, running the exit
    functions and flushing stdout and stderr, then ending through ``os._exit`` without the interpreter's teardown.

    The teardown frees, module by module, what the process's end frees at once (some 0.05 s after a diagnosis, which
    imports over 400 modules); every file a command writes is closed where it is written, and the exit functions
    (the worker pools' finalizers, logging's) run here as they would at a normal exit. While a thread other than
    the main one is alive the interpreter exits as usual (it waits for such threads), and so it does under a profiler
    or a tracer (``python -m cProfile``, ``trace``), which writes what it found once the program returns. CPython also
    marks a KeyboardInterrupt that passed through an extension's ``PyRun`` call (as one may while the subcommands'
    modules load) as unhandled even once caught, and then ends a ``-m`` run by SIGINT whatever its status: through
    ``os._exit`` an interrupted command ends with its status."""
    status = main()
    interrupted = status in {128 + int(number) for number in STOPPING_SIGNALS}
    watched = sys.getprofile() is not None or sys.gettrace() is not None
    if interrupted or (threading.active_count() == 1 and not watched):
        atexit._run_exitfuncs()
        os._exit(_flushed(status))
    sys.exit(status)


def _flushed(status: int) -> int:
    """`status` once stdout and stderr are flushed; where that fails (a reader gone away, a closed stream), 120 in
    place of 0, as the interpreter's own exit gives."""
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):
            status = status or 120
    return status


if __name__ == "__main__":
    run_as_main()
