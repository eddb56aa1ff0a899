"""Measurement files read for a diagnosis, and the rack of a record that has none.

:func:`load_measurements` reads and validates the files a diagnosis or a comparison is given. A file with no
rack channel (a car's own bus: handwheel angle and torque) is replayed from a rack derived from the angle through
the model's column, its damper included (:func:`rack_from_angle`); its replay uncertainty comes from the angle
channel's logger carried through the ratio (:func:`rack_logger`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import UsageError
from ..geometry import column_twist, pinion_angle_from_column
from ..parameters import Parameters
from ..names import TORQUE
from .channel_map import ANGLE
from .importers import load_record
from .io import Measurement
from .metrics import noise_floor


@dataclass(frozen=True)
class TorsionBar:
    """An assisted car's torque sensor: the assist effect whose quantities it has (``<assist>.torsion_bar_stiffness``)
    and whether the bar is in the column (a column assist) or on the pinion (pinion, rack and hydraulic gears)."""

    assist: str
    in_column: bool


def load_measurements(paths: list[str | Path], params: Parameters, case: str | None = None,
                      surface: str | None = None, channel_map=None, assist: TorsionBar | None = None
                      ) -> Iterator[tuple[str | Path, Measurement, str, float]]:
    """Read (through :func:`parksteer.measure.importers.load_record`) and validate measurement files, one at a time:
    (path, measurement, its case, the rest resolution of its rack) each. `case` replaces the case every file
    names, `surface` fills the surface a file does not state; an angle-only record's rack is derived through the
    model's column (:func:`rack_from_angle`; with `assist`, an assisted car's torsion bar, through it) and
    its rest resolution is the angle's step carried to the rack (:func:`rack_rounding`; 0 for a measured rack)."""
    if not paths:
        raise UsageError("no measurement file given")
    if case is not None:
        params.case(case)  # one-line error for an unknown case
    for path in paths:
        measurement = load_record(path, channel_map, case=case, surface=surface, params=params)
        if surface is not None and measurement.surface != surface:
            raise UsageError(f"{path}: the file says surface {measurement.surface!r} but --surface is {surface!r}; "
                             "remove one")
        chosen = case or measurement.case
        stated = measurement.extra_offset_m
        if stated is not None and abs(stated - params.case(chosen)["extra_offset"]) > 5e-4:
            raise UsageError(
                f"{path}: extra_offset_m = {stated:g} m but case {chosen} has "
                f"{params.case(chosen)['extra_offset']:g} m; name the matching case (--case)"
            )
        measurement, resolution = with_derived_rack(measurement, params, assist)
        yield path, measurement, chosen, resolution


def with_derived_rack(measurement: Measurement, params: Parameters, assist: TorsionBar | None = None
                      ) -> tuple[Measurement, float]:
    """(the record, the rounding of its rack): an angle-only record with its rack derived through the model's
    column (:func:`rack_from_angle`) and that rack's rounding (:func:`rack_rounding`); a record with a rack as it
    is, its rounding 0."""
    if "rack_derived" in measurement.metadata:
        measurement = rack_from_angle(measurement, params, assist)
    return measurement, rack_rounding(measurement, params)


def rack_rounding(measurement: Measurement, params: Parameters) -> float:
    """The rounding of a rack derived from the handwheel angle (m): the angle's step
    (:meth:`parksteer.measure.io.Measurement.rounding_step`, kept through a decimation) over
    handwheel_to_rack_ratio. A bus's angle is far coarser than its noise, so this rounding is not dithered away;
    0 for a measured rack, whose rounding its own noise dithers, or an angle whose step the file does not state."""
    if "rack_derived" not in measurement.metadata:
        return 0.0
    return measurement.rounding_step(ANGLE) / params.sections["steering"]["handwheel_to_rack_ratio"]


