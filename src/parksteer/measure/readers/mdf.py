"""ASAM MDF (versions 3 and 4), as automotive loggers write it, through the optional asammdf package
(``pip install 'parksteer[mdf]'``; imported only when an MDF file is read). Each numeric channel comes with its
unit and its own time stamps; master (time) channels and asammdf's bookkeeping channels are not channels here."""

from __future__ import annotations

import gc
import io
import re
import sys
from pathlib import Path
from typing import ClassVar

import numpy as np

from ...errors import UsageError, cannot_read_as
from .base import TIME_ALIASES, Record, Source, normal_name, refusal

MAGIC = (b"MDF     ", b"UnFinMF ")


class MdfReader:
    name: ClassVar[str] = "ASAM MDF"
    suffixes: ClassVar[tuple[str, ...]] = (".mf4", ".mdf", ".dat")

    def sniff(self, head: bytes) -> bool:
        """The file identifier of MDF 3 and 4 (an unfinalised file included)."""
        return head[:8] in MAGIC

    def read(self, raw: bytes, where: Path) -> Record:
        return Record(self.name, _sources(raw, where), {"format": self.name})


def _sources(raw: bytes, where: Path) -> list[Source]:
    try:
        from asammdf import MDF
    except ImportError:
        raise UsageError(
            f"{where}: an ASAM MDF file; reading it needs the optional extra: pip install 'parksteer[mdf]'"
        ) from None
    problem = None
    try:
        mdf = MDF(io.BytesIO(raw))
    except Exception as exc:  # asammdf raises many types for a damaged file; the user needs the file and the gist
        problem = re.sub(r"'?<_io\.BytesIO object at 0x[0-9a-f]+>'?", "it", f"{type(exc).__name__}: {exc}")
    if problem is not None:
        # The half-built reader's finaliser fails on a damaged file and would print a traceback: collect it now,
        # with that report silenced.
        hook, sys.unraisablehook = sys.unraisablehook, lambda report: None
        try:
            gc.collect()
        finally:
            sys.unraisablehook = hook
        raise UsageError(cannot_read_as(where, "ASAM MDF", problem.splitlines()[0]))
    sources: list[Source] = []
    try:
        for name, places in mdf.channels_db.items():
            if normal_name(name) in TIME_ALIASES or name.startswith("$"):
                continue  # master (time) channels and asammdf's own bookkeeping
            if len(places) > 1:
                raise refusal(where, f"channel {name!r} appears in {len(places)} channel groups; rename one")
            group, index = places[0]
            signal = mdf.get(name, group=group, index=index)
            samples = np.asarray(signal.samples)
            if samples.ndim != 1 or samples.dtype.kind not in "iuf" or len(samples) < 2:
                continue  # arrays, strings, bus frames and empty channels cannot be a native column
            sources.append(Source(name, str(signal.unit).strip() or None, samples.astype(float),
                                  np.asarray(signal.timestamps, dtype=float)))
    finally:
        mdf.close()
    if not sources:
        raise refusal(where, "the MDF file holds no numeric channel")
    return sources
