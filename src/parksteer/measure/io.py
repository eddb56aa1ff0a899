"""Measurement files: read, validate and write handwheel torque against rack displacement.

A measurement file is UTF-8 CSV. Leading ``# key: value`` lines carry metadata, then one
header row names the columns, then one row per sample::

    # case: unladen
    # surface: ground
    # source: Maestro test 3, 12 May
    time_s,rack_m,handwheel_torque_Nm
    0,0,0.1
    0.02,0.0003,2.4

Columns (SI units; the unit is part of the name): required ``time_s`` (strictly increasing), ``rack_m`` (positive
to the right), ``handwheel_torque_Nm``; optional ``handwheel_angle_rad``, ``load_left_N``, ``load_right_N``,
``vehicle_speed_mps``, and of an assisted car ``motor_current_A`` or ``motor_torque_Nm``. An assisted car's record
may carry the torsion-bar torque in ``handwheel_torque_Nm`` with ``torque_sensor: torsion_bar`` (default
``handwheel``).

Metadata: ``case`` (a case of the parameter file) and ``surface`` (``ground`` or ``air_bearing``) are required;
``extra_offset_m`` (spacer offset, m) and ``source`` are optional; ``full_scale_<column>`` (in the column's unit)
and ``bits`` (or ``bits_<column>`` for a channel with a converter of its own) give the quantisation step. Any other
key is kept as text.

Every defect is refused with a :class:`~parksteer.errors.UsageError` whose one-line message
names the file and, where it applies, the column and the data row (1-based, the first row
after the header is row 1) with its line number in the file.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UsageError, cannot_read
from .converter import quantisation_step
from ..names import SURFACES, TORQUE
from ..parameters import Parameters, load_parameters
from ..tables import atomic_path, format_number, format_numbers
from .text_table import parse_number, read_table

REQUIRED_COLUMNS = ("time_s", "rack_m", TORQUE)
OPTIONAL_COLUMNS = ("handwheel_angle_rad", "load_left_N", "load_right_N")
# The car's speed (a CAN log's speed signal; 0 in a standstill parking test): a column of measured records only,
# kept out of OPTIONAL_COLUMNS, which the synthetic records take as the model's recorded channels.
# The assist motor's current or torque: a second measured signal of an assisted car (its control unit's).
MEASURED_ONLY_COLUMNS = ("vehicle_speed_mps", "motor_current_A", "motor_torque_Nm")
ALLOWED_COLUMNS = REQUIRED_COLUMNS + OPTIONAL_COLUMNS + MEASURED_ONLY_COLUMNS
UNITS = {
    "time_s": "s",
    "rack_m": "m",
    TORQUE: "N m",
    "handwheel_angle_rad": "rad",
    "load_left_N": "N",
    "load_right_N": "N",
    "vehicle_speed_mps": "m/s",
    "motor_current_A": "A",
    "motor_torque_Nm": "N m",
}
# What sensor the torque column holds (metadata torque_sensor): the handwheel's, or an assisted car's torsion bar.
TORQUE_SENSORS = ("handwheel", "torsion_bar")
REQUIRED_METADATA = ("case", "surface")

# A lock-to-lock cycle has up to nine phase segments (initial rise; wind-up and sliding on
# each of three strokes; two reversals; the return); the phase finder needs several samples
# in each to tell a level from a slope, so fewer than 50 samples cannot describe a cycle.
MIN_SAMPLES = 50

# Plausibility limits. A car's rack travels about +-0.07 m (the Maestro: +-0.067 m), so a
# rack beyond 0.2 m is almost certainly written in millimetres. Parking torques are tens of
# N m; beyond 200 N m no driver could turn the wheel, so the column is mislabelled or
# scaled. The handwheel lock is about +-12.6 rad (two turns); beyond 30 rad (nearly five
# turns) the angle is in degrees. A front wheel carries about 3 kN; beyond 20 kN the load
# is not in newtons, and loads that never exceed 20 in magnitude are in kilonewtons.
RACK_LIMIT_M = 0.2
TORQUE_LIMIT_NM = 200.0
ANGLE_LIMIT_RAD = 30.0
LOAD_LIMIT_N = 20000.0
LOAD_KILONEWTON_SUSPICION_N = 20.0
# An EPS motor draws up to about 100 A (peak torques 3-6 N m at 0.03-0.07 N m/A); beyond 500 A the channel is in
# mA or scaled. Motor torques are a few N m; beyond 50 N m the channel is the assist at the column or rack.
MOTOR_CURRENT_LIMIT_A = 500.0
MOTOR_TORQUE_LIMIT_NM = 50.0
EXTRA_OFFSET_LIMIT_M = 0.2
# A steering cycle moves the rack to a lock (tens of millimetres); a rack that spans less than half a millimetre,
# the size of the rack lash, holds no cycle to compare, smooth or replay.
RACK_MOTION_MIN_M = 5.0e-4


@dataclass(frozen=True)
class Measurement:
    """One validated measurement: float columns keyed by name, and the metadata as text."""

    path: Path | None
    columns: dict[str, np.ndarray]
    metadata: dict[str, str] = field(default_factory=dict)

    @property
    def time_s(self) -> np.ndarray:
        return self.columns["time_s"]

    @property
    def rack_m(self) -> np.ndarray:
        return self.columns["rack_m"]

    @property
    def handwheel_torque_Nm(self) -> np.ndarray:
        return self.columns[TORQUE]

    @property
    def torque_sensor(self) -> str:
        """``handwheel``, or ``torsion_bar`` for an assisted car's record (metadata torque_sensor)."""
        return self.metadata.get("torque_sensor", "handwheel")

    @property
    def case(self) -> str:
        return self.metadata["case"]

    @property
    def surface(self) -> str:
        return self.metadata["surface"]

    @property
    def extra_offset_m(self) -> float | None:
        """The spacer offset stated in the file, or None when the file leaves it to the case."""
        value = self.metadata.get("extra_offset_m")
        return None if value is None else float(value)

    @property
    def n_samples(self) -> int:
        return len(self.time_s)

    @property
    def duration_s(self) -> float:
        return float(self.time_s[-1] - self.time_s[0])

    @property
    def sample_interval_s(self) -> float:
        """Median sample interval (robust to the odd missing sample)."""
        return float(np.median(np.diff(self.time_s)))

    @property
    def is_synthetic(self) -> bool:
        return self.metadata.get("synthetic", "false").strip().lower() == "true"

    def full_scale(self, column: str) -> float | None:
        """The logger's full scale for `column` (its unit), if the file states it."""
        value = self.metadata.get(f"full_scale_{column}")
        return None if value is None else float(value)

    def bits(self, column: str) -> int | None:
        """The converter bits of `column`: its own ``bits_<column>`` if the file states one, else ``bits``."""
        value = self.metadata.get(f"bits_{column}", self.metadata.get("bits"))
        return None if value is None else int(value)

    def quantisation_step(self, column: str) -> float:
        """The logger's step for `column`: 2 full_scale / (2**bits - 1); 0 if the file does not say."""
        full_scale, bits = self.full_scale(column), self.bits(column)
        if full_scale is None or bits is None:
            return 0.0
        return quantisation_step(full_scale, bits)

    def rounding_step(self, column: str) -> float:
        """The step `column` was rounded to: the logger's (:meth:`quantisation_step`), or, where the import
        filtered the samples off the converter's levels (a decimation), the step the converter had
        (``rounding_step_<column>``); 0 if neither is known."""
        return self.quantisation_step(column) or float(self.metadata.get(f"rounding_step_{column}", 0.0))


