"""A car's own CAN bus: the channel map of ``--bus NAME`` / ``--dbc CAR.dbc``, and the way back from a record to
the frames a car would send (:func:`encode_frames`, :func:`write_log`), with which the decoding is shown to lose
nothing but the bus's own resolution (tests/measure/test_bus.py, benchmarks/bench_bus_roundtrip.py).

Encoding is the reader's map run backwards: each mapped native column, in SI, negated where the map negates it,
split into magnitude and sign flag where the map names a sign signal, converted to the signal's unit, divided by
the map's scale and quantised to the nearest raw count of the DBC (``round((value - offset) / factor)``, clipped
to the signal's bits: a torque beyond 1023 cN m reads back as saturated). Each message is sent at its nominal
rate (the bus file's ``rates_hz``), with its counter running and its checksum where the bus file names the
algorithm; the torque's message at the record's instants, the others optionally shifted by a fixed phase each (the
messages of a real bus are not sent together). A column the record lacks (speed in a parking test) is sent as 0.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import UsageError
from .channel_map import Channel, channel_map_from_options, parse_channel_map
from .io import Measurement
from .readers.bus_files import BusMap, BusSpec, checksum_signal, counter_signal, dbc_bus, load_bus, load_dbc
from .units import from_si
from ..names import TORQUE

WRITERS = {"candump": ".log", "asc": ".asc", "blf": ".blf", "trc": ".trc", "mf4": ".mf4"}


def bus_channel_map(bus: str | None, dbc: str | None, map_text: str | None, map_file: str | None) -> BusMap | None:
    """The channel map of ``--bus``/``--dbc`` with ``--map``/``--map-file``: a bus's ready map, any --map entry
    replacing the ready entry of its target; with --dbc alone the map is the user's. None without either."""
    if bus is None and dbc is None:
        return None
    if bus is not None and dbc is not None:
        raise UsageError("--bus and --dbc both given: --bus names its own DBC; give one")
    spec = load_bus(bus) if bus is not None else dbc_bus(dbc)
    user = channel_map_from_options(map_text, map_file) or []
    ready = parse_channel_map(",".join(spec.map_entries), f"bus {bus}") if spec.map_entries else []
    channels = [ch for ch in ready if all(ch.target != u.target for u in user)] + list(user)
    if not channels:
        raise UsageError(f"--dbc {dbc}: say which signals are which columns with --map "
                         "'MESSAGE.SIGNAL[unit]=column', e.g. --map 'LH_EPS_03.EPS_Lenkmoment[cN*m]=handwheel_torque_Nm'")
    return BusMap(channels, spec)


def _signal_values(ch: Channel, values: np.ndarray, message, name: str) -> dict[str, np.ndarray]:
    """Raw counts of the signal of `ch` (and of its sign flag) for SI values of its target."""
    v = -values if ch.negate else values
    out = {}
    if ch.sign:
        out[ch.sign.partition(".")[2]] = (v < 0.0).astype(float)
        v = np.abs(v)
    v = from_si(v, ch.unit, ch.target) / (ch.scale or 1.0)
    signal = message.get_signal_by_name(name)
    raw = np.round((v - signal.offset) / signal.scale)
    low, high = (-(2 ** (signal.length - 1)), 2 ** (signal.length - 1) - 1) if signal.is_signed \
        else (0, 2 ** signal.length - 1)
    out[name] = np.clip(raw, low, high)
    return out


def encode_frames(record: Measurement, channels: BusMap, t0: float = 1_700_000_000.0, phase_s: float = 0.0):
    """The frames (python-can Messages, in time order) a car would send for `record` on the bus of `channels`:
    each message from the record's first instant at its rate, the torque's message first, the n-th after it
    `n phase_s` later in name order (0: the messages together, so a record at a message's rate is sent at its own
    instants)."""
    import can

    bus: BusSpec = channels.bus
    dbc = load_dbc(bus)
    time_s = record.time_s
    by_message: dict[str, list[Channel]] = {}
    for ch in channels:
        by_message.setdefault(ch.source.partition(".")[0], []).append(ch)
    frames = []
    # The torque's message first: at the record's own instants, so its samples are sent as they are (resampled,
    # a noisy record would have its noise averaged by the interpolation)
    order = sorted(by_message.items(), key=lambda item: (all(c.target != TORQUE for c in item[1]),
                                                         item[0]))
    for phase, (name, chs) in enumerate(order):
        message = dbc.get_message_by_name(name)
        rate = bus.rates_hz.get(name)
        if rate is None:
            raise UsageError(f"bus {bus.name}: no rate for message {name} (rates_hz)")
        t = time_s[0] + phase * phase_s + np.arange(int((time_s[-1] - time_s[0] - phase * phase_s) * rate + 1e-6) + 1) / rate
        raw = {s.name: np.zeros(len(t)) for s in message.signals}
        for ch in chs:
            column = record.columns.get(ch.target)
            values = np.zeros(len(t)) if column is None else np.interp(t, time_s, column)
            raw.update(_signal_values(ch, values, message, ch.source.partition(".")[2]))
        counter = counter_signal(message)
        checksum = checksum_signal(message)
        algorithm = bus.checksum_algorithm
        for k, tk in enumerate(t):
            signals = {s: int(v[k]) for s, v in raw.items()}
            if counter is not None:
                signals[counter.name] = k % 2 ** counter.length
            data = bytearray(message.encode(signals, scaling=False, strict=False))
            if checksum is not None and algorithm is not None and message.frame_id in bus.data_ids:
                data[0] = algorithm(bytes(data), bus.data_ids[message.frame_id])
            frames.append(can.Message(timestamp=t0 + tk, arbitration_id=message.frame_id, data=bytes(data),
                                      is_extended_id=message.is_extended_frame, channel=0))
    frames.sort(key=lambda m: m.timestamp)
    return frames


def write_log(frames, path: str | Path, fmt: str | None = None, dbc: Path | None = None) -> Path:
    """`frames` written as a bus log of format `fmt` (a key of WRITERS; by default from the file's suffix)."""
    from can.io import asc, blf, canutils, trc

    path = Path(path)
    fmt = fmt or next((k for k, suffix in WRITERS.items() if path.suffix == suffix), None)
    if fmt not in WRITERS:
        raise UsageError(f"{path}: no bus log format {fmt!r} (name one of {', '.join(WRITERS)}, or a file ending "
                         f"{', '.join(WRITERS.values())})")
    if fmt == "mf4":
        from can.io import mf4

        writer = mf4.MF4Writer(path, database=dbc)
    else:
        writer = {"candump": canutils.CanutilsLogWriter, "asc": asc.ASCWriter, "blf": blf.BLFWriter,
                  "trc": trc.TRCWriter}[fmt](path)
    for frame in frames:
        writer.on_message_received(frame)
    writer.stop()
    return path
