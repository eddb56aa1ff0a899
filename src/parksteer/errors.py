"""Errors a user can act on. The command line prints each as one line and exits with status 2."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from os import PathLike


class UsageError(ValueError):
    """Bad input from the user (arguments, files, values); the message is one line."""


class SolverError(UsageError):
    """The integrator gave up (a stiff or absurd set of values); the message names the time it failed at.

    `t_failed_s` is the last time the integrator reached; callers that know the case and the values add them.
    """

    def __init__(self, message: str, t_failed_s: float | None = None):
        super().__init__(message)
        self.t_failed_s = t_failed_s


def cannot_read(path: str | PathLike, exc: OSError) -> str:
    """The one-line message of a file that cannot be read: its path and the system's reason."""
    return f"{path}: cannot read ({exc.strerror})"


def cannot_read_as(path: str | PathLike, what: str, problem: str) -> str:
    """The one-line message of a file a reader cannot read as its format `what`: its path and the reader's
    `problem`."""
    return f"{path}: cannot read as {what} ({problem})"


@contextmanager
def naming(where: str | PathLike) -> Iterator[None]:
    """Prefix a :class:`UsageError` raised inside with `where` (a file), unless the message names it already."""
    try:
        yield
    except UsageError as exc:
        text = str(exc)
        if text.startswith(f"{where}"):
            raise
        new = UsageError(f"{where}: {text}")
        if isinstance(exc, SolverError):
            new = SolverError(f"{where}: {text}", exc.t_failed_s)
        raise new from None