def _where(path: Path | str, column: str, row: int, line_numbers: list[int] | None) -> str:
    """'file: column 'c', row r (line l)' for data row `row` (1-based)."""
    line = f" (line {line_numbers[row - 1]})" if line_numbers is not None else ""
    return f"{path}: column {column!r}, row {row}{line}"


def _validate_metadata(where: Path | str, metadata: Mapping[str, str], params: Parameters) -> None:
    for key in REQUIRED_METADATA:
        if key not in metadata:
            raise UsageError(f"{where}: missing metadata line '# {key}: ...'")
    if metadata["case"] not in params.case_names:
        known = ", ".join(params.case_names)
        raise UsageError(f"{where}: unknown case {metadata['case']!r} (known: {known})")
    if metadata["surface"] not in SURFACES:
        raise UsageError(f"{where}: unknown surface {metadata['surface']!r} (known: {', '.join(SURFACES)})")
    if metadata.get("torque_sensor", "handwheel") not in TORQUE_SENSORS:
        raise UsageError(f"{where}: metadata torque_sensor = {metadata['torque_sensor']!r} (known: "
                         f"{', '.join(TORQUE_SENSORS)})")
    if "extra_offset_m" in metadata:
        offset = parse_number(metadata["extra_offset_m"], f"{where}: metadata extra_offset_m")
        if offset > EXTRA_OFFSET_LIMIT_M:
            raise UsageError(
                f"{where}: metadata extra_offset_m = {offset:g} looks like millimetres; convert to metres"
            )
        if offset < 0.0:
            raise UsageError(f"{where}: metadata extra_offset_m = {offset:g} is negative (spacers add offset)")
    for key, value in metadata.items():
        if key == "bits" or key.startswith("bits_"):
            bits = value.strip()
            if not bits.isdigit() or not 1 <= int(bits) <= 32:
                raise UsageError(f"{where}: metadata {key} = {bits!r} is not a whole number of bits from 1 to 32")
            if key != "bits" and key[len("bits_"):] not in ALLOWED_COLUMNS:
                raise UsageError(f"{where}: metadata {key} names no known column ({', '.join(ALLOWED_COLUMNS)})")
        if key.startswith("full_scale_"):
            column = key[len("full_scale_"):]
            if column not in ALLOWED_COLUMNS:
                raise UsageError(f"{where}: metadata {key} names no known column ({', '.join(ALLOWED_COLUMNS)})")
            if parse_number(value, f"{where}: metadata {key}") <= 0.0:
                raise UsageError(f"{where}: metadata {key} = {value} must be positive")


