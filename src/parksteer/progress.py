"""Progress of the long steps (derivation, code generation, compilation, a rule's run) on stderr: what is being
computed, how long it took, its key numbers. ``--quiet`` silences it; a Snakemake rule sends stderr to its log
(:func:`parksteer.rules.rule_log`), so each rule's log holds the same lines."""

from __future__ import annotations

import sys
import time
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Iterator

# Whether the progress lines are silenced, held by the running context (a forked worker inherits its parent's).
QUIET: ContextVar[bool] = ContextVar("parksteer_progress_quiet", default=False)


def set_quiet(quiet: bool) -> None:
    """Silence (True) or restore (False) the progress lines of the current context."""
    QUIET.set(bool(quiet))


@contextmanager
def quiet_while(quiet: bool) -> Iterator[None]:
    """Silence the progress lines inside the block when `quiet` (a subcommand's ``--quiet``), then restore what
    was set before it (a command run in-process, as the tests run them, leaves the next one as it found it)."""
    token = QUIET.set(QUIET.get() or bool(quiet))
    try:
        yield
    finally:
        QUIET.reset(token)


def note(message: str) -> None:
    """One progress line on the current stderr (looked up at each call: a rule redirects it to its log), written
    whole in one call, so that processes sharing the stream (a diagnosis's builders and workers) never split a line."""
    if not QUIET.get():
        sys.stderr.write(message + "\n")
        sys.stderr.flush()


@contextmanager
def step(what: str) -> Iterator[None]:
    """Note `what` when it starts and how long it took when it ends (or that it failed)."""
    note(f"{what} ...")
    start = time.perf_counter()
    try:
        yield
    except BaseException:
        note(f"{what}: failed after {time.perf_counter() - start:.2f} s")
        raise
    note(f"{what}: {time.perf_counter() - start:.2f} s")
