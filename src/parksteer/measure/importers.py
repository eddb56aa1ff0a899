"""The import layer: every measurement, rack drive or angle record enters through :func:`load_record`.

The file format is the business of its reader (:mod:`parksteer.measure.readers`, one module each, found through
its table ``READERS``); this module maps what a reader gives to the native columns, the same for every format.

A logger export rarely looks like the native format (data/measurements/README.md): its channels have their own
names and units, cells may be separated by semicolons or tabs with a decimal comma, a units row may sit under the
header, and automotive loggers write ASAM MDF. :func:`load_record` reads any of these, maps the channels to the
native names (a channel map, or known aliases when that is unambiguous), converts units with pint, fills the case
and surface the file does not state, derives the rack from the handwheel angle when there is no rack channel, and
then runs the native format's own checks (:func:`parksteer.measure.io.validate_record`) and the plausibility checks
below. Every refusal is one :class:`~parksteer.errors.UsageError` line naming the file and the channel, row or key.

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

import errno
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import portable as pm
from ..errors import UsageError, cannot_read
from ..geometry import rack_from_handwheel
from ..names import TORQUE
from ..parameters import Parameters, load_parameters
from .io import ALLOWED_COLUMNS, REQUIRED_COLUMNS, UNITS, Measurement, metadata_text, validate_record
from .readers import Record, Source, reader_for
from .readers.base import TIME_ALIASES, name_and_unit, normal_name, refusal

RACK, ANGLE, TIME = "rack_m", "handwheel_angle_rad", "time_s"
# An assisted car's torque sensor: a map target of its own, read into the torque column with the metadata
# torque_sensor = torsion_bar (the torque role with a flag: everything downstream of the import reads one torque).
TORSION_BAR = "torsion_bar_torque_Nm"
CURRENT, MOTOR_TORQUE, SPEED = "motor_current_A", "motor_torque_Nm", "vehicle_speed_mps"
MAP_TARGETS = ALLOWED_COLUMNS + (TORSION_BAR,)
RACK_DRIVE_COLUMNS = (TIME, RACK)

# The pint unit each native column is converted to.
SI_UNITS = {TIME: "s", RACK: "m", TORQUE: "N*m", ANGLE: "rad", "load_left_N": "N", "load_right_N": "N",
            SPEED: "m/s", TORSION_BAR: "N*m", CURRENT: "A", MOTOR_TORQUE: "N*m"}
UNIT_DIMENSIONS = {TIME: "time", RACK: "length", TORQUE: "torque", ANGLE: "angle", "load_left_N": "force",
                   "load_right_N": "force", SPEED: "speed", TORSION_BAR: "torque", CURRENT: "current",
                   MOTOR_TORQUE: "torque"}

# Logger spellings pint reads as something else: "Nm" is pint's number-metre, never a torque on a logger.
UNIT_SPELLINGS = {"Nm": "N*m", "rev": "revolution", "Nmm": "N*mm", "kNm": "kN*m", "deg.": "deg", "sec": "s", "kph": "km/h"}
ANGLE_UNIT_WORDS = ("radian", "degree", "revolution", "turn", "grade", "arcminute", "arcsecond")

# Channel names loggers use for the native columns, compared lower-case without spaces, '_', '-' or '.'.
ALIASES = {
    TIME: TIME_ALIASES,
    RACK: ("rack", "rackpos", "rackposition", "rackdisplacement", "racktravel", "zahnstange", "zahnstangenweg"),
    TORQUE: ("torque", "steertorque", "steeringtorque", "handwheeltorque", "steeringwheeltorque", "swt",
             "lenkmoment", "lenkradmoment"),
    ANGLE: ("angle", "swa", "steerangle", "steeringangle", "steeringwheelangle", "handwheelangle", "lenkwinkel",
            "lenkradwinkel"),
    "load_left_N": ("loadleft", "wheelloadleft", "fzfl"),
    "load_right_N": ("loadright", "wheelloadright", "fzfr"),
    SPEED: ("vehiclespeed", "vehspeed", "speed", "fahrzeuggeschwindigkeit", "geschwindigkeit"),
    TORSION_BAR: ("torsionbartorque", "torsionbar", "tbt", "torsionstabmoment", "drehstabmoment"),
    CURRENT: ("motorcurrent", "epscurrent", "imotor", "motorstrom"),
    MOTOR_TORQUE: ("motortorque", "epsmotortorque", "motormoment"),
}

# Plausibility against the car (the parameter file's lock and ratio). Refused, not warned: each of these makes a
# comparison with the model meaningless, and a warning scrolls past while the report is believed.
# - The rack cannot pass the lock. Beyond the handwheel lock the rack moves by at most the column twist (30 N m
#   on a 1000 N m/rad column: 0.03 rad at the handwheel) and the Hooke joint's largest lead of the pinion over the
#   column (0.05 rad at 0.45 rad joint angle); 10 % more covers a zero offset of the rack sensor.
LOCK_MARGIN = 1.10
LOCK_TWIST_TORQUE_NM = 30.0
# - A rack or angle tens to thousands of times the lock is a unit error, and the ratio names the unit.
UNIT_SUSPECTS = {RACK: (("centimetres", "cm", 100.0), ("millimetres", "mm", 1000.0)),
                 ANGLE: (("degrees", "deg", 180.0 / np.pi),)}
# - Torque against rack speed: the driver pushes the rack the way it moves (friction opposes the motion), so over a
#   cycle they correlate strongly positively (about +0.8 for the paper's car). A clearly negative correlation is a
#   flipped sign convention on one channel; noise alone stays near zero.
SIGN_CORRELATION_LIMIT = -0.3
SPEED_WINDOW_S = 0.25  # rack speed from a moving average over this window (converter steps are not motion)

# Big and fast records. The method resolves a steering cycle's phases over windows of 0.1 s and more, and it is
# shown to work on 50 Hz loggers (data/measurements/example_unladen.csv); 100 samples a second, twice that, carry
# all it uses. A faster record is low-pass filtered (an FIR anti-alias filter, zero phase) and decimated to at
# least that rate on reading, so the work downstream grows with the record's duration, not its sample rate.
# Beyond the caps a record is refused, not read for minutes.
METHOD_RATE_HZ = 100.0
MAX_RECORD_BYTES = 256 * 2**20


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


# --------------------------------------------------------------------------------------------------- units

def unit_registry():
    """pint's application registry (pint's default units, built by pint on first use: it takes a few tenths of a
    second); the package never defines units in it."""
    import pint

    return pint.get_application_registry()


def conversion(unit: str | None, target: str, where: str):
    """A function taking values in `unit` to the SI unit of native column `target`; refused in one line when
    pint does not know the unit or its dimension is not the target's."""
    si = SI_UNITS[target]
    if unit is None or unit.strip() == "" or unit.strip() == si:
        return lambda values: np.asarray(values, dtype=float)
    text = UNIT_SPELLINGS.get(unit.strip(), unit.strip())
    ureg = unit_registry()
    try:
        parsed = ureg.parse_units(text)
    except Exception:  # pint raises several types (undefined unit, syntax, tokenizer) for one user mistake
        raise refusal(where, f"unit {unit!r} is not a unit pint knows") from None
    try:
        factor = float(ureg.Quantity(1.0, parsed).to(si).magnitude)
    except Exception:
        raise UsageError(
            f"{where}: unit {unit!r} is not a unit of {UNIT_DIMENSIONS[target]} (column {target!r} needs {si} or "
            f"another unit of {UNIT_DIMENSIONS[target]})"
        ) from None
    if target == ANGLE and not any(word in str(parsed) for word in ANGLE_UNIT_WORDS):
        raise refusal(where, f"unit {unit!r} is not an angle (column {target!r} needs rad, deg or rev)")
    if float(ureg.Quantity(0.0, parsed).to(si).magnitude) != 0.0:
        raise refusal(where, f"unit {unit!r} has an offset (like degC); give a unit that starts at zero")
    divisor = 1.0 / factor
    if factor < 1.0 and divisor == round(divisor):
        # A decimal prefix: divide by the exact integer, so mm -> m is value / 1000 to the last bit.
        return lambda values: np.asarray(values, dtype=float) / round(divisor)
    return lambda values: np.asarray(values, dtype=float) * factor