def _first_row(mask: np.ndarray) -> int:
    """1-based row of the first True in `mask`."""
    return int(np.argmax(mask)) + 1


def _check_column_names(where: Path | str, names: list[str], required: tuple[str, ...] = REQUIRED_COLUMNS) -> None:
    for name in required:
        if name not in names:
            raise UsageError(f"{where}: missing required column {name!r} (required: {', '.join(required)})")
    for name in names:
        if name not in ALLOWED_COLUMNS:
            raise UsageError(f"{where}: unknown column {name!r} (allowed: {', '.join(ALLOWED_COLUMNS)})")


def _validate_columns(where: Path | str, columns: Mapping[str, np.ndarray], line_numbers: list[int] | None,
                      required: tuple[str, ...] = REQUIRED_COLUMNS) -> None:
    names = list(columns)
    _check_column_names(where, names, required)
    lengths = {len(columns[n]) for n in names}
    if len(lengths) != 1:
        raise UsageError(f"{where}: columns have different lengths {sorted(lengths)}")
    for name in names:
        bad = ~np.isfinite(columns[name])
        if bad.any():
            row = _first_row(bad)
            raise UsageError(f"{_where(where, name, row, line_numbers)}: value {columns[name][row - 1]} is not finite")
    n = lengths.pop()
    if n < MIN_SAMPLES:
        raise UsageError(
            f"{where}: {n} samples; at least {MIN_SAMPLES} are needed to resolve the phases of a steering cycle"
        )

    time_s = columns["time_s"]
    steps = np.diff(time_s)
    if (steps <= 0.0).any():
        row = _first_row(steps <= 0.0) + 1
        raise UsageError(
            f"{_where(where, 'time_s', row, line_numbers)}: time {time_s[row - 1]:g} s does not increase "
            f"(previous row {time_s[row - 2]:g} s); time must be strictly increasing"
        )

    def check_limit(name: str, limit: float, advice: str) -> None:
        if name in columns:
            magnitude = np.abs(columns[name])
            if magnitude.max() > limit:
                row = _first_row(magnitude > limit)
                unit = UNITS[name]
                raise UsageError(
                    f"{_where(where, name, row, line_numbers)}: {columns[name][row - 1]:g} {unit} is beyond "
                    f"+-{limit:g} {unit}; {advice}"
                )

    if "rack_m" in columns:
        span = float(np.ptp(columns["rack_m"]))
        if span < RACK_MOTION_MIN_M:
            raise UsageError(
                f"{where}: column 'rack_m': the rack never moves (it spans {span:.3g} m, less than "
                f"{RACK_MOTION_MIN_M:g} m), so the record holds no steering cycle"
            )
    check_limit("rack_m", RACK_LIMIT_M, "looks like millimetres; convert to metres (a car rack travels about 0.07 m)")
    check_limit(
        TORQUE,
        TORQUE_LIMIT_NM,
        "implausible handwheel torque (parking torques are tens of N m); check the column's unit and scale",
    )
    check_limit("handwheel_angle_rad", ANGLE_LIMIT_RAD, "looks like degrees; convert to radians")
    check_limit("motor_current_A", MOTOR_CURRENT_LIMIT_A,
                "implausible motor current (EPS motors draw up to about 100 A); check the unit (mA?) and scale")
    check_limit("motor_torque_Nm", MOTOR_TORQUE_LIMIT_NM,
                "implausible motor torque (EPS motors give a few N m); is it the assist at the column or rack?")
    for name in ("load_left_N", "load_right_N"):
        check_limit(name, LOAD_LIMIT_N, "implausible wheel load (a front wheel carries about 3000 N)")
        if name in columns and np.abs(columns[name]).max() < LOAD_KILONEWTON_SUSPICION_N:
            raise UsageError(
                f"{where}: column {name!r}: every load is below {LOAD_KILONEWTON_SUSPICION_N:g} N; "
                "looks like kilonewtons; convert to newtons"
            )


