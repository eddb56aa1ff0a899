"""Independent replays of a diagnosis run side by side, and what the diagnosis says while it runs.

The replays of a diagnosis that do not depend on each other (the racks of the replay ensemble,
the candidates' signatures, the refits of the best-scored candidates, the files of one
prediction) are spread over worker processes by :func:`fork_map`. The workers are forked from
the diagnosing process, so they start with its compiled models, files and fits, and each runs
exactly the computation the process would have run itself: the results are the same, in the
same order, whatever the number of workers. Only plain results (arrays, numbers) travel back.
A worker never forks again (:func:`fork_map` inside a worker runs in line).

Where the platform cannot fork (Windows, or ``workers`` <= 1), everything runs in line.

A worker ignores SIGINT (a terminal's Ctrl-C reaches the whole process group): the diagnosing process alone
answers it, by ending its workers (:meth:`ServingPool.terminate`, and :func:`fork_map` on any exception), so no
pool starts new workers in their place and none is waited for. Forking and ending workers happen with SIGINT and
SIGTERM held back (:func:`signals_held`): the interpreter ignores an exception raised in its fork hooks, which would
lose a Ctrl-C, and an interrupt half-way through ending a pool would leave its workers behind.

:class:`Progress` writes one line per step of a diagnosis to stderr (unless quiet), so that a
long diagnosis says where it is.
"""

from __future__ import annotations

import io
import multiprocessing
import os
import pickle
import signal
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any
from ..progress import note

def available_workers() -> int:
    """The CPUs this process may run on (its affinity where the platform tells it)."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return max(os.cpu_count() or 1, 1)


STOPPING_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held back inside the block and delivered when it ends (module docstring); where signals
    cannot be held (no pthread_sigmask, or not the main thread, which alone runs Python's handlers), as they are."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, STOPPING_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def can_fork() -> bool:
    return "fork" in multiprocessing.get_all_start_methods()


def forks(count: int, workers: int) -> bool:
    """Whether :func:`fork_map` of `count` items on `workers` workers runs in worker processes (never in a worker)."""
    return min(workers, count) > 1 and not in_worker() and can_fork()


# The attribute of a worker's process object (multiprocessing.current_process()) holding what it serves.
SERVE_ATTRIBUTE = "parksteer_serve"


class InheritedPickler(pickle.Pickler):
    """A pickler that writes each object of `inherited` (by identity) as its place in it, for a worker forked
    holding the same sequence to read back with :func:`loads_inherited`: a pool's tasks name the objects its
    workers inherited (a diagnosis's effects and their classes) so, and a class with no importable home (an effect
    loaded from a user's file, or made by a factory) reaches them without being registered anywhere by name."""

    def __init__(self, file, inherited: Sequence[Any]):
        super().__init__(file, protocol=pickle.HIGHEST_PROTOCOL)
        self.inherited = inherited
        self.places = {id(obj): place for place, obj in enumerate(inherited)}

    def persistent_id(self, obj):
        place = self.places.get(id(obj))
        return place if place is not None and self.inherited[place] is obj else None


class InheritedUnpickler(pickle.Unpickler):
    """Reads what :class:`InheritedPickler` wrote, each place taken from the worker's copy of `inherited`."""

    def __init__(self, file, inherited: Sequence[Any]):
        super().__init__(file)
        self.inherited = inherited

    def persistent_load(self, place):
        return self.inherited[place]


def dumps_inherited(obj: Any, inherited: Sequence[Any]) -> bytes:
    buffer = io.BytesIO()
    InheritedPickler(buffer, inherited).dump(obj)
    return buffer.getvalue()


def loads_inherited(data: bytes, inherited: Sequence[Any]) -> Any:
    return InheritedUnpickler(io.BytesIO(data), inherited).load()


def start_worker(serve: Callable[[Any], Any], inherited: Sequence[Any] = ()) -> None:
    """A pool worker's initializer: keep `serve` and `inherited` on the worker's own process object, where
    :func:`_serve` finds them for each task (multiprocessing sends a task's function by name, so the function a
    worker runs is found through an object the worker owns, not a closure). :func:`pool` forks its workers with
    both (a closure over anything in the forking process, and the objects tasks name by place: inherited, never
    pickled). The diagnosing process's own process object holds nothing, which is how :func:`in_worker` tells a
    worker, which never forks again, from the process that forked it."""
    # Ctrl-C is the forking process's to answer (module docstring); SIGTERM, which ends a pool's workers,
    # ends this one at once, even inside a solve, whatever handler it inherited
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, STOPPING_SIGNALS)  # held while the pool forked it
    setattr(multiprocessing.current_process(), SERVE_ATTRIBUTE, (serve, tuple(inherited)))


