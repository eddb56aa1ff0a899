"""Raw CAN bus logs, decoded with the car's DBC: SocketCAN ``candump -l`` logs, Vector ASC and BLF, PCAN TRC and
ASAM MDF4 bus logging (frames in ``CAN_DataFrame`` channels, as CAN-to-SD loggers write them), read through the
optional python-can's log readers (its MDF4 reader through asammdf) and decoded with cantools
(``pip install 'parksteer[bus]'``; imported only when a bus log is read).

A bus log holds frames, not channels: which signals become which native columns is the channel map's
(``--map 'LH_EPS_03.EPS_Lenkmoment[cN*m]=-handwheel_torque_Nm;sign=LH_EPS_03.EPS_VZ_Lenkmoment'``, or a
ready map of ``parksteer/data/buses/NAME.toml`` through ``--bus NAME``), so this reader decodes only the mapped
signals, each on the time stamps of its own message's frames. :func:`parksteer.measure.importers.load_record`
then puts them on one time base as it does an MDF file's channels: the torque message's frames, the others
interpolated linearly. A value so interpolated is read from frames at most half its message's period away; for a
smooth signal linear interpolation adds no lag of its own, but the value is only as fresh as those frames (the
metadata ``bus_time_base`` states the periods).

What a bus does to data is checked frame by frame, each finding a note on stderr and in the metadata
``bus_checks``, or a refusal in one line when the record cannot be trusted:

- time stamps that go back are refused (the logger's clock jumped); an exact duplicate of the previous frame of
  a message (same time stamp, or same counter and data) is dropped and counted;
- the counter (``COUNTER`` or ``..._BZ``): a jump of more than one is frames lost, named with its time;
- the checksum (``CHECKSUM`` or ``..._CRC``), where the bus file names its algorithm (VW MQB: AUTOSAR E2E
  profile 2): a failing frame is dropped; more than :data:`MAX_BAD_SHARE` failing is refused (not this bus or not
  this car's DBC). With a DBC alone the checksum is not checked, and the metadata says so;
- the quality bit of a signal (``..._QBit`` of the same message, e.g. ``EPS_Lenkmoment_QBit``): a frame whose bit
  is set carries a substitute value and is dropped;
- gaps: a message's frames further apart than 1.5 of its period are frames lost (noted with their times); a gap
  longer than :data:`MAX_GAP_S` is refused, and one where no frame at all is on the bus is named a bus-off or
  logger pause;
- a signal at its largest raw value is saturated (the torque beyond it is lost): refused;
- a named message without any frame in the log (another bus, or another car's DBC) is one line naming the
  message and the log's most frequent ids.
"""

from __future__ import annotations

import gc
import io
import logging
import re
import sys
import tomllib
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from ...errors import UsageError, cannot_read_as
from .base import SNIFF_BYTES, Record, Source, refusal
from ...names import TORQUE

# A gap in a used message longer than this is refused: the method resolves the phases of a cycle over windows of
# 0.1 s (parksteer.measure.importers.METHOD_RATE_HZ), so a longer hole takes a part of a phase with it.
MAX_GAP_S = 0.1
# A gap is frames lost when the frames are further apart than this many periods of the message.
GAP_PERIODS = 1.5
# More than this share of a message's frames failing their checksum or decoding: not this bus, or not this DBC.
MAX_BAD_SHARE = 0.1
# How many findings of one kind a note names with their times.
NAMED_FINDINGS = 3
# Quality bits: VW names them '<stem>_QBit' or '<prefix>_QBit_<stem>'; set (1) means a substitute value.
QBIT = "qbit"

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


