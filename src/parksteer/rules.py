"""What every Snakemake rule script shares: log to the rule's log file, and turn a user error into one line.

A rule script is then two lines of its own::

    with rule_log(snakemake):
        make_fig3(snakemake.input.parameters, snakemake.output.svg, ...)
"""

from __future__ import annotations

import sys
from contextlib import contextmanager
from typing import Any, Iterator

from .errors import UsageError


@contextmanager
def rule_log(snakemake: Any) -> Iterator[None]:
    """Send stderr to the rule's log; a UsageError ends the job with one line in that log, no traceback."""
    log = open(snakemake.log[0], "w", encoding="utf-8")
    sys.stderr = log
    try:
        yield
    except UsageError as exc:
        print(f"{snakemake.rule}: error: {exc}", file=log)
        log.flush()
        sys.exit(1)
    finally:
        log.flush()