def to_si(values, unit: str | None, target: str, where: str = "value") -> np.ndarray:
    """Values in `unit` converted to the SI unit of native column `target`."""
    return conversion(unit, target, where)(values)


def from_si(values, unit: str | None, target: str, where: str = "value") -> np.ndarray:
    """The inverse of :func:`to_si`: SI values of `target` in `unit`."""
    one = float(to_si(np.array([1.0]), unit, target, where)[0])
    divisor = 1.0 / one
    if one < 1.0 and divisor == round(divisor):
        return np.asarray(values, dtype=float) * round(divisor)
    return np.asarray(values, dtype=float) / one


# ---------------------------------------------------------------------------------------------- mapping

def _map_sources(where: Path, sources: list[Source], channel_map: list[Channel] | None) -> dict[str, tuple[Source, Channel]]:
    """Native column -> (source, channel) by the map, the native names and, without a map, the aliases."""
    by_name = {s.name: s for s in sources}
    by_lower: dict[str, list[Source]] = {}
    for s in sources:
        by_lower.setdefault(s.name.lower(), []).append(s)
    chosen: dict[str, tuple[Source, Channel]] = {}
    used: set[str] = set()
    listing = ", ".join(s.name for s in sources)
    for ch in channel_map or []:
        source = by_name.get(ch.source)
        if source is None and len(by_lower.get(ch.source.lower(), [])) == 1:
            source = by_lower[ch.source.lower()][0]
        if source is None:
            raise refusal(where, f"{ch.origin} names channel {ch.source!r}, which the file does not have "
                             f"(channels: {listing})")
        chosen[ch.target] = (source, ch)
        used.add(source.name)
    # Native names map to themselves (their unit is in the name); the time channel by its aliases, even with a map.
    for s in sources:
        if s.name in used:
            continue
        if s.name in MAP_TARGETS:
            target = s.name
        elif channel_map is None or normal_name(s.name) in ALIASES[TIME]:
            target = next((t for t, names in ALIASES.items() if normal_name(s.name) in names), None)
        else:
            target = None
        if target is None:
            continue
        if target in chosen:
            if chosen[target][1].origin != "alias":
                continue  # the map chose another channel for this column; this one is ignored
            other = chosen[target][0].name
            raise UsageError(
                f"{where}: channels {other!r} and {s.name!r} could both be {target!r}; say which with "
                f"--map '{s.name}[unit]={target}'"
            )
        chosen[target] = (s, Channel(s.name, s.unit, target, False, "alias"))
    for target, (source, ch) in chosen.items():
        unit = ch.unit or source.unit
        if unit is None and source.name != target and ch.origin == "alias":
            raise refusal(where, f"channel {source.name!r} has no unit; give it in brackets, a units row or "
                             f"--map '{source.name}[unit]={target}'")
    return chosen