class CanLogReader:
    """Sniffs the bus log formats; reading one needs a DBC (:func:`read_bus_log`), so without one it refuses the
    file in one line saying what to give."""

    name: ClassVar[str] = "CAN bus log"
    suffixes: ClassVar[tuple[str, ...]] = (".log", ".asc", ".blf", ".trc", ".mf4")

    def sniff(self, head: bytes) -> bool:
        return bus_format(head) is not None

    def read(self, raw: bytes, where: Path) -> Record:
        fmt = FORMAT_NAMES[bus_format(raw[:SNIFF_BYTES]) or "candump"]
        raise refusal(where, f"a raw CAN log ({fmt}); decoding it needs the car's DBC: give --bus NAME "
                         f"(known: {', '.join(known_buses())}) or --dbc CAR.dbc with --map "
                         "'MESSAGE.SIGNAL[unit]=column'")


# ------------------------------------------------------------------------------------------------ bus files

BUSES_DIR = Path(__file__).resolve().parents[2] / "data" / "buses"


@dataclass(frozen=True)
class BusSpec:
    """A DBC and what the project knows of its bus: the ready channel map (--map entries), the messages' send
    rates, the checksum algorithm and its data IDs (message id -> one byte per counter value)."""

    name: str
    dbc: Path
    map_entries: tuple[str, ...] = ()
    rates_hz: dict[str, float] = field(default_factory=dict)
    checksum: str | None = None
    data_ids: dict[int, tuple[int, ...]] = field(default_factory=dict)
    source: str = ""

    @property
    def checksum_algorithm(self):
        """The function computing a frame's checksum (a value of CHECKSUMS), or None when none is named."""
        return CHECKSUMS.get(self.checksum) if self.checksum else None


def known_buses() -> list[str]:
    return sorted(p.stem for p in BUSES_DIR.glob("*.toml"))


def load_bus(name: str) -> BusSpec:
    """The bus file ``parksteer/data/buses/NAME.toml``; refused in one line when there is none."""
    path = BUSES_DIR / f"{name}.toml"
    if not path.is_file():
        raise UsageError(f"--bus {name}: no such bus (known: {', '.join(known_buses())})")
    with path.open("rb") as f:
        spec = tomllib.load(f)
    checksum = spec.get("checksum", {})
    return BusSpec(spec["name"], path.parent / spec["dbc"], tuple(spec.get("map", ())),
                   {k: float(v) for k, v in spec.get("rates_hz", {}).items()}, checksum.get("algorithm"),
                   {int(k): tuple(v) for k, v in checksum.get("data_ids", {}).items()}, spec.get("source", ""))


def dbc_bus(path: str | Path) -> BusSpec:
    """A DBC given alone (--dbc): no ready map, no known checksum."""
    path = Path(path)
    if not path.is_file():
        raise UsageError(f"--dbc {path}: no such file")
    return BusSpec(path.stem, path)


class BusMap(list):
    """A channel map (a list of parksteer.measure.importers.Channel) that carries the bus its signals are on."""

    def __init__(self, channels, bus: BusSpec):
        super().__init__(channels)
        self.bus = bus


def load_dbc(bus: BusSpec):
    """The cantools database of `bus`; refused in one line when it does not parse."""
    try:
        import cantools
    except ImportError:
        raise UsageError(f"{bus.dbc}: decoding a CAN log needs the optional extra: pip install 'parksteer[bus]'") \
            from None
    try:
        return cantools.database.load_file(str(bus.dbc), database_format="dbc", strict=False)
    except Exception as exc:  # cantools raises parser errors of several types
        raise UsageError(f"{bus.dbc}: not a DBC cantools can read ({str(exc).splitlines()[0][:160]})") from None


# ------------------------------------------------------------------------------------------------ checksums

def _crc8_h2f_table() -> list[int]:
    """CRC-8 with polynomial 0x2F (AUTOSAR CRC8H2F), most significant bit first."""
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = ((crc << 1) ^ 0x2F) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
        table.append(crc)
    return table


_H2F = _crc8_h2f_table()


def e2e_p2_checksum(data: bytes, data_ids: tuple[int, ...]) -> int:
    """AUTOSAR E2E profile 2 checksum of a frame whose byte 0 is the checksum and whose low nibble of byte 1 is
    the counter: CRC8H2F from 0xFF over bytes 1.., then the data ID of that counter value, final XOR 0xFF."""
    crc = 0xFF
    for byte in data[1:]:
        crc = _H2F[crc ^ byte]
    crc = _H2F[crc ^ data_ids[data[1] & 0x0F]]
    return crc ^ 0xFF