def validate_record(where: Path | str, columns: Mapping[str, np.ndarray], metadata: Mapping[str, str],
                    params: Parameters, line_numbers: list[int] | None = None,
                    required: tuple[str, ...] = REQUIRED_COLUMNS) -> None:
    """Every check of the format on SI columns and metadata, whatever file they came from."""
    _validate_columns(where, columns, line_numbers, required)
    _validate_metadata(where, metadata, params)


def parse_measurement(text: str, where: Path | str, params: Parameters | None = None) -> Measurement:
    """Parse and validate measurement text in the native format; `where` names it in error messages."""
    if params is None:
        params = load_parameters()
    table = read_table(text, where)
    # Name a missing or unknown column before complaining about the rows below it.
    _check_column_names(where, table.header)
    if table.units is not None:
        raise UsageError(
            f"{where}: line {table.header_line + 1}: a units row; the native format has SI units in the column "
            "names (read logger exports through parksteer.measure.importers.load_record, or --map)"
        )
    columns = {name: table.column(j) for j, name in enumerate(table.header)}
    validate_record(where, columns, table.metadata, params, table.line_numbers)
    return Measurement(path=Path(where) if isinstance(where, (str, Path)) else None, columns=columns,
                       metadata=table.metadata)


def read_measurement(path: str | Path, params: Parameters | None = None) -> Measurement:
    """Read and validate a measurement file; raise :class:`UsageError` (one line) on any defect."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise UsageError(cannot_read(path, exc)) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise UsageError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    return parse_measurement(text, path, params)


def metadata_text(value: Any) -> str:
    """How a metadata value is written: booleans as true/false, floats with ten significant digits."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return format_number(value, 10)
    return str(value)


def format_measurement(measurement: Measurement) -> str:
    """The file text for `measurement`: metadata lines, then columns in canonical order."""
    lines = []
    for key, value in measurement.metadata.items():
        text = metadata_text(value)
        if not key or ":" in key or "\n" in key or "\n" in text or key != key.strip():
            raise UsageError(f"metadata key {key!r} or its value cannot be written as '# key: value'")
        lines.append(f"# {key}: {text}")
    names = [n for n in ALLOWED_COLUMNS if n in measurement.columns]
    names += [n for n in measurement.columns if n not in ALLOWED_COLUMNS]  # refused by validation
    lines.append(",".join(names))
    data = [np.asarray(measurement.columns[n], dtype=float) for n in names]
    lengths = {len(c) for c in data}
    if len(lengths) != 1:
        raise UsageError(f"columns have different lengths {sorted(lengths)}")
    lines.extend(map(",".join, zip(*(format_numbers(column, 9) for column in data))))
    return "\n".join(lines) + "\n"


def write_measurement(path: str | Path, measurement: Measurement, params: Parameters | None = None) -> None:
    """Validate `measurement` and write it to `path` atomically.

    The text is parsed back with the reader before anything is written, so a file this
    writes always reads; on any defect nothing is written and the old file is untouched.
    Numbers carry nine significant digits: rounding moves a value by at most 5e-9 of itself.
    """
    path = Path(path)
    text = format_measurement(measurement)
    parse_measurement(text, path, params)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
