"""The frames of a raw CAN log: which format a file is (:func:`bus_format`) and every data frame in it, read
through python-can's log readers (:func:`read_frames`); a damaged or cut file is refused in one line."""

from __future__ import annotations

import gc
import io
import logging
import re
import sys
from pathlib import Path

import numpy as np

from ...errors import UsageError, cannot_read_as
from .base import refusal


FORMAT_NAMES = {"candump": "candump log", "asc": "Vector ASC", "blf": "Vector BLF", "trc": "PCAN TRC",
                "mf4": "ASAM MDF4 bus logging"}


_CANDUMP_LINE = re.compile(r"^\(\s*\d+(\.\d+)?\)\s+\S+\s+[0-9A-Fa-f]{1,8}#")


def bus_format(head: bytes) -> str | None:
    """Which bus log a file beginning with `head` is (a key of FORMAT_NAMES), or None. An MDF file is 'mf4' only
    when read with a DBC: whether it holds frames or channels shows in its channels, not its first bytes."""
    if head[:4] == b"LOGG":
        return "blf"
    text = head.decode("utf-8", errors="replace").lstrip("\ufeff")
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    if not lines:
        return None
    if _CANDUMP_LINE.match(lines[0]):
        return "candump"
    if lines[0].startswith(";$FILEVERSION") or (lines[0].startswith(";") and "PCAN" in text[:1000]):
        return "trc"
    if lines[0].lower().startswith("date ") and any(line.lower().startswith("base ") for line in lines[:4]):
        return "asc"
    return None


def read_frames(raw: bytes, where: Path, fmt: str):
    """(time stamps, ids, data, channels, error frame count) of every data frame of the log, in file order."""
    try:
        import can  # noqa: F401
        from can.io import asc, blf, canutils, trc
    except ImportError:
        raise refusal(where, f"a raw CAN log; reading it needs the optional extra: pip install 'parksteer[bus]'") \
            from None
    times, ids, data, channels, errors = [], [], [], [], 0
    if fmt == "blf" and len(raw) >= 24:
        # The file header states the file's size (uint64 at byte 16); python-can stops quietly at a cut
        stated = int.from_bytes(raw[16:24], "little")
        if stated > len(raw):
            raise refusal(where, f"the Vector BLF is cut short: {len(raw)} of the {stated} bytes its header "
                             "states; copy the whole file from the logger")
    # asammdf logs a damaged file's tracebacks and its half-built reader's finaliser fails: both silenced here
    quiet = logging.getLogger("asammdf"), sys.unraisablehook
    quiet[0].disabled, sys.unraisablehook = True, (lambda report: None)
    problem = None
    try:
        if fmt == "blf":
            reader = blf.BLFReader(io.BytesIO(raw))
        elif fmt == "mf4":
            from can.io import mf4

            reader = mf4.MF4Reader(io.BytesIO(raw))
        else:
            text = io.StringIO(raw.decode("utf-8", errors="replace"))
            reader = {"candump": canutils.CanutilsLogReader, "asc": asc.ASCReader, "trc": trc.TRCReader}[fmt](text)
        for message in reader:
            if message.is_error_frame:
                errors += 1
                continue
            if message.is_remote_frame:
                continue
            times.append(message.timestamp)
            ids.append(message.arbitration_id)
            data.append(bytes(message.data))
            channels.append(str(message.channel))
    except UsageError:
        raise
    except Exception as exc:  # the readers raise many types for a damaged file; the user needs the gist
        problem = re.sub(r"<_io\.\w+ object at 0x[0-9a-f]+>", "it", f"{type(exc).__name__}: {exc}").splitlines()
        problem = problem[0][:160] if problem else type(exc).__name__
    finally:
        reader = None
    try:
        # A reader that failed half-built, its exception and traceback gone, is collected now, quietly; only then,
        # since a whole collection takes half a second in a process with a large heap.
        if problem is not None:
            gc.collect()
    finally:
        quiet[0].disabled, sys.unraisablehook = False, quiet[1]
    if problem is not None:
        got = f" after {len(times)} frames" if times else ""
        raise UsageError(cannot_read_as(where, f"{FORMAT_NAMES[fmt]}{got}", problem)
                         + "; the file is damaged or cut short")
    if not times:
        raise refusal(where, f"the {FORMAT_NAMES[fmt]} holds no CAN data frame")
    return np.asarray(times, dtype=float), np.asarray(ids, dtype=np.int64), data, np.asarray(channels), errors