def rack_from_angle(measurement: Measurement, params: Parameters, assist: TorsionBar | None = None) -> Measurement:
    """A copy of an angle-only record (its rack derived by the importer) with the rack derived through the model's
    column: the column angle is the handwheel angle less the twist that passes the measured torque through the
    column's spring and damper, ``c dtwist/dt + k twist = T`` (:func:`parksteer.geometry.column_twist`,
    exact for a torque linear between samples, from the static twist T(0) / k at the first sample), the Hooke joint
    turns it into the pinion angle (:func:`parksteer.geometry.pinion_angle_from_column`) and
    rack = theta_p / handwheel_to_rack_ratio (m). This is the inverse of the replay's own handwheel angle
    (:func:`parksteer.model.numeric.prescribed.solve`: column angle plus that twist). The importer's static law leaves
    the damper out, an error at the reversals several times the angle-derived rack's noise (docs/bus.md).
    The torque's noise reaches the rack only through the twist, divided by k and the ratio (0.1 N m: 5e-7 m), and
    low-passed by the damper.

    Of an assisted car (`assist`, its torsion bar), the torque is the torsion bar's and the bar is in series with
    the column shaft: the twist is through their series stiffness k k_t / (k + k_t), with the damping that keeps
    the column's time constant (as the assist's deflection law); a bar on the pinion (pinion, rack and hydraulic
    gears) reads the column torque through the joint, T_s = T dtheta_c/dtheta_p.
    """
    s = params.sections["steering"]
    columns = measurement.columns
    stiffness, damping = s["column_torsional_stiffness"], s["column_torsional_damping"]
    torque = columns[TORQUE]
    if assist is not None:  # the torsion bar in series with the column shaft (assist_common.series_deflection)
        bar = params[f"{assist.assist}.torsion_bar_stiffness"]
        series = stiffness * bar / (stiffness + bar)
        stiffness, damping = series, damping * series / stiffness
    twist, _ = column_twist(columns["time_s"], torque, stiffness, damping)
    joint = (s["hooke_joint_angle"], s["hooke_joint_phase"])
    pinion = pinion_angle_from_column(columns[ANGLE] - twist, *joint)
    if assist is not None and not assist.in_column:
        # the bar on the pinion reads T_s = T dtheta_c/dtheta_p: the column carries T_s dtheta_p/dtheta_c, the
        # joint's speed ratio taken at the column angle of the first pass (it varies by 1e-4 over the twist)
        column = columns[ANGLE] - twist
        h = 1e-6
        ratio = (pinion_angle_from_column(column + h, *joint) - pinion_angle_from_column(column - h, *joint)) / (2 * h)
        twist, _ = column_twist(columns["time_s"], torque * ratio, stiffness, damping)
        pinion = pinion_angle_from_column(columns[ANGLE] - twist, *joint)
    metadata = dict(measurement.metadata)
    metadata["rack_derived"] = (
        f"from {ANGLE} and {TORQUE} through the model's column (parksteer.measure.column.rack_from_angle): twist "
        f"from c dtwist/dt + k twist = T with k {stiffness:g} N m/rad and c "
        f"{damping:g} N m s/rad, Hooke joint angle {s['hooke_joint_angle']:g} rad and phase "
        f"{s['hooke_joint_phase']:g} rad, ratio {s['handwheel_to_rack_ratio']:g} rad/m"
        + (f"; the torsion bar of {assist.assist} in series" if assist is not None else "")
    )
    return replace(measurement, columns={**columns, "rack_m": pinion / s["handwheel_to_rack_ratio"]},
                   metadata=metadata)


def rack_logger(measurement: Measurement, params: Parameters | None = None) -> tuple[float, int, float] | None:
    """(full scale, bits, analog noise RMS) of the rack channel, if the file states its logger; else None.

    The analog part is the rack's noise (from its second differences) less the rounding's
    step / sqrt(12), root sum of squares, as :func:`parksteer.measure.metrics.noise_floor` splits it.

    A rack derived from the handwheel angle (:func:`rack_from_angle`) has no logger of its own: its noise and
    rounding are the angle channel's, carried through the column to the rack. So its logger is the angle's
    (``full_scale_``/``bits_`` of the angle, the angle's analog noise from its own second differences), each
    divided by handwheel_to_rack_ratio (`params`): the rack's levels are then the angle's steps over the ratio.
    The Hooke joint scales that step by its local speed ratio, between cos(alpha) and 1 / cos(alpha) (0.90 to
    1.11 at 0.45 rad), which the mean ratio leaves out; the torque's share through the twist (module docstring
    of :func:`rack_from_angle`) is twenty times smaller and left out too. Without a stated angle logger, None.
    """
    if "rack_derived" in measurement.metadata:
        if params is None or ANGLE not in measurement.columns:
            return None
        full_scale, bits = measurement.full_scale(ANGLE), measurement.bits(ANGLE)
        if full_scale is None or bits is None:
            return None
        ratio = params.sections["steering"]["handwheel_to_rack_ratio"]
        floor = noise_floor(measurement.columns[ANGLE], measurement.quantisation_step(ANGLE))
        return full_scale / ratio, bits, floor.analog_rms / ratio
    full_scale, bits = measurement.full_scale("rack_m"), measurement.bits("rack_m")
    if full_scale is None or bits is None:
        return None
    floor = noise_floor(measurement.rack_m, measurement.quantisation_step("rack_m"))
    return full_scale, bits, floor.analog_rms
