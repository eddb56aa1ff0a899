"""Deterministic, atomic writing of result tables (CSV) and summaries (JSON).

Every output is written to a temporary file beside its target and renamed into place,
so a failure never leaves a half-written file. Numbers are formatted with a fixed
number of significant digits so that the same inputs give the same bytes, and so that
a last-bit difference between platforms does not change a checksum.
"""

from __future__ import annotations

import glob
import json
import math
import os
import socket
import tempfile
import time
from collections.abc import Iterable, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from .errors import UsageError

SIGNIFICANT_DIGITS = 7


def format_number(x: float, digits: int = SIGNIFICANT_DIGITS) -> str:
    """Format a float with `digits` significant digits; -0 becomes 0 (nan, inf and -inf as Python writes them).

    Only a zero is written as zero: a nonzero float rounded to one or more significant digits keeps a nonzero
    leading digit, so "-0" is the one text to mend."""
    s = format(float(x), f".{digits}g")
    return "0" if s == "-0" else s


def format_numbers(values: np.ndarray, digits: int = SIGNIFICANT_DIGITS) -> list[str]:
    """:func:`format_number` of each of the floats `values` (a table's column, written in one pass)."""
    spec = f".{digits}g"
    return ["0" if s == "-0" else s for s in [format(v, spec) for v in np.asarray(values, dtype=float).tolist()]]


# A temporary file is named ".<target name>.<host>.<pid>.<random>.tmp" so that one left by a killed writer can be
# told from one being written: remove_stale_temporaries deletes those whose process is gone (same host), or that are
# older than any write could take (another host, on a shared file system).
TEMPORARY_SUFFIX = ".tmp"
STALE_TEMPORARY_S = 6 * 3600.0


def _host() -> str:
    return socket.gethostname().replace(".", "-")


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def _stale_temporary(path: Path, host: str, now: float) -> bool:
    """True if `path` is a temporary file of atomic_path whose writer is gone."""
    parts = path.name.split(".")
    if not (path.name.startswith(".") and path.name.endswith(TEMPORARY_SUFFIX) and len(parts) >= 6):
        return False
    owner_host, pid = parts[-4], parts[-3]
    if not pid.isdigit():
        return False
    try:
        age = now - path.lstat().st_mtime
    except OSError:
        return False
    return (owner_host == host and not _process_alive(int(pid))) or age > STALE_TEMPORARY_S


def remove_stale_temporaries(*roots: str | Path) -> list[Path]:
    """Remove the temporary files of atomic_path left by killed writers in `roots` (folders, searched through);
    return what was removed. A file being written by a live process is left alone."""
    host, now, removed = _host(), time.time(), []
    for root in map(Path, roots):
        if not root.is_dir():
            continue
        for folder, _, names in os.walk(root):
            for name in names:
                path = Path(folder) / name
                if name.endswith(TEMPORARY_SUFFIX) and _stale_temporary(path, host, now):
                    try:
                        path.unlink()
                    except FileNotFoundError:
                        continue
                    removed.append(path)
    return removed


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside `path`; rename it onto `path` only on success.

    A temporary file of the same target left by a killed writer is removed first."""
    path = Path(path)
    if path.is_dir():
        raise UsageError(f"{path}: is a directory; name a file to write")
    if path.parent.exists() and not path.parent.is_dir():
        raise UsageError(f"{path}: {path.parent} is a file, not a directory")
    host = _host()
    try:  # a folder nothing can be written in (read-only, /proc): the user's path in one line, not a traceback
        path.parent.mkdir(parents=True, exist_ok=True)
        for old in path.parent.glob(f".{glob.escape(path.name)}.*{TEMPORARY_SUFFIX}"):
            if _stale_temporary(old, host, time.time()):
                old.unlink(missing_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{host}.{os.getpid()}.", suffix=TEMPORARY_SUFFIX,
                                   dir=path.parent)
    except OSError as exc:
        raise UsageError(f"{path}: cannot write in folder {path.parent} ({exc.strerror})") from None
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; outputs are ordinary files
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


ROWS_KEY = "rows"  # the last header line of a table: its number of data rows


def write_csv(
    path: str | Path,
    columns: Mapping[str, Sequence[Any] | np.ndarray],
    header: Mapping[str, Any] | None = None,
    digits: int = SIGNIFICANT_DIGITS,
) -> None:
    """Write named columns as CSV, with optional leading ``# key: value`` lines and, last of them, ``# rows: N``.

    The row count lets a reader (:func:`read_csv`) and the damage check (:mod:`parksteer.outputs`) tell a table
    cut exactly at a row boundary, which still parses, from the table that was written.
    """
    names = list(columns)
    data = [np.asarray(columns[n]) for n in names]
    lengths = {len(c) for c in data}
    if len(lengths) > 1:
        raise ValueError(f"{path}: columns have different lengths {sorted(lengths)}")
    for name, column in zip(names, data):  # the format has no quoting: a text cell holds no separator
        if column.dtype.kind in "US":
            for i, cell in enumerate(column):
                if any(c in str(cell) for c in ',\n"'):
                    raise ValueError(f"{path}: column {name}, row {i + 1}: {str(cell)!r} holds a comma, a quote or a "
                                     "line break, which this CSV cannot carry")
    rows = (",".join(str(v) if isinstance(v, (str, np.str_)) else format_number(v, digits) for v in row)
            for row in zip(*data))
    write_csv_rows(path, names, rows, lengths.pop() if lengths else 0, header)


def write_csv_rows(path: str | Path, names: Sequence[str], rows: Iterable[str], n_rows: int,
                   header: Mapping[str, Any] | None = None) -> None:
    """Write a CSV as write_csv does, from its column names and its data rows, each already joined by commas,
    written as they come (a table of a million rows need not be held); `n_rows` is their number."""
    if header and ROWS_KEY in header:
        raise ValueError(f"{path}: the header key {ROWS_KEY!r} is the row count's")
    lines = [f"# {k}: {v}" for k, v in (header or {}).items()]
    lines.append(f"# {ROWS_KEY}: {n_rows}")
    lines.append(",".join(names))
    written = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as out:
        out.write("\n".join(lines) + "\n")
        for row in rows:
            out.write(row + "\n")
            written += 1
        if written != n_rows:  # inside: a table whose count is wrong is never put in place
            raise ValueError(f"{path}: {written} rows written where {n_rows} were announced")


def read_csv(path: str | Path) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """Read a CSV written by :func:`write_csv`: numeric columns and the ``# key: value`` header."""
    header: dict[str, str] = {}
    rows: list[list[str]] = []
    names: list[str] | None = None
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            key, _, value = line[1:].partition(":")
            header[key.strip()] = value.strip()
        elif names is None:
            names = line.split(",")
        elif line.strip():
            rows.append(line.split(","))
    if names is None:
        raise ValueError(f"{path}: no header row")
    if ROWS_KEY in header and header[ROWS_KEY] != str(len(rows)):
        raise ValueError(f"{path}: {len(rows)} data rows where its header says {header[ROWS_KEY]} (truncated)")
    cols: dict[str, np.ndarray] = {}
    for i, n in enumerate(names):
        raw = [r[i] for r in rows]
        try:
            cols[n] = np.array([float(v) for v in raw])
        except ValueError:
            cols[n] = np.array(raw, dtype=object)
    return cols, header


