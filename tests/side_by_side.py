"""Processes that meet on one model cache at once, as a first diagnosis's background builders and its workers do:
each forked from the test's process, so that they start together."""

from __future__ import annotations

import multiprocessing

FORKS = "fork" in multiprocessing.get_all_start_methods()


def exit_codes(target, *args, count: int = 3) -> list[int]:
    """The exit codes of `count` processes forked at once, each running ``target(*args)``."""
    context = multiprocessing.get_context("fork")
    processes = [context.Process(target=target, args=args) for _ in range(count)]
    for process in processes:
        process.start()
    for process in processes:
        process.join()
    return [process.exitcode for process in processes]
