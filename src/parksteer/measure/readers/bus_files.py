"""A CAN bus as the bus log reader knows it: its file (``parksteer/data/buses/NAME.toml``: the DBC, the ready
channel map, the messages' rates, the checksum algorithm and its data IDs) or a DBC given alone, the checksum
algorithms, and the roles of a message's signals (counter, checksum, quality bit)."""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import UsageError


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
    """A channel map (a list of parksteer.measure.channel_map.Channel) that carries the bus its signals are on."""

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


def quality_bit(msg, signal: str):
    """The quality bit of `signal` in its message: a QBit signal whose name holds the signal's stem."""
    stem = signal.split("_", 1)[1] if "_" in signal else signal
    for s in msg.signals:
        if QBIT in s.name.lower() and stem.lower() in s.name.lower() and s.length == 1:
            return s
    return None


# Quality bits: VW names them '<stem>_QBit' or '<prefix>_QBit_<stem>'; set (1) means a substitute value.
QBIT = "qbit"
