"""Independent replays of a diagnosis run side by side, and what the diagnosis says while it runs.

The replays of a diagnosis that do not depend on each other (the racks of the replay ensemble,
the candidates' signatures, the refits of the best-scored candidates, the files of one
prediction) are spread over worker processes by :func:`fork_map`. The workers are forked from
the diagnosing process, so they start with its compiled models, files and fits, and each runs
exactly the computation the process would have run itself: the results are the same, in the
same order, whatever the number of workers. Only plain results (arrays, numbers) travel back.
A worker never forks again (:func:`fork_map` inside a worker runs in line).

Where the platform cannot fork (Windows, or ``workers`` <= 1), everything runs in line.

:class:`Progress` writes one line per step of a diagnosis to stderr (unless quiet), so that a
long diagnosis says where it is.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from collections.abc import Callable, Sequence
from typing import Any
from ..progress import note

_TASK: tuple[Callable[[Any], Any], Sequence[Any]] | None = None
_IN_WORKER = False


def available_workers() -> int:
    """The CPUs this process may run on (its affinity where the platform tells it)."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return max(os.cpu_count() or 1, 1)


def can_fork() -> bool:
    return "fork" in multiprocessing.get_all_start_methods()


def mark_worker() -> None:
    """Called in each worker as it starts: a worker runs every further map in line."""
    global _IN_WORKER
    _IN_WORKER = True


def in_worker() -> bool:
    return _IN_WORKER


def forks(count: int, workers: int) -> bool:
    """Whether :func:`fork_map` of `count` items on `workers` workers runs in worker processes."""
    return min(workers, count) > 1 and not _IN_WORKER and can_fork()


def worker_pool(workers: int):
    """A pool of `workers` processes forked from this one (close it when done), or None where it would not fork."""
    if not forks(workers, workers):
        return None
    return multiprocessing.get_context("fork").Pool(workers, initializer=mark_worker)


def _run(index: int):
    mark_worker()
    function, items = _TASK
    return function(items[index])


def fork_map(function: Callable[[Any], Any], items: Sequence[Any], workers: int) -> list:
    """``[function(item) for item in items]``, on up to `workers` forked processes (module docstring).

    `function` may be a closure over anything in this process (it is inherited, never pickled); its
    results must pickle.
    """
    global _TASK
    items = list(items)
    if not forks(len(items), workers):
        return [function(item) for item in items]
    workers = min(workers, len(items))
    _TASK = (function, items)
    try:
        with multiprocessing.get_context("fork").Pool(workers) as pool:
            return pool.map(_run, range(len(items)), chunksize=1)
    finally:
        _TASK = None


class Progress:
    """One line per step on stderr: ``diagnose: <step> ... (<seconds> s)``; nothing when quiet."""

    def __init__(self, quiet: bool = False, stream=None):
        self.quiet = quiet
        self.stream = stream
        self.start = time.perf_counter()

    def __call__(self, message: str) -> None:
        if self.quiet:
            return
        line = f"diagnose: {message} ({time.perf_counter() - self.start:.1f} s)"
        if self.stream is None:
            note(line)  # the package's one progress channel (stderr, a rule's log)
        else:
            print(line, file=self.stream, flush=True)
