"""What every Snakemake rule script shares: log to the rule's log file, and turn a user error into one line.

A rule script is then two lines of its own::

    with rule_log(snakemake):
        make_fig3(snakemake.input.parameters, snakemake.output.svg, ...)

The log then holds what the job computed and how long it took: a first line naming the rule, its wildcards and
inputs; the progress lines of the code it runs (:mod:`parksteer.progress`, and anything else written to stderr);
at the end each output with its size and the key numbers of its JSON outputs, and the job's time.
"""

from __future__ import annotations

import hashlib
import json
import sys
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

from .errors import UsageError
from .progress import note

KEY_NUMBERS_SHOWN = 12  # per JSON output; the rest are in the file


def _size(path: Path) -> str:
    if path.is_dir():
        files = [p for p in path.rglob("*") if p.is_file()]
        return f"folder, {len(files)} files, {sum(p.stat().st_size for p in files) / 1024:.1f} KiB"
    return f"{path.stat().st_size / 1024:.1f} KiB"


def _key_numbers(path: Path) -> list[str]:
    """`key = value` for the top-level numbers (and numbers one level down) of a JSON output, the first few."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    found = []

    def walk(value, name):
        if isinstance(value, bool) or value is None:
            return
        if isinstance(value, (int, float)):
            found.append(f"{name} = {value:.6g}")
        elif isinstance(value, dict) and name.count(".") < 1:
            for key, item in value.items():
                walk(item, f"{name}.{key}" if name else str(key))

    if isinstance(data, dict):
        walk(data, "")
    shown = found[:KEY_NUMBERS_SHOWN]
    if len(found) > len(shown):
        shown.append(f"... {len(found) - len(shown)} more numbers in the file")
    return shown


def describe_outputs(outputs) -> list[str]:
    """One line per output (its size, or that it is missing), each JSON output's key numbers indented below."""
    lines = []
    for name in outputs:
        path = Path(name)
        if not path.exists():
            lines.append(f"  {name}: not written")
            continue
        lines.append(f"  {name}: {_size(path)}")
        if path.suffix == ".json" and path.is_file():
            lines.extend(f"    {item}" for item in _key_numbers(path))
    return lines


def _job_name(snakemake: Any) -> str:
    wildcards = dict(snakemake.wildcards.items()) if hasattr(snakemake.wildcards, "items") else {}
    return snakemake.rule + "".join(f" {k}={v}" for k, v in wildcards.items())


@contextmanager
def rule_log(snakemake: Any) -> Iterator[None]:
    """Send stderr to the rule's log, with the job's progress; a UsageError ends the job with one line in that
    log, no traceback. A job that fails also says why in one line on the terminal's stderr."""
    log = open(snakemake.log[0], "w", encoding="utf-8")
    terminal, sys.stderr = sys.stderr, log
    job = _job_name(snakemake)
    inputs = list(snakemake.input)
    note(f"{job}: started, {len(inputs)} input files")
    start = time.perf_counter()
    outcome = "failed"
    try:
        yield
        outcome = "finished"
    except UsageError as exc:
        print(f"{snakemake.rule}: error: {exc}", file=log)
        log.flush()
        print(f"parksteer: {job}: error: {exc}", file=terminal)
        sys.exit(1)
    except BaseException as exc:
        # The cause on the terminal too, beside Snakemake's own report: one line, the traceback in the log.
        if not isinstance(exc, (SystemExit, KeyboardInterrupt)):
            cause = str(exc).splitlines()[0] if str(exc) else ""
            print(f"parksteer: {job}: {type(exc).__name__}: {cause} (traceback in {snakemake.log[0]})",
                  file=terminal)
        raise
    finally:
        note(f"{job}: {outcome} after {time.perf_counter() - start:.2f} s")
        for line in describe_outputs(snakemake.output):
            note(line)
        log.flush()


def write_code_stamp(sources, out_path: str | Path) -> None:
    """Write the sha256 and path of each file of `sources`, one line each (sha256sum's format): a single file
    that a rule can take as input in place of the many modules its script runs, and that is rewritten when one
    of them changes (the rule writing it reruns)."""
    from .tables import atomic_path

    lines = [f"{hashlib.sha256(Path(p).read_bytes()).hexdigest()}  {p}" for p in sources]
    with atomic_path(out_path) as scratch:
        scratch.write_text("".join(f"{line}\n" for line in lines), encoding="utf-8")