CHECKSUMS = {"autosar_e2e_p2": e2e_p2_checksum}


# ------------------------------------------------------------------------------------------------ frames

def read_frames(raw: bytes, where: Path, fmt: str):
    """(time stamps, ids, data, channels, error frame count) of every data frame of the log, in file order."""
    try:
        import can  # noqa: F401
        from can.io import asc, blf, canutils, trc
    except ImportError:
        raise refusal(where, "a raw CAN log; reading it needs the optional extra: pip install 'parksteer[bus]'") \
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
        gc.collect()  # the exception and its traceback are gone: a half-built reader is collected now, quietly
    finally:
        quiet[0].disabled, sys.unraisablehook = False, quiet[1]
    if problem is not None:
        got = f" after {len(times)} frames" if times else ""
        raise UsageError(cannot_read_as(where, f"{FORMAT_NAMES[fmt]}{got}", problem)
                         + "; the file is damaged or cut short")
    if not times:
        raise refusal(where, f"the {FORMAT_NAMES[fmt]} holds no CAN data frame")
    return np.asarray(times, dtype=float), np.asarray(ids, dtype=np.int64), data, np.asarray(channels), errors


def _listing(ids: np.ndarray, count: int = 5) -> str:
    common = Counter(ids.tolist()).most_common(count)
    return ", ".join(f"0x{i:03X} ({n} frames)" for i, n in common)


def _times(values, unit="s") -> str:
    shown = ", ".join(f"{v:.3f} {unit}" for v in values[:NAMED_FINDINGS])
    return shown + (f" and {len(values) - NAMED_FINDINGS} more" if len(values) > NAMED_FINDINGS else "")


@dataclass
class _Signal:
    """A mapped signal: its message, name, sign signal and scale (from the channel map entry)."""

    message: str
    signal: str
    sign: tuple[str, str] | None
    scale: float
    name: str


def _split_signal(text: str, where: Path, dbc, dbc_path: Path, what: str) -> tuple[str, str]:
    message, dot, signal = text.partition(".")
    if not dot or not message or not signal:
        raise refusal(where, f"{what} {text!r} must read 'MESSAGE.SIGNAL' (a message and signal of {dbc_path.name})")
    try:
        msg = dbc.get_message_by_name(message)
    except KeyError:
        raise refusal(where, f"{what} {text!r}: {dbc_path.name} has no message {message!r}") from None
    if signal not in [s.name for s in msg.signals]:
        names = ", ".join(s.name for s in msg.signals)
        raise refusal(where, f"{what} {text!r}: message {message} has no signal {signal!r} (signals: {names})")
    return message, signal


def _role(msg, pattern: str):
    """The signal of a message whose name matches `pattern`, or None."""
    for s in msg.signals:
        if re.fullmatch(pattern, s.name):
            return s
    return None


def counter_signal(msg):
    """The message counter of a message (COUNTER, or VW's ..._BZ), or None."""
    return _role(msg, r"COUNTER|\w+_BZ")


def checksum_signal(msg):
    """The checksum of a message (CHECKSUM, or VW's ..._CRC), or None."""
    return _role(msg, r"CHECKSUM|\w+_CRC")


def _quality_bit(msg, signal: str):
    """The quality bit of `signal` in its message: a QBit signal whose name holds the signal's stem."""
    stem = signal.split("_", 1)[1] if "_" in signal else signal
    for s in msg.signals:
        if QBIT in s.name.lower() and stem.lower() in s.name.lower() and s.length == 1:
            return s
    return None


