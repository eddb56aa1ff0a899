"""The channel map: how a logger's channels become the native columns of a record (``--map``, ``--map-file``).

Channel map syntax (``--map`` or one entry per line in a map file)::

    RackPos[mm]=rack_m,SteerTorque[N*m]=handwheel_torque_Nm,SWA[deg]=-handwheel_angle_rad

A unit in brackets is the source channel's unit; a leading minus on the target negates the channel (a logger with
the opposite sign convention). A target without a source unit is taken in its own SI unit (``rack_m``: metres).

A signal of a raw CAN log (``--dbc CAR.dbc`` or ``--bus NAME``, :mod:`parksteer.measure.readers.can_log`) is
named ``MESSAGE.SIGNAL``, and its entry may end in options after semicolons: ``sign=MESSAGE.SIGNAL`` (the value
is a magnitude whose sign is that flag signal: set means negative) and ``scale=FACTOR`` (the decoded value, a raw
count where the DBC gives no factor, times FACTOR, before the unit)::

    LH_EPS_03.EPS_Lenkmoment[cN*m]=-handwheel_torque_Nm;sign=LH_EPS_03.EPS_VZ_Lenkmoment
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import UsageError, cannot_read
from .io import ALLOWED_COLUMNS
from .readers.base import name_and_unit

RACK, ANGLE, TIME = "rack_m", "handwheel_angle_rad", "time_s"
# An assisted car's torque sensor: a map target of its own, read into the torque column with the metadata
# torque_sensor = torsion_bar (the torque role with a flag: everything downstream of the import reads one torque).
TORSION_BAR = "torsion_bar_torque_Nm"
CURRENT, MOTOR_TORQUE, SPEED = "motor_current_A", "motor_torque_Nm", "vehicle_speed_mps"
MAP_TARGETS = ALLOWED_COLUMNS + (TORSION_BAR,)


@dataclass(frozen=True)
class Channel:
    """One entry of a channel map: source channel (with its unit, if stated) to a native column."""

    source: str
    unit: str | None
    target: str
    negate: bool = False
    origin: str = "--map"
    sign: str | None = None  # a bus log's flag signal holding the sign of this magnitude (set: negative)
    scale: float | None = None  # a bus log's signal times this factor before the unit (a raw count's scale)

    def spec(self, negate: bool | None = None) -> str:
        negate = self.negate if negate is None else negate
        unit = f"[{self.unit}]" if self.unit else ""
        options = (f";sign={self.sign}" if self.sign else "") + (f";scale={self.scale:g}" if self.scale else "")
        return f"{self.source}{unit}={'-' if negate else ''}{self.target}{options}"


def _split_entries(text: str) -> list[str]:
    """Split a map on commas outside brackets (a unit may not contain one, but a stray one gets a clear error)."""
    entries, depth, current = [], 0, ""
    for ch in text:
        depth += ch in "[(" and 1 or 0
        depth -= ch in "])" and 1 or 0
        if ch == "," and depth <= 0:
            entries.append(current)
            current = ""
        else:
            current += ch
    entries.append(current)
    return [e.strip() for e in entries if e.strip()]


def parse_channel_map(text: str, origin: str = "--map") -> list[Channel]:
    """Parse ``Source[unit]=[-]target`` entries separated by commas; `origin` names the map in errors."""
    channels: list[Channel] = []
    for entry in _split_entries(text):
        source_text, eq, target = entry.partition("=")
        target, *options = [part.strip() for part in target.split(";")]
        sign, scale = _bus_options(options, entry, origin)
        negate = target.startswith("-")
        target = target.lstrip("-").strip()
        source, unit = name_and_unit(source_text)
        if not eq or not source:
            raise UsageError(f"{origin}: entry {entry!r} must read 'Source[unit]=target', e.g. 'RackPos[mm]=rack_m'")
        if target not in MAP_TARGETS:
            raise UsageError(f"{origin}: entry {entry!r}: unknown target {target!r} (known: {', '.join(MAP_TARGETS)})")
        for other in channels:
            if other.target == target:
                raise UsageError(f"{origin}: entries {other.spec()!r} and {entry!r} both map to {target!r}")
            if other.source == source:
                raise UsageError(f"{origin}: channel {source!r} is mapped twice")
        channels.append(Channel(source, unit or None, target, negate, origin, sign, scale))
    if not channels:
        raise UsageError(f"{origin}: empty channel map")
    return channels


def _bus_options(options: list[str], entry: str, origin: str) -> tuple[str | None, float | None]:
    """The ';sign=MESSAGE.SIGNAL' and ';scale=FACTOR' options of a bus signal's map entry."""
    sign = scale = None
    for option in options:
        key, eq, value = (part.strip() for part in option.partition("="))
        if key == "sign" and eq and value:
            sign = value
        elif key == "scale" and eq:
            try:
                scale = float(value)
            except ValueError:
                scale = math.nan
            if not math.isfinite(scale) or scale == 0.0:
                raise UsageError(f"{origin}: entry {entry!r}: scale={value} is not a finite non-zero number")
        else:
            raise UsageError(f"{origin}: entry {entry!r}: option {option!r} is neither 'sign=MESSAGE.SIGNAL' nor "
                             "'scale=FACTOR'")
    return sign, scale


def read_channel_map(path: str | Path) -> list[Channel]:
    """A map file: one ``Source[unit]=[-]target`` entry per line (or several, comma separated); '#' comments."""
    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except OSError as exc:
        raise UsageError(cannot_read(path, exc)) from None
    except UnicodeDecodeError as exc:
        raise UsageError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    channels: list[Channel] = []
    for line_no, line in enumerate(text.splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if line:
            for channel in parse_channel_map(line, f"{path}: line {line_no}"):
                for other in channels:
                    if other.target == channel.target or other.source == channel.source:
                        raise UsageError(f"{path}: line {line_no}: {channel.spec()!r} repeats a channel or target "
                                         f"of {other.spec()!r}")
                channels.append(channel)
    if not channels:
        raise UsageError(f"{path}: empty channel map")
    return channels


def channel_map_from_options(map_text: str | None, map_file: str | Path | None) -> list[Channel] | None:
    """The channel map of ``--map`` and ``--map-file`` together (None when neither is given)."""
    channels = (read_channel_map(map_file) if map_file else []) + (parse_channel_map(map_text) if map_text else [])
    for i, a in enumerate(channels):
        for b in channels[i + 1:]:
            if a.target == b.target or a.source == b.source:
                raise UsageError(f"{b.origin}: {b.spec()!r} repeats a channel or target of {a.spec()!r} ({a.origin})")
    return channels or None