def _lock_rack_m(params: Parameters) -> float:
    s = params.sections["steering"]
    return params["input.handwheel_lock_angle"] / s["handwheel_to_rack_ratio"]


def _lock_limits(params: Parameters) -> dict[str, float]:
    """The largest plausible |rack| and |handwheel angle| of the car, margins included (see LOCK_MARGIN)."""
    s = params.sections["steering"]
    cos_a = pm.cos(s["hooke_joint_angle"])
    hooke_lead = pm.atan((1.0 - cos_a) / (2.0 * math.sqrt(cos_a)))
    twist = LOCK_TWIST_TORQUE_NM / s["column_torsional_stiffness"]
    angle = (params["input.handwheel_lock_angle"] + hooke_lead + twist) * LOCK_MARGIN
    return {ANGLE: angle, RACK: angle / s["handwheel_to_rack_ratio"]}


def _source_text(source: Source, ch: Channel) -> str:
    return f"column {source.name!r}" if source.name == ch.target else f"column {source.name!r} ({ch.target})"


def _fix_unit_hint(source: Source, ch: Channel, unit: str) -> str:
    return f"--map '{Channel(source.name, unit, ch.target, ch.negate).spec()}'"


def _check_against_lock(where: Path, columns: dict, chosen: dict, params: Parameters,
                        line_numbers: list[int] | None) -> None:
    limits = _lock_limits(params)
    for target in (ANGLE, RACK):
        if target not in columns or target not in chosen:
            continue
        values = columns[target]
        magnitude = np.abs(values)
        peak = float(magnitude.max())
        if peak <= limits[target]:
            continue
        row = int(np.argmax(magnitude > limits[target])) + 1
        line = f" (line {line_numbers[row - 1]})" if line_numbers is not None else ""
        source, ch = chosen[target]
        at = f"{where}: {_source_text(source, ch)}, row {row}{line}"
        unit = UNITS[target]
        lock = _lock_rack_m(params) if target == RACK else params["input.handwheel_lock_angle"]
        ratio = peak / lock
        for words, symbol, scale in UNIT_SUSPECTS[target]:
            if scale / 3.0 < ratio < scale * 3.0:
                raise UsageError(
                    f"{at}: peak {peak:g} {unit} is {ratio:.0f} times the car's lock ({lock:.4g} {unit}); looks like "
                    f"{words} given as {unit}: give the unit, e.g. {_fix_unit_hint(source, ch, symbol)}"
                )
        raise UsageError(
            f"{at}: {values[row - 1]:g} {unit} is beyond the car's lock ({lock:.4g} {unit} from "
            f"input.handwheel_lock_angle and steering.handwheel_to_rack_ratio, {limits[target]:.4g} {unit} with "
            "margin); check the channel's unit and zero, or use the parameter file of this car"
        )


