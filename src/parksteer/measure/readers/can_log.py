"""Raw CAN bus logs, decoded with the car's DBC: SocketCAN ``candump -l`` logs, Vector ASC and BLF, PCAN TRC and
ASAM MDF4 bus logging (frames in ``CAN_DataFrame`` channels), read through the optional python-can's log readers
(its MDF4 reader through asammdf) and decoded with cantools (``pip install 'parksteer[bus]'``; imported only when
a bus log is read).

The channel map (``--map`` or ``--bus NAME``, ``parksteer/data/buses/NAME.toml``) says which signals become which
native columns; only those are decoded, each on the time stamps of its own message's frames, and
:func:`parksteer.measure.importers.load_record` puts them on one time base (metadata ``bus_time_base``). Time
stamps, duplicates, counters, checksums (where the bus file names the algorithm), quality bits, gaps and saturation
are checked frame by frame: each finding is a note on stderr and in the metadata ``bus_checks``, or a one-line
refusal when the record cannot be trusted (more than :data:`MAX_BAD_SHARE` failing checksums, a gap longer than
:data:`MAX_GAP_S` seconds, a saturated signal, a time stamp going back, a mapped message without frames). The
checks, one by one: docs/bus.md.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from ...errors import UsageError
from .base import SNIFF_BYTES, Record, Source, refusal
from .bus_files import BusSpec, checksum_signal, counter_signal, known_buses, load_dbc, quality_bit
from .can_frames import FORMAT_NAMES, bus_format, read_frames
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


@dataclass
class _Findings:
    """What the checks of a bus log found, in the order found: notes (stderr and the metadata ``bus_findings``)
    and the checks made (``bus_checks``)."""

    notes: list[str] = field(default_factory=list)
    checks: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class _Frames:
    """Every data frame of a log: time stamps (s, from the first frame, to the microsecond), ids, data, the
    channel each came in on, and the first frame's time stamp as logged."""

    times: np.ndarray
    ids: np.ndarray
    data: list[bytes]
    buses: np.ndarray
    t0: float


def read_bus_log(raw: bytes, where: Path, channels) -> Record:
    """The mapped signals of the bus log `raw` (file `where`), decoded with the DBC that `channels` (a
    :class:`~parksteer.measure.readers.bus_files.BusMap`) carries, each with the time stamps of its message's
    frames, checked as the module says."""
    bus: BusSpec = channels.bus
    fmt = _log_format(raw, where)
    dbc = load_dbc(bus)
    signals = []
    for ch in channels:
        message, signal = _split_signal(ch.source, where, dbc, bus.dbc, "channel")
        sign = _split_signal(ch.sign, where, dbc, bus.dbc, "sign") if ch.sign else None
        signals.append(_Signal(message, signal, sign, ch.scale if ch.scale is not None else 1.0, ch.source))
    times, ids, data, buses, error_frames = read_frames(raw, where, fmt)
    found = _Findings()
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
        found.notes.append(f"{error_frames} error frames on the bus")
    # Silences of the whole bus: longer than MAX_GAP_S with no frame of any id.
    silent = np.nonzero(steps > MAX_GAP_S)[0]
    silences = [(times[k] - t0, times[k + 1] - t0) for k in silent]
    frames = _Frames(times, ids, data, buses, t0)

    messages = {}
    for sig in signals:
        for name in [sig.message] + ([sig.sign[0]] if sig.sign else []):
            messages.setdefault(name, dbc.get_message_by_name(name))
    decoded: dict[str, tuple[np.ndarray, dict[str, np.ndarray]]] = {}
    periods: dict[str, float] = {}
    for name, msg in messages.items():
        t, columns = _message_columns(name, msg, frames, bus, where, found)
        periods[name] = _check_gaps(name, t, silences, where, found)
        decoded[name] = (t, columns)
    sources = [_signal_source(sig, messages[sig.message], decoded, where, found) for sig in signals]

    base = next((s for s, ch in zip(signals, channels) if ch.target == TORQUE), signals[0])
    metadata = {"format": FORMAT_NAMES[fmt], "bus": bus.name, "dbc": bus.dbc.name,
                "bus_time_base": _time_base(base.message, sorted({s.message for s in signals} - {base.message}),
                                            periods),
                "bus_checks": "; ".join(found.checks)}
    if found.notes:
        metadata["bus_findings"] = "; ".join(found.notes)
    return Record(f"{FORMAT_NAMES[fmt]} ({bus.name})", sources, metadata,
                  notes=[f"{where}: note: {n}" for n in found.notes])