class StreamedList:
    """A list of a JSON document that write_json encodes item by item as `items` yields them (read once), so that
    it need never be whole in memory: the bytes are those of the same document holding the list itself."""

    def __init__(self, items: Iterable[Any]):
        self.items = items


def _clean(obj: Any, digits: int, streamed: list | None = None) -> Any:
    if isinstance(obj, StreamedList):
        if streamed is None:
            raise TypeError("a StreamedList only at the top of write_json's document")
        streamed.append(obj)
        return f"\0streamed list {len(streamed) - 1}\0"
    if isinstance(obj, Mapping):
        return {str(k): _clean(v, digits, streamed) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_clean(v, digits, streamed) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(format_number(obj, digits)) if math.isfinite(obj) else None
    return obj


def write_json(path: str | Path, obj: Any, digits: int = SIGNIFICANT_DIGITS) -> None:
    """Write JSON with sorted keys and rounded floats (non-finite numbers become null).

    The text goes to the file as it is encoded (json.dump: the bytes json.dumps gives), never whole in memory. A
    list given as a :class:`StreamedList` is encoded one item at a time where it stands (a sweep's summary of a
    million points lists some 450,000 points above its assistance threshold): the rest of the document is
    encoded with a placeholder string there, and the items go in its place, each encoded alone and indented
    as json.dump indents a list's items at that depth (the placeholder's line's indent plus one step)."""
    streamed: list[StreamedList] = []
    cleaned = _clean(obj, digits, streamed)
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as out:
        if not streamed:
            json.dump(cleaned, out, indent=2, sort_keys=True)
        else:
            text = json.dumps(cleaned, indent=2, sort_keys=True)
            places = sorted((text.index(json.dumps(f"\0streamed list {number}\0")), number)
                            for number in range(len(streamed)))  # in the text's order (keys are sorted)
            start = 0
            for at, number in places:
                listed, placeholder = streamed[number], json.dumps(f"\0streamed list {number}\0")
                line = text[text.rfind("\n", 0, at) + 1:at]
                indent = " " * (len(line) - len(line.lstrip(" ")))
                inner = "\n" + indent + "  "
                out.write(text[start:at])
                out.write("[")
                empty = True
                for item in listed.items:
                    out.write(("" if empty else ",") + inner)
                    out.write(json.dumps(_clean(item, digits), indent=2, sort_keys=True).replace("\n", inner))
                    empty = False
                out.write("]" if empty else "\n" + indent + "]")
                start = at + len(placeholder)
            out.write(text[start:])
        out.write("\n")
