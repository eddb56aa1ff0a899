"""MATLAB MAT-files (level 5, what MATLAB writes by default up to `-v7` and what data acquisition tools export),
through scipy.io. Every numeric vector is a channel; a vector named like time (`time`, `t`, ...) is their time
base, shared by the channels of its length. A MAT-file states no units: the channel map names them
(`--map "RackPos[mm]=rack_m"`), or the variables carry native names (`rack_m`, `handwheel_torque_Nm`)."""

from __future__ import annotations

import io
from pathlib import Path
from typing import ClassVar

import numpy as np

from ...errors import UsageError, cannot_read_as
from .base import TIME_ALIASES, Record, Source, normal_name, refusal

MAGIC = b"MATLAB 5.0 MAT-file"
HDF5 = b"MATLAB 7.3 MAT-file"


class MatlabReader:
    name: ClassVar[str] = "MATLAB MAT-file"
    suffixes: ClassVar[tuple[str, ...]] = (".mat",)

    def sniff(self, head: bytes) -> bool:
        """The text header of a level-5 MAT-file, or of a version 7.3 one (refused by name when read)."""
        return head.startswith(MAGIC) or head.startswith(HDF5)

    def read(self, raw: bytes, where: Path) -> Record:
        if raw.startswith(HDF5):
            raise UsageError(cannot_read_as(where, self.name, "version 7.3, an HDF5 file: save it with -v7"))
        from scipy.io import loadmat

        try:
            variables = loadmat(io.BytesIO(raw), squeeze_me=True)
        except Exception as exc:  # scipy raises several types for a damaged file; the user needs the file and the gist
            raise UsageError(cannot_read_as(where, self.name, f"{type(exc).__name__}: {exc}".splitlines()[0])) from None
        vectors = {name: np.asarray(value, dtype=float) for name, value in variables.items()
                   if not name.startswith("__") and isinstance(value, np.ndarray) and value.ndim == 1
                   and value.dtype.kind in "iuf" and len(value) >= 2}
        times = [name for name in vectors if normal_name(name) in TIME_ALIASES]
        if not times:
            raise refusal(where, "no time vector among the MAT-file's variables (name one "
                             f"{', '.join(TIME_ALIASES)}); its vectors: {', '.join(sorted(vectors)) or 'none'}")
        if len(times) > 1:
            raise refusal(where, f"{len(times)} time vectors ({', '.join(times)}); keep one")
        time = vectors.pop(times[0])
        sources = [Source(name, None, values, time) for name, values in vectors.items() if len(values) == len(time)]
        if not sources:
            raise refusal(where, f"no numeric vector of the time vector's length ({len(time)} samples)")
        return Record(self.name, sources, {"format": self.name})