def _rack_speed(time_s: np.ndarray, rack_m: np.ndarray) -> np.ndarray:
    dt = float(np.median(np.diff(time_s)))
    width = max(1, int(round(SPEED_WINDOW_S / dt)))
    padded = np.pad(rack_m, (width // 2, width - 1 - width // 2), mode="edge")
    smooth = np.sum(np.lib.stride_tricks.sliding_window_view(padded, width), axis=-1) / width  # a moving mean
    return np.gradient(smooth, time_s)


def _correlation(a: np.ndarray, b: np.ndarray) -> float | None:
    if np.std(a) == 0.0 or np.std(b) == 0.0:
        return None
    return float(np.corrcoef(a, b)[0, 1])


def _check_signs(where: Path, columns: dict, chosen: dict, derived_rack: bool) -> None:
    """Torque with rack speed, and measured angle with measured rack, correlate positively on a cycle."""
    time_s = columns[TIME]
    if ANGLE in columns and RACK in columns and not derived_rack:
        r = _correlation(columns[ANGLE], columns[RACK])
        if r is not None and r < SIGN_CORRELATION_LIMIT:
            source, ch = chosen[ANGLE]
            raise UsageError(
                f"{where}: handwheel angle and rack move against each other (correlation {r:.2f}); both are "
                f"positive to the right: negate one, e.g. --map '{ch.spec(negate=not ch.negate)}'"
            )
    if TORQUE in columns and RACK in columns:
        r = _correlation(columns[TORQUE], _rack_speed(time_s, columns[RACK]))
        if r is not None and r < SIGN_CORRELATION_LIMIT:
            source, ch = chosen[TORQUE]
            moving = "handwheel angle" if derived_rack else "rack"
            raise UsageError(
                f"{where}: torque opposes the {moving}'s motion through the cycle (correlation {r:.2f} with its speed); "
                f"torque and {moving} are positive turning right: negate one, e.g. --map "
                f"'{ch.spec(negate=not ch.negate)}'"
            )


# ------------------------------------------------------------------------------------------------ reader

def _fill(metadata: dict[str, str], key: str, value: str | None) -> None:
    """A value the caller gives fills what the file does not state; the caller decides about a conflict."""
    if value is not None and key not in metadata:
        metadata[key] = value


def read_record_bytes(path: Path) -> bytes:
    """The bytes of a record file, refused in one line beyond MAX_RECORD_BYTES, unreadable, or a link loop."""
    try:
        size = path.stat().st_size if path.is_file() else 0
        if size > MAX_RECORD_BYTES:
            raise UsageError(f"{path}: {size / 2**20:.0f} MiB is beyond the {MAX_RECORD_BYTES / 2**20:.0f} MiB a "
                             f"record may have; cut it to the steering cycles or decimate it to {METHOD_RATE_HZ:g} Hz")
        raw = path.read_bytes()
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise UsageError(f"{path}: a symbolic link loop (a link that leads back to itself); point it at the "
                             "record file") from None
        raise UsageError(cannot_read(path, exc)) from None
    if len(raw) > MAX_RECORD_BYTES:
        raise UsageError(f"{path}: more than {MAX_RECORD_BYTES / 2**20:.0f} MiB, the most a record may have; cut it "
                         f"to the steering cycles or decimate it to {METHOD_RATE_HZ:g} Hz")
    return raw


def _on_one_time_base(path: Path, record: Record, chosen: dict, listing: str) -> None:
    """Fill each chosen source's values on one time base: a shared time base's columns as they are; channels
    with time stamps of their own resampled onto the torque channel's (the signal the model is judged on), within
    the span every used channel covers."""
    if record.shared_time_base:
        for src, _ in chosen.values():
            src.values = record.samples(src)
        return
    base_target = next((t for t in (TORQUE, RACK, ANGLE) if t in chosen), None)
    if base_target is None:
        raise UsageError(f"{path}: no torque, rack or angle channel (channels: {listing}); map them with --map")
    base = chosen[base_target][0].timestamps
    start = max(src.timestamps[0] for src, _ in chosen.values())
    end = min(src.timestamps[-1] for src, _ in chosen.values())
    base = base[(base >= start) & (base <= end)]
    for src, _ in chosen.values():
        if np.any(np.diff(src.timestamps) <= 0.0):
            raise UsageError(f"{path}: channel {src.name!r}: time stamps do not increase")
        src.values = np.interp(base, src.timestamps, src.values)
    chosen[TIME] = (Source("time", "s", base), Channel("time", "s", TIME, False, "master"))


def load_record(path: str | Path, channel_map: str | list[Channel] | None = None, case: str | None = None,
                surface: str | None = None, params: Parameters | None = None, *,
                required: tuple[str, ...] = REQUIRED_COLUMNS) -> Measurement:
    """Read a measurement (any format of :data:`parksteer.measure.readers.READERS`: native CSV, logger CSV, ASAM
    MDF, and a raw CAN log when `channel_map` carries its bus) into native SI columns on one time base.

    channel_map: a map spec (``"RackPos[mm]=rack_m,..."``) or parsed channels; without one, native column names
    and, when unambiguous, known aliases map the channels. case, surface: fill what the file does not state.
    required: the native columns the caller needs (a rack drive needs only time_s and rack_m); a rack is derived
    from handwheel angle and torque when the file has no rack channel. Notes (an ignored channel, a decimation)
    go to stderr only when the record is read: a refused record gives its one line alone.
    """
    path = Path(path)
    if params is None:
        params = load_parameters()
    if isinstance(channel_map, str):
        channel_map = parse_channel_map(channel_map)
    raw = read_record_bytes(path)
    # A raw CAN log is decoded with the DBC its channel map carries (--dbc, --bus); sign= and scale= are its own.
    bus_only = next((ch for ch in channel_map or [] if ch.sign or ch.scale), None)
    if bus_only is not None and getattr(channel_map, "bus", None) is None:
        raise UsageError(f"{bus_only.origin}: {bus_only.spec()!r}: sign= and scale= apply to a CAN log's "
                         "signals; give the car's DBC (--dbc or --bus)")
    record = reader_for(raw, channel_map).read(raw, path)
    sources, metadata, line_numbers = record.sources, dict(record.metadata), record.line_numbers
    notes: list[str] = list(record.notes)

    chosen = _map_sources(path, sources, channel_map)
    listing = ", ".join(s.name for s in sources)
    if TIME not in chosen and record.shared_time_base:
        raise UsageError(f"{path}: no time channel (channels: {listing}); map one, e.g. --map 'Time[s]=time_s'")
    ignored = [s.name for s in sources if all(s is not src for src, _ in chosen.values())]
    if ignored:
        notes.append(f"{path}: note: ignored channel{'s' if len(ignored) > 1 else ''} {', '.join(ignored)} "
                     f"(not mapped to {', '.join(MAP_TARGETS)})")
    _on_one_time_base(path, record, chosen, listing)

    columns: dict[str, np.ndarray] = {}
    for target, (src, ch) in chosen.items():
        unit = ch.unit or src.unit
        at = f"{path}: channel {src.name!r}"
        try:
            if ch.unit is not None and src.unit is not None and ch.unit != src.unit:
                one = np.ones(1)
                same = to_si(one, ch.unit, target, at)[0] == to_si(one, src.unit, target, at)[0]
            values = to_si(src.values, unit, target, at)
        except UsageError as exc:
            if ch.unit is None or ch.origin in ("alias", "master") or repr(ch.unit) not in str(exc):
                raise
            raise UsageError(f"{exc} (the unit of {ch.origin})") from None
        if ch.unit is not None and src.unit is not None and ch.unit != src.unit and not same:
            raise UsageError(f"{at}: {ch.origin} says [{ch.unit}] but the file says [{src.unit}]; give one unit")
        columns[target] = -values if ch.negate else values
        if src.step and src.full_scale and target != TIME:  # a bus signal's resolution: the quantisation step
            step, full = (abs(float(to_si(np.array([x]), unit, target, at)[0])) for x in (src.step, src.full_scale))
            metadata[f"full_scale_{target}"] = metadata_text(full)
            metadata[f"bits_{target}"] = str(min(32, (round(2.0 * full / step) + 1).bit_length()))
    renamed = [Channel(src.name, ch.unit or src.unit, ch.target, ch.negate).spec() for src, ch in chosen.values()
               if (src.name != ch.target or ch.negate) and ch.origin != "master"]
    if renamed:
        metadata["channel_map"] = ", ".join(renamed)
    _torsion_bar_as_torque(path, columns, chosen, metadata)
    if CURRENT in columns and MOTOR_TORQUE in columns:
        raise UsageError(f"{path}: channels {chosen[CURRENT][0].name!r} ({CURRENT}) and {chosen[MOTOR_TORQUE][0].name!r} "
                         f"({MOTOR_TORQUE}) are both the motor's; map one (the current, if the car's torque constant "
                         "is the file's)")

    _check_against_lock(path, columns, chosen, params, line_numbers)
    derived = False
    if RACK not in columns and RACK in required:
        if ANGLE in columns and TORQUE in columns:
            columns[RACK] = rack_from_handwheel(columns[ANGLE], columns[TORQUE], params)
            s = params.sections["steering"]
            metadata["rack_derived"] = (
                f"from {ANGLE} and {TORQUE} by the column law (parksteer.geometry.rack_from_handwheel): column twist "
                f"T / {s['column_torsional_stiffness']:g} N m/rad, Hooke joint angle {s['hooke_joint_angle']:g} rad "
                f"and phase {s['hooke_joint_phase']:g} rad, ratio {s['handwheel_to_rack_ratio']:g} rad/m"
            )
            derived = True
        else:
            raise UsageError(f"{path}: no rack channel, and no handwheel angle and torque to derive it from "
                             f"(channels: {listing}){_unmapped(ignored)}; map one, e.g. --map 'RackPos[mm]=rack_m'")
    missing = [t for t in required if t not in columns]
    if missing:
        raise UsageError(f"{path}: no channel for {missing[0]!r} (channels: {listing}){_unmapped(ignored)}; map one, "
                         f"e.g. --map 'NAME[{SI_UNITS[missing[0]]}]={missing[0]}'")

    if "case" not in metadata and case is None:
        add = "add '# case: NAME' above the header or " if record.is_text else ""
        raise UsageError(f"{path}: the file names no case; {add}give --case (known: {', '.join(params.case_names)})")
    if "surface" not in metadata and surface is None:
        add = "add '# surface: ground' above the header or " if record.is_text else ""
        raise UsageError(f"{path}: the file names no surface; {add}give --surface ground|air_bearing")
    _fill(metadata, "case", case)
    _fill(metadata, "surface", surface)
    ordered = {name: columns[name] for name in ALLOWED_COLUMNS if name in columns}
    validate_record(path, ordered, metadata, params, line_numbers, required)
    _check_signs(path, ordered, chosen, derived)
    ordered = _decimate(path, ordered, metadata, notes)
    for note in notes:
        sys.stderr.write(note + "\n")
    return Measurement(path=path, columns=ordered, metadata=metadata)


def _torsion_bar_as_torque(path: Path, columns: dict, chosen: dict, metadata: dict[str, str]) -> None:
    """An assisted car's torsion-bar channel read as the torque column, the metadata saying which sensor it is
    (an assisted car has no other torque sensor; see :mod:`parksteer.measure.io`)."""
    if TORSION_BAR not in columns:
        return
    if TORQUE in columns:
        raise UsageError(f"{path}: channels {chosen[TORQUE][0].name!r} ({TORQUE}) and {chosen[TORSION_BAR][0].name!r} "
                         f"({TORSION_BAR}) are both a steering torque; map the one the model is to be judged on")
    if metadata.get("torque_sensor", "torsion_bar") != "torsion_bar":
        raise UsageError(f"{path}: metadata torque_sensor = {metadata['torque_sensor']!r}, but channel "
                         f"{chosen[TORSION_BAR][0].name!r} is mapped to {TORSION_BAR}")
    columns[TORQUE] = columns.pop(TORSION_BAR)
    chosen[TORQUE] = chosen.pop(TORSION_BAR)
    for key in (f"full_scale_{TORSION_BAR}", f"bits_{TORSION_BAR}"):
        if key in metadata:
            metadata[key.replace(TORSION_BAR, TORQUE)] = metadata.pop(key)
    metadata["torque_sensor"] = "torsion_bar"


def _unmapped(ignored: list[str]) -> str:
    """', of which X is not a known channel name' for an error about a missing channel, naming those ignored."""
    if not ignored:
        return ""
    return f", of which {', '.join(ignored)} {'is' if len(ignored) == 1 else 'are'} not a known channel name"


def _decimate(path: Path, columns: dict[str, np.ndarray], metadata: dict[str, str], notes: list[str]
              ) -> dict[str, np.ndarray]:
    """A record sampled faster than METHOD_RATE_HZ, filtered (FIR anti-alias, zero phase) and decimated by the
    largest whole factor that keeps at least that rate; a record with uneven sampling is left as it is."""
    time_s = columns[TIME]
    steps = np.diff(time_s)
    dt = float(np.median(steps))
    factor = int(1.0 / (dt * METHOD_RATE_HZ))
    if factor < 2 or float(steps.max() - steps.min()) > 0.01 * dt or len(time_s) < 40 * factor:
        return columns
    out = {TIME: time_s[::factor]}
    # scipy.signal.decimate's filter (ftype="fir", zero_phase=True), designed without numpy's CPU-dispatched sin
    fir = pm.hamming_lowpass_fir(20 * factor + 1, 1.0 / factor)
    for name, values in columns.items():
        if name != TIME:
            out[name] = pm.fir_decimate(values, fir, factor)[: len(out[TIME])]
    # A converter's levels no longer describe filtered samples, but its rounding stays in them where the signal
    # moves by less than a step (the filter averages rounding errors only across the levels crossed): the step is
    # kept as the column's rounding (Measurement.rounding_step).
    for name in columns:
        step = Measurement(None, {}, metadata).quantisation_step(name) if name != TIME else 0.0
        if step > 0.0:
            metadata[f"rounding_step_{name}"] = repr(step)
    for column in list(metadata):
        if column.startswith("full_scale_") or column == "bits":
            del metadata[column]
    metadata["decimated"] = (f"from {1.0 / dt:.6g} Hz by {factor} to {1.0 / (dt * factor):.6g} Hz with an FIR "
                             "anti-alias filter (parksteer.measure.importers.METHOD_RATE_HZ)")
    notes.append(f"{path}: note: {1.0 / dt:.6g} Hz decimated by {factor} to {1.0 / (dt * factor):.6g} Hz")
    return out


def load_rack_drive(path: str | Path, channel_map: str | list[Channel] | None = None, case: str | None = None,
                    surface: str | None = None, params: Parameters | None = None) -> Measurement:
    """A record that prescribes the rack: time and rack (measured, or derived from angle and torque)."""
    return load_record(path, channel_map, case, surface, params, required=RACK_DRIVE_COLUMNS)