def _log_format(raw: bytes, where: Path) -> str:
    """The bus log format of `raw` (a key of FORMAT_NAMES): sniffed, or 'mf4' for an MDF file read with a DBC."""
    fmt = bus_format(raw[:SNIFF_BYTES])
    if fmt is None:
        if raw[:8] in (b"MDF     ", b"UnFinMF "):
            fmt = "mf4"
        else:
            raise refusal(where, f"--dbc/--bus given, but the file is not a CAN log this tool reads "
                             f"({', '.join(FORMAT_NAMES.values())}); a file of named channels needs neither")
    return fmt


def _message_columns(name: str, msg, frames: _Frames, bus: BusSpec, where: Path, found: _Findings
                     ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The frames of message `name` that pass the checks (duplicates, checksum, decoding, counter), as its time
    stamps and each of its signals' values."""
    mask = frames.ids == msg.frame_id
    if not mask.any():
        raise refusal(where, f"no frame of {name} (id {msg.frame_id} = 0x{msg.frame_id:03X}) in the log, "
                         f"which holds {_listing(frames.ids)}: a log of another bus, or not this car's DBC")
    # A log of two buses (candump -l any, a logger's two channels) may hold a message on both, as a gateway
    # forwards it: the channel with the most of its frames is read
    on = Counter(frames.buses[mask].tolist())
    if len(on) > 1:
        chosen, count = on.most_common(1)[0]
        found.notes.append(f"{name} is on channels {', '.join(f'{c} ({n} frames)' for c, n in on.most_common())}: "
                           f"read from {chosen}")
        mask &= frames.buses == chosen
    t = np.round(frames.times[mask] - frames.t0, 6)
    data = [frames.data[k] for k in np.nonzero(mask)[0]]
    keep = np.ones(len(t), dtype=bool)
    # exact duplicates: the same time stamp and data as the frame before
    dup = np.zeros(len(t), dtype=bool)
    dup[1:] = (np.diff(t) == 0.0) & np.array([data[k] == data[k - 1] for k in range(1, len(t))])
    if dup.any():
        found.notes.append(f"{name}: {int(dup.sum())} duplicated frames dropped (at {_times(t[dup])})")
    keep &= ~dup
    if np.any(np.diff(t[keep]) == 0.0):
        k = int(np.argmax(np.diff(t[keep]) == 0.0)) + 1
        raise refusal(where, f"two frames of {name} with different data share the time stamp "
                         f"{t[keep][k]:.6f} s: the log's time stamps cannot be trusted there")
    keep &= ~_failing_checksum(name, msg, bus, t, data, keep, where, found)
    t, columns = _decoded(name, msg, t, data, keep, where, found)
    return _counted(name, msg, t, columns, found)


def _failing_checksum(name: str, msg, bus: BusSpec, t: np.ndarray, data: list[bytes], keep: np.ndarray,
                      where: Path, found: _Findings) -> np.ndarray:
    """Which of the kept frames of `msg` fail their checksum, where the bus names its algorithm (none where it
    does not); too many refuse the log."""
    crc = checksum_signal(msg)
    algorithm = bus.checksum_algorithm
    if crc is not None and algorithm is not None and msg.frame_id in bus.data_ids and crc.start == 0 \
            and crc.length == 8:
        bad = np.array([len(f) < 2 or algorithm(f, bus.data_ids[msg.frame_id]) != f[0] for f in data])
        bad &= keep
        if bad.sum() > MAX_BAD_SHARE * keep.sum():
            raise refusal(where, f"{name}: the checksum fails in {int(bad.sum())} of {int(keep.sum())} "
                             f"frames (first at {t[bad][0]:.3f} s): not this bus, or not this car's DBC")
        if bad.any():
            found.notes.append(f"{name}: {int(bad.sum())} frames failing their checksum dropped (at {_times(t[bad])})")
        found.checks.append(f"{name} checksum {bus.checksum} checked")
        return bad
    found.checks.append(f"{name} checksum not checked (no algorithm known for it)")
    if crc is not None:
        found.notes.append(f"{name}: checksum {crc.name} not checked (no algorithm known for {bus.dbc.name}; "
                           "a bus file of parksteer/data/buses names one)")
    return np.zeros(len(t), dtype=bool)


def _decoded(name: str, msg, t: np.ndarray, data: list[bytes], keep: np.ndarray, where: Path, found: _Findings
             ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The kept frames of `msg` decoded: their time stamps and each signal's values; a frame that does not decode
    is dropped, too many refuse the log."""
    values: dict[str, list] = {s.name: [] for s in msg.signals}
    undecodable = np.zeros(len(t), dtype=bool)
    for k in np.nonzero(keep)[0]:
        try:
            out = msg.decode(data[k], decode_choices=False)
        except Exception:  # a frame shorter than its message (cantools DecodeError and others)
            undecodable[k] = True
            continue
        for s in msg.signals:
            values[s.name].append(float(out[s.name]))
    if undecodable.sum() > MAX_BAD_SHARE * keep.sum():
        raise refusal(where, f"{name}: {int(undecodable.sum())} of {int(keep.sum())} frames do not decode "
                         f"(first at {t[undecodable][0]:.3f} s, {len(data[int(np.argmax(undecodable))])} bytes "
                         f"where the DBC has {msg.length}): not this car's DBC")
    if undecodable.any():
        found.notes.append(f"{name}: {int(undecodable.sum())} frames that do not decode dropped")
    keep = keep & ~undecodable
    return t[keep], {s: np.asarray(v, dtype=float) for s, v in values.items()}


def _counted(name: str, msg, t: np.ndarray, columns: dict[str, np.ndarray], found: _Findings
             ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The frames of `msg` after its message counter's check: a repeated counter dropped, jumps noted."""
    counter = counter_signal(msg)
    if counter is not None and len(t) > 1:
        modulus = 2 ** counter.length
        step = np.mod(np.diff(columns[counter.name]), modulus)
        repeated = np.concatenate([[False], step == 0])
        if repeated.any():
            found.notes.append(f"{name}: {int(repeated.sum())} frames repeating their counter dropped (at "
                               f"{_times(t[repeated])})")
            t = t[~repeated]
            columns = {s: v[~repeated] for s, v in columns.items()}
            step = np.mod(np.diff(columns[counter.name]), modulus)
        jumps = np.nonzero(step > 1)[0]
        if len(jumps):
            lost = int(np.sum(step[jumps] - 1))
            found.notes.append(f"{name}: counter {counter.name} jumps {len(jumps)} times, {lost} frames lost (at "
                               f"{_times(t[jumps + 1])})")
        found.checks.append(f"{name} counter {counter.name}: {len(jumps)} jumps")
    return t, columns


def _check_gaps(name: str, t: np.ndarray, silences: list[tuple[float, float]], where: Path, found: _Findings
                ) -> float:
    """The period of message `name` (the median spacing of its frames); its gaps noted, a long one refused."""
    if len(t) < 2:
        raise refusal(where, f"{name}: fewer than two usable frames")
    period = float(np.median(np.diff(t)))
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
        found.notes.append(f"{name}: {len(gaps)} gaps of frames lost (at {_times(t[gaps])}, up to "
                           f"{max(t[k + 1] - t[k] for k in gaps) * 1000:.0f} ms)")
    return period


def _signal_source(sig: _Signal, msg, decoded: dict[str, tuple[np.ndarray, dict[str, np.ndarray]]], where: Path,
                   found: _Findings) -> Source:
    """A mapped signal's values on its message's frames: quality bit, saturation and sign applied, scaled."""
    t, columns = decoded[sig.message]
    values = columns[sig.signal].copy()
    good = np.ones(len(t), dtype=bool)
    qbit = quality_bit(msg, sig.signal)
    if qbit is not None:
        flagged = columns[qbit.name] != 0.0
        if flagged.all():
            raise refusal(where, f"{sig.name}: every frame has its quality bit {qbit.name} set (a "
                             "substitute value, the sensor not ready or failed)")
        if flagged.any():
            found.notes.append(f"{sig.name}: {int(flagged.sum())} frames with the quality bit {qbit.name} set "
                               f"dropped (at {_times(t[flagged])})")
        good &= ~flagged
        found.checks.append(f"{sig.name} quality bit {qbit.name}")
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
    return Source(sig.name, unit, values[good], t[good], step=step,
                  full_scale=abs(counts * spec.scale * sig.scale) if spec.offset == 0 else None)


def _time_base(base: str, others: list[str], periods: dict[str, float]) -> str:
    """The metadata ``bus_time_base``: the message whose frames are the time base, the others interpolated."""
    text = f"the frames of {base} ({1.0 / periods[base]:.4g} Hz)"
    if others:
        text += "; " + ", ".join(f"{m} ({1.0 / periods[m]:.4g} Hz)" for m in others) + (
            " interpolated linearly onto them, each value from frames at most half its period away, the most lag "
            "this adds (" + ", ".join(f"{0.5 * periods[m] * 1000:.3g} ms" for m in others) + ")")
    return text
