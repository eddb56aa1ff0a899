"""What every reader of a measurement format gives: the file's channels, their units and their time base.

A reader (:class:`Reader`) says whether it reads a file from its first bytes (``sniff``) and turns the file's
bytes into a :class:`Record`: the channels as :class:`Source` (name, stated unit, samples), the metadata the file
states, and either one time base shared by every channel (a time channel among them, as in a text table) or time
stamps of each channel's own (as in ASAM MDF). Mapping channels to the native columns, unit conversion and every
check of the measurement format happen after, in :func:`parksteer.measure.importers.load_record`, the same for
every format.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar, Protocol

import numpy as np

from ...errors import UsageError

# Channel names loggers use for time, compared by :func:`normal_name` (master channels of MDF files go by these).
TIME_ALIASES = ("time", "t", "zeit", "timestamp", "timestamps")
# How many leading bytes a reader's sniff sees.
SNIFF_BYTES = 4096


@dataclass
class Source:
    """One channel of a file before mapping: its name, stated unit, samples and (MDF) its own time stamps."""

    name: str
    unit: str | None
    values: np.ndarray | None = None  # filled when the channel is used
    timestamps: np.ndarray | None = None
    column: int | None = None  # position in a text table
    step: float | None = None  # a bus signal's resolution in `unit`, and its largest magnitude (full scale)
    full_scale: float | None = None


@dataclass
class Record:
    """A file as its reader found it, before mapping.

    `samples` reads one channel's samples on the shared time base (a text table parses a column only when it is
    used, so a bad cell in an ignored column does not matter); None when each source carries its own values and
    time stamps. `line_numbers` gives the file line of each data row of a text file (None for a binary file).
    """

    format: str
    sources: list[Source]
    metadata: dict[str, str] = field(default_factory=dict)
    line_numbers: list[int] | None = None
    samples: Callable[[Source], np.ndarray] | None = None
    notes: list[str] = field(default_factory=list)  # findings for stderr once the record is read (a bus log's)

    @property
    def shared_time_base(self) -> bool:
        """True when the channels share one time base, one of them the time channel."""
        return self.samples is not None

    @property
    def is_text(self) -> bool:
        """True for a text file, which may state its case and surface in '# key: value' lines."""
        return self.line_numbers is not None


class Reader(Protocol):
    """One measurement format. `name` names it in messages; `suffixes` are the file name endings it usually has
    (documentation: a file is recognised by its content, not its name)."""

    name: ClassVar[str]
    suffixes: ClassVar[tuple[str, ...]]

    def sniff(self, head: bytes) -> bool:
        """Whether this reader reads a file that begins with `head` (its first bytes)."""

    def read(self, raw: bytes, where: Path) -> Record:
        """The channels of the file `where` whose bytes are `raw`; any defect is a one-line UsageError naming
        `where`. (The caller reads the bytes once, under the size cap of a record.)"""


def refusal(where, problem: str) -> UsageError:
    """The one-line refusal of a record: `where` (its file, with the channel, row or line when known), then what is
    wrong with it: ``{where}: {problem}``."""
    return UsageError(f"{where}: {problem}")


def normal_name(name: str) -> str:
    """A channel name as aliases are compared: lower case, without spaces, '_', '-' or '.'."""
    return re.sub(r"[\s_.\-]", "", name.lower())


_BRACKETED = re.compile(r"^(?P<name>.*?)\s*[\[(](?P<unit>[^\[\]()]*)[\])]\s*$")


def name_and_unit(text: str) -> tuple[str, str | None]:
    """'RackPos[mm]' or 'RackPos (mm)' -> ('RackPos', 'mm'); 'RackPos' -> ('RackPos', None)."""
    match = _BRACKETED.match(text.strip())
    if match and match.group("name"):
        return match.group("name").strip(), match.group("unit").strip()
    return text.strip(), None


def decode_text(raw: bytes, where: Path) -> str:
    """`raw` as UTF-8 text; a byte that is not UTF-8 is refused naming its position."""
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise refusal(where, f"not UTF-8 text (byte {exc.start})") from None
