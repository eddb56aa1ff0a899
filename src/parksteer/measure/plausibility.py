"""A record's plausibility against the car (the parameter file's lock and ratio) and against itself (the signs of
torque, angle and rack over a steering cycle): what would make a comparison with the model meaningless, refused."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..names import TORQUE
from ..parameters import Parameters
from .channel_map import ANGLE, RACK, TIME, Channel
from .io import UNITS
from .readers.base import Source

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


def check_against_lock(where: Path, columns: dict, chosen: dict, params: Parameters,
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


def check_signs(where: Path, columns: dict, chosen: dict, derived_rack: bool) -> None:
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