def in_worker() -> bool:
    """Whether this process is a pool worker serving a function (:func:`start_worker`)."""
    return getattr(multiprocessing.current_process(), SERVE_ATTRIBUTE, None) is not None


def _serve(task: bytes):
    serve, inherited = getattr(multiprocessing.current_process(), SERVE_ATTRIBUTE)
    return serve(loads_inherited(task, inherited))


def pool(workers: int, serve: Callable[[Any], Any], inherited: Sequence[Any] = ()):
    """A pool of `workers` processes forked from this one, each serving `serve` and holding `inherited`
    (:func:`start_worker`), or None where it would not fork. Map items over it with :func:`pool_map` and the same
    `inherited`; close it when done."""
    if not forks(workers, workers):
        return None
    with signals_held():
        return multiprocessing.get_context("fork").Pool(workers, initializer=start_worker,
                                                        initargs=(serve, tuple(inherited)))


def pool_map(workers_pool, items: Sequence[Any], inherited: Sequence[Any] = ()) -> list:
    """``[serve(item) for item in items]`` on the workers of `workers_pool` (:func:`pool`, forked holding
    `inherited`), in order."""
    tasks = [dumps_inherited(item, inherited) for item in items]
    return workers_pool.map(_serve, tasks, chunksize=1)


class ServingPool:
    """Up to `workers` worker processes that serve one function made for one key, forked when first asked.

    A worker holds what the forking process held when it was forked (a diagnosis's problem, its files, its
    replays): asked to serve another key, the pool ends its workers and forks new ones from the process as it is
    then, so no worker ever answers for a key it was not made for. Keys are compared by identity, and the pool
    holds the key it serves, so that key's identity cannot pass to another object meanwhile. Its workers hold
    `inherited` (objects an item may hold, e.g. a diagnosis's effect classes), sent by their place in it."""

    def __init__(self, workers: int, inherited: Sequence[Any] = ()):
        self.workers = workers
        self.inherited = tuple(inherited)
        self.key: Any = None
        self.pool = None

    def map(self, key: Any, serve: Callable[[Any], Any], items: Sequence[Any]) -> list | None:
        """``[serve(item) for item in items]`` on workers forked to serve `serve` for `key` (`serve` is used only
        when the pool forks: a pool already serving `key` serves the function it was forked with); None where
        the platform cannot fork, or in a worker."""
        if self.pool is None or self.key is not key:
            with signals_held():  # the pool is this object's before an interrupt can arrive
                self.close()
                self.pool = pool(self.workers, serve, self.inherited)
                self.key = key if self.pool is not None else None
        if self.pool is None:
            return None
        return pool_map(self.pool, items, self.inherited)

    def close(self) -> None:
        """Let the workers finish and end them."""
        with signals_held():
            if self.pool is not None:
                self.pool.close()
                self.pool.join()
            self.pool, self.key = None, None

    def terminate(self) -> None:
        """End the workers now, whatever they are doing (on an interrupt or an error), and reap them."""
        with signals_held():
            if self.pool is not None:
                self.pool.terminate()
                self.pool.join()
            self.pool, self.key = None, None


def fork_map(function: Callable[[Any], Any], items: Sequence[Any], workers: int) -> list:
    """``[function(item) for item in items]``, on up to `workers` forked processes (module docstring).

    `function` may be a closure over anything in this process (it is inherited, never pickled); its
    results must pickle.
    """
    items = list(items)
    if not forks(len(items), workers):
        return [function(item) for item in items]
    serving = ServingPool(min(workers, len(items)))
    try:
        out = serving.map(items, lambda index: function(items[index]), range(len(items)))
    except BaseException:  # an interrupt, or an error in a worker: the others' work is not waited for
        serving.terminate()
        raise
    serving.close()
    return out


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

