"""The import layer: every measurement, rack drive or angle record enters through :func:`load_record`.

The file format is the business of its reader (:mod:`parksteer.measure.readers`, one module each, found through
its table ``READERS``); this module maps what a reader gives to the native columns, the same for every format.

A logger export rarely looks like the native format (data/measurements/README.md): its channels have their own
names and units, cells may be separated by semicolons or tabs with a decimal comma, a units row may sit under the
header, and automotive loggers write ASAM MDF. :func:`load_record` reads any of these, maps the channels to the
native names (a channel map, or known aliases when that is unambiguous), converts units with pint, fills the case
and surface the file does not state, derives the rack from the handwheel angle when there is no rack channel, and
then runs the native format's own checks (:func:`parksteer.measure.io.validate_record`) and the plausibility checks
(:mod:`.plausibility`). Every refusal is one :class:`~parksteer.errors.UsageError` line naming the file and the
channel, row or key.

The channel map's syntax and parsing are :mod:`.channel_map`'s, the units' conversion :mod:`.units`'; this module
runs them, in order, on what the reader gives.
"""

from __future__ import annotations

import errno
import sys
from pathlib import Path

import numpy as np

from .. import portable as pm
from ..errors import UsageError, cannot_read
from ..geometry import rack_from_handwheel
from ..names import TORQUE
from ..parameters import Parameters, load_parameters
from .channel_map import (ANGLE, CURRENT, MAP_TARGETS, MOTOR_TORQUE, RACK, SPEED, TIME, TORSION_BAR, Channel,
                          parse_channel_map)
from .io import ALLOWED_COLUMNS, REQUIRED_COLUMNS, Measurement, metadata_text, validate_record
from .plausibility import check_against_lock, check_signs
from .readers import Record, Source, reader_for
from .readers.base import TIME_ALIASES, normal_name, refusal
from .units import SI_UNITS, to_si


RACK_DRIVE_COLUMNS = (TIME, RACK)

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

# Big and fast records. The method resolves a steering cycle's phases over windows of 0.1 s and more, and it is
# shown to work on 50 Hz loggers (data/measurements/example_unladen.csv); 100 samples a second, twice that, carry
# all it uses. A faster record is low-pass filtered (an FIR anti-alias filter, zero phase) and decimated to at
# least that rate on reading, so the work downstream grows with the record's duration, not its sample rate.
# Beyond the caps a record is refused, not read for minutes.
METHOD_RATE_HZ = 100.0
# What the zero-phase filter reads beyond a record's ends: the record reflected through its end sample
# (parksteer.portable.fir_decimate, "antireflect"; scipy.signal.filtfilt's odd padding). Zeros there (scipy's
# default) pull the samples within half the filter of an end toward 0 wherever the record ends away from 0: a torque
# held or a rack off centre at the end, a record cut mid-stroke (its last sample 4.3 N m under the 17.9 N m logged,
# the samples before it ringing); the reflection passes a straight line through unchanged up to the ends.
DECIMATION_PADDING = "antireflect"
MAX_RECORD_BYTES = 256 * 2**20


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
    record = _read(path, channel_map)
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
    columns = _si_columns(path, chosen, metadata)
    _torsion_bar_as_torque(path, columns, chosen, metadata)
    if CURRENT in columns and MOTOR_TORQUE in columns:
        raise UsageError(f"{path}: channels {chosen[CURRENT][0].name!r} ({CURRENT}) and {chosen[MOTOR_TORQUE][0].name!r} "
                         f"({MOTOR_TORQUE}) are both the motor's; map one (the current, if the car's torque constant "
                         "is the file's)")

    check_against_lock(path, columns, chosen, params, line_numbers)
    derived = RACK not in columns and RACK in required
    if derived:
        _derive_rack(path, columns, metadata, params, f"(channels: {listing}){_unmapped(ignored)}")
    missing = [t for t in required if t not in columns]
    if missing:
        raise UsageError(f"{path}: no channel for {missing[0]!r} (channels: {listing}){_unmapped(ignored)}; map one, "
                         f"e.g. --map 'NAME[{SI_UNITS[missing[0]]}]={missing[0]}'")
    _case_and_surface(path, metadata, case, surface, record.is_text, params)
    ordered = {name: columns[name] for name in ALLOWED_COLUMNS if name in columns}
    validate_record(path, ordered, metadata, params, line_numbers, required)
    check_signs(path, ordered, chosen, derived)
    ordered = _decimate(path, ordered, metadata, notes)
    for note in notes:
        sys.stderr.write(note + "\n")
    return Measurement(path=path, columns=ordered, metadata=metadata)