def read_bus_log(raw: bytes, where: Path, channels) -> Record:
    """The mapped signals of the bus log `raw` (file `where`), decoded with the DBC that `channels` (a
    :class:`BusMap`) carries, each with the time stamps of its message's frames, checked as the module says."""
    bus: BusSpec = channels.bus
    fmt = bus_format(raw[:SNIFF_BYTES])
    if fmt is None:
        if raw[:8] in (b"MDF     ", b"UnFinMF "):
            fmt = "mf4"
        else:
            raise refusal(where, "--dbc/--bus given, but the file is not a CAN log this tool reads "
                             f"({', '.join(FORMAT_NAMES.values())}); a file of named channels needs neither")
    dbc = load_dbc(bus)
    signals = []
    for ch in channels:
        message, signal = _split_signal(ch.source, where, dbc, bus.dbc, "channel")
        sign = _split_signal(ch.sign, where, dbc, bus.dbc, "sign") if ch.sign else None
        signals.append(_Signal(message, signal, sign, ch.scale if ch.scale is not None else 1.0, ch.source))
    times, ids, data, buses, error_frames = read_frames(raw, where, fmt)
    notes: list[str] = []
    checks: list[str] = []
    steps = np.diff(times)
    if np.any(steps < 0.0):
        k = int(np.argmax(steps < 0.0)) + 1
        raise refusal(where, f"frame {k + 1} (id 0x{ids[k]:03X}) is stamped {times[k] - times[0]:.6f} s, before "
                         f"the frame ahead of it ({times[k - 1] - times[0]:.6f} s): the logger's clock jumped; cut "
                         "the log there or merge its parts in time order")
    # Times from the first frame, to the microsecond: the resolution of candump and ASC, and what undoes the
    # rounding of absolute (epoch) time stamps in a float (2.4e-7 s at 1.7e9 s)
    t0 = times[0]
    times = t0 + np.round(times - t0, 6)
    if error_frames:
        notes.append(f"{error_frames} error frames on the bus")
    # Silences of the whole bus: longer than MAX_GAP_S with no frame of any id.
    silent = np.nonzero(steps > MAX_GAP_S)[0]
    silences = [(times[k] - t0, times[k + 1] - t0) for k in silent]

    messages = {}
    for sig in signals:
        for name in [sig.message] + ([sig.sign[0]] if sig.sign else []):
            messages.setdefault(name, dbc.get_message_by_name(name))
    decoded: dict[str, tuple[np.ndarray, dict[str, np.ndarray]]] = {}
    periods: dict[str, float] = {}
    for name, msg in messages.items():
        mask = ids == msg.frame_id
        if not mask.any():
            raise refusal(where, f"no frame of {name} (id {msg.frame_id} = 0x{msg.frame_id:03X}) in the log, "
                             f"which holds {_listing(ids)}: a log of another bus, or not this car's DBC")
        # A log of two buses (candump -l any, a logger's two channels) may hold a message on both, as a gateway
        # forwards it: the channel with the most of its frames is read
        on = Counter(buses[mask].tolist())
        if len(on) > 1:
            chosen, count = on.most_common(1)[0]
            notes.append(f"{name} is on channels {', '.join(f'{c} ({n} frames)' for c, n in on.most_common())}: "
                         f"read from {chosen}")
            mask &= buses == chosen
        t = np.round(times[mask] - t0, 6)
        frames = [data[k] for k in np.nonzero(mask)[0]]
        keep = np.ones(len(t), dtype=bool)
        # exact duplicates: the same time stamp and data as the frame before
        dup = np.zeros(len(t), dtype=bool)
        dup[1:] = (np.diff(t) == 0.0) & np.array([frames[k] == frames[k - 1] for k in range(1, len(t))])
        if dup.any():
            notes.append(f"{name}: {int(dup.sum())} duplicated frames dropped (at {_times(t[dup])})")
        keep &= ~dup
        if np.any(np.diff(t[keep]) == 0.0):
            k = int(np.argmax(np.diff(t[keep]) == 0.0)) + 1
            raise refusal(where, f"two frames of {name} with different data share the time stamp "
                             f"{t[keep][k]:.6f} s: the log's time stamps cannot be trusted there")
        # checksum
        crc = checksum_signal(msg)
        algorithm = bus.checksum_algorithm
        if crc is not None and algorithm is not None and msg.frame_id in bus.data_ids and crc.start == 0 \
                and crc.length == 8:
            bad = np.array([len(f) < 2 or algorithm(f, bus.data_ids[msg.frame_id]) != f[0] for f in frames])
            bad &= keep
            if bad.sum() > MAX_BAD_SHARE * keep.sum():
                raise refusal(where, f"{name}: the checksum fails in {int(bad.sum())} of {int(keep.sum())} "
                                 f"frames (first at {t[bad][0]:.3f} s): not this bus, or not this car's DBC")
            if bad.any():
                notes.append(f"{name}: {int(bad.sum())} frames failing their checksum dropped (at {_times(t[bad])})")
            keep &= ~bad
            checks.append(f"{name} checksum {bus.checksum} checked")
        else:
            checks.append(f"{name} checksum not checked (no algorithm known for it)")
            if crc is not None:
                notes.append(f"{name}: checksum {crc.name} not checked (no algorithm known for {bus.dbc.name}; "
                             "a bus file of parksteer/data/buses names one)")
        # decoding
        values: dict[str, list] = {s.name: [] for s in msg.signals}
        undecodable = np.zeros(len(t), dtype=bool)
        for k in np.nonzero(keep)[0]:
            try:
                out = msg.decode(frames[k], decode_choices=False)
            except Exception:  # a frame shorter than its message (cantools DecodeError and others)
                undecodable[k] = True
                continue
            for s in msg.signals:
                values[s.name].append(float(out[s.name]))
        if undecodable.sum() > MAX_BAD_SHARE * keep.sum():
            raise refusal(where, f"{name}: {int(undecodable.sum())} of {int(keep.sum())} frames do not decode "
                             f"(first at {t[undecodable][0]:.3f} s, {len(frames[int(np.argmax(undecodable))])} bytes "
                             f"where the DBC has {msg.length}): not this car's DBC")
        if undecodable.any():
            notes.append(f"{name}: {int(undecodable.sum())} frames that do not decode dropped")
        keep &= ~undecodable
        t = t[keep]
        columns = {s: np.asarray(v, dtype=float) for s, v in values.items()}
        # counter
        counter = counter_signal(msg)
        if counter is not None and len(t) > 1:
            modulus = 2 ** counter.length
            step = np.mod(np.diff(columns[counter.name]), modulus)
            repeated = np.concatenate([[False], step == 0])
            if repeated.any():
                notes.append(f"{name}: {int(repeated.sum())} frames repeating their counter dropped (at "
                             f"{_times(t[repeated])})")
                t = t[~repeated]
                columns = {s: v[~repeated] for s, v in columns.items()}
                step = np.mod(np.diff(columns[counter.name]), modulus)
            jumps = np.nonzero(step > 1)[0]
            if len(jumps):
                lost = int(np.sum(step[jumps] - 1))
                notes.append(f"{name}: counter {counter.name} jumps {len(jumps)} times, {lost} frames lost (at "
                             f"{_times(t[jumps + 1])})")
            checks.append(f"{name} counter {counter.name}: {len(jumps)} jumps")
        if len(t) < 2:
            raise refusal(where, f"{name}: fewer than two usable frames")
        period = float(np.median(np.diff(t)))
        periods[name] = period
        gaps = np.nonzero(np.diff(t) > GAP_PERIODS * period)[0]
        if len(gaps):
            long = [k for k in gaps if t[k + 1] - t[k] > MAX_GAP_S]
            if long:
                k = long[0]
                within = [s for s in silences if s[0] >= t[k] - 1e-9 and s[1] <= t[k + 1] + 1e-9]
                why = ("no frame of any id on the bus then: bus off or a logger pause" if within
                       else "other messages go on: frames of this one lost")
                raise refusal(where, f"{name}: no frame from {t[k]:.3f} s to {t[k + 1]:.3f} s "
                                 f"({t[k + 1] - t[k]:.3f} s, more than {MAX_GAP_S:g} s; {why}); cut the log to "
                                 "one side of it")
            notes.append(f"{name}: {len(gaps)} gaps of frames lost (at {_times(t[gaps])}, up to "
                         f"{max(t[k + 1] - t[k] for k in gaps) * 1000:.0f} ms)")
        decoded[name] = (t, columns)

    sources = []
    for sig, ch in zip(signals, channels):
        msg = messages[sig.message]
        t, columns = decoded[sig.message]
        values = columns[sig.signal].copy()
        good = np.ones(len(t), dtype=bool)
        qbit = _quality_bit(msg, sig.signal)
        if qbit is not None:
            flagged = columns[qbit.name] != 0.0
            if flagged.all():
                raise refusal(where, f"{sig.name}: every frame has its quality bit {qbit.name} set (a "
                                 "substitute value, the sensor not ready or failed)")
            if flagged.any():
                notes.append(f"{sig.name}: {int(flagged.sum())} frames with the quality bit {qbit.name} set dropped "
                             f"(at {_times(t[flagged])})")
            good &= ~flagged
            checks.append(f"{sig.name} quality bit {qbit.name}")
        spec = msg.get_signal_by_name(sig.signal)
        if not spec.is_signed and not spec.is_float and spec.length > 1:
            top = (2 ** spec.length - 1) * spec.scale + spec.offset
            full = good & (np.abs(values - top) <= 0.5 * abs(spec.scale))
            if full.any():
                raise refusal(where, f"{sig.name} sits at its largest raw value {2 ** spec.length - 1} "
                                 f"({top:g} {spec.unit or ''}) in {int(full.sum())} frames from {t[full][0]:.3f} s: "
                                 "the signal saturates and what lies beyond it is lost")
        if sig.sign is not None:
            st, scolumns = decoded[sig.sign[0]]
            flag = scolumns[sig.sign[1]]
            if sig.sign[0] == sig.message:
                negative = flag != 0.0
            else:  # another message: its last frame at or before each sample
                index = np.clip(np.searchsorted(st, t, side="right") - 1, 0, len(st) - 1)
                negative = flag[index] != 0.0
            values = np.where(negative, -values, values)
        values = values * sig.scale
        unit = spec.unit.strip() if spec.unit else None
        if unit is not None and (unit.startswith("Unit_") or not unit):
            unit = None  # VW's unit names (Unit_centiNewtoMeter) are not units pint reads: the map gives one
        # The resolution: one raw count; the full scale: the largest raw magnitude (the sign flag doubles the levels)
        step = abs(spec.scale * sig.scale)
        counts = 2 ** (spec.length - 1) if spec.is_signed else 2 ** spec.length - 1
        sources.append(Source(sig.name, unit, values[good], t[good], step=step,
                              full_scale=abs(counts * spec.scale * sig.scale) if spec.offset == 0 else None))

    base = next((s for s, ch in zip(signals, channels) if ch.target == TORQUE), signals[0])
    others = sorted({s.message for s in signals} - {base.message})
    text = f"the frames of {base.message} ({1.0 / periods[base.message]:.4g} Hz)"
    if others:
        text += "; " + ", ".join(f"{m} ({1.0 / periods[m]:.4g} Hz)" for m in others) + (
            " interpolated linearly onto them, each value from frames at most half its period away, the most lag "
            "this adds (" + ", ".join(f"{0.5 * periods[m] * 1000:.3g} ms" for m in others) + ")")
    metadata = {"format": FORMAT_NAMES[fmt], "bus": bus.name, "dbc": bus.dbc.name, "bus_time_base": text,
                "bus_checks": "; ".join(checks)}
    if notes:
        metadata["bus_findings"] = "; ".join(notes)
    return Record(f"{FORMAT_NAMES[fmt]} ({bus.name})", sources, metadata,
                  notes=[f"{where}: note: {n}" for n in notes])