def _read(path: Path, channel_map: list[Channel] | None) -> Record:
    """The record as the readers' table reads it: a raw CAN log is decoded with the DBC its channel map carries
    (--dbc, --bus); sign= and scale= are its own."""
    raw = read_record_bytes(path)
    bus_only = next((ch for ch in channel_map or [] if ch.sign or ch.scale), None)
    if bus_only is not None and getattr(channel_map, "bus", None) is None:
        raise UsageError(f"{bus_only.origin}: {bus_only.spec()!r}: sign= and scale= apply to a CAN log's "
                         "signals; give the car's DBC (--dbc or --bus)")
    return reader_for(raw, channel_map).read(raw, path)


def _si_columns(path: Path, chosen: dict, metadata: dict[str, str]) -> dict[str, np.ndarray]:
    """Each chosen source in its column's SI unit, negated where the map says; a unit the map and the file state
    differently is refused; a bus signal's resolution goes into the metadata (full scale and bits)."""
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
    return columns


def _derive_rack(path: Path, columns: dict, metadata: dict[str, str], params: Parameters, channels: str) -> None:
    """The rack from the handwheel angle and torque by the column law, said in the metadata; refused without them
    (`channels`: the file's channels, for the refusal)."""
    if ANGLE not in columns or TORQUE not in columns:
        raise UsageError(f"{path}: no rack channel, and no handwheel angle and torque to derive it from "
                         f"{channels}; map one, e.g. --map 'RackPos[mm]=rack_m'")
    columns[RACK] = rack_from_handwheel(columns[ANGLE], columns[TORQUE], params)
    s = params.sections["steering"]
    metadata["rack_derived"] = (
        f"from {ANGLE} and {TORQUE} by the column law (parksteer.geometry.rack_from_handwheel): column twist "
        f"T / {s['column_torsional_stiffness']:g} N m/rad, Hooke joint angle {s['hooke_joint_angle']:g} rad "
        f"and phase {s['hooke_joint_phase']:g} rad, ratio {s['handwheel_to_rack_ratio']:g} rad/m"
    )


def _case_and_surface(path: Path, metadata: dict[str, str], case: str | None, surface: str | None, is_text: bool,
                      params: Parameters) -> None:
    """The case and surface the caller gives fill what the file does not state; refused when neither says."""
    if "case" not in metadata and case is None:
        add = "add '# case: NAME' above the header or " if is_text else ""
        raise UsageError(f"{path}: the file names no case; {add}give --case (known: {', '.join(params.case_names)})")
    if "surface" not in metadata and surface is None:
        add = "add '# surface: ground' above the header or " if is_text else ""
        raise UsageError(f"{path}: the file names no surface; {add}give --surface ground|air_bearing")
    _fill(metadata, "case", case)
    _fill(metadata, "surface", surface)


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
    """A record sampled faster than METHOD_RATE_HZ, filtered (FIR anti-alias, zero phase, its ends extended by
    DECIMATION_PADDING) and decimated by the largest whole factor that keeps at least that rate; a record with uneven
    sampling is left as it is."""
    time_s = columns[TIME]
    steps = np.diff(time_s)
    dt = float(np.median(steps))
    factor = int(1.0 / (dt * METHOD_RATE_HZ))
    if factor < 2 or float(steps.max() - steps.min()) > 0.01 * dt or len(time_s) < 40 * factor:
        return columns
    out = {TIME: time_s[::factor]}
    # scipy.signal.decimate's filter (ftype="fir", zero_phase=True), designed without numpy's CPU-dispatched sin, its
    # ends extended by reflection (resample_poly's padtype="antireflect") instead of zeros
    fir = pm.hamming_lowpass_fir(20 * factor + 1, 1.0 / factor)
    for name, values in columns.items():
        if name != TIME:
            out[name] = pm.fir_decimate(values, fir, factor, DECIMATION_PADDING)[: len(out[TIME])]
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
