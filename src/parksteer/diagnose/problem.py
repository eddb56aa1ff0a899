"""The data of a comparison or a diagnosis: measurement files, their smoothed racks, noise and weights.

Each file (:class:`FileData`) carries what its residuals need: the measured torque, the
phases of its cycle (:mod:`parksteer.measure.phases`), its noise floor
(:mod:`parksteer.measure.metrics`: quantisation step / sqrt(12) combined with the analog
noise estimated from the data) and, in the files
:func:`parksteer.diagnose.ensemble.with_replay_uncertainty` makes,
the replay's own uncertainty at every sample. A file is never changed: what a diagnosis derives for
it (its replay uncertainty, its torque lag, whether its angle is fitted) goes into a new
:class:`FileData` (``dataclasses.replace``), and into a new :class:`Problem` that holds it.

The replay uncertainty (:mod:`parksteer.diagnose.ensemble`) is found by propagation: the spread of replays of the
racks the data allow equally well.

A file with no rack channel (a car's own bus: handwheel angle and torque) is replayed from a rack derived from
the angle through the model's column, its damper included (:func:`rack_from_angle`, which
:func:`load_files` applies to every record whose importer derived its rack); its replay uncertainty comes from
the angle channel's logger carried through the ratio (:func:`rack_logger`).

A file with a handwheel angle beside a measured rack may be fitted on both signals
(:attr:`FileData.uses_angle`, in the copies the diagnosis makes when its settings ask): each prediction is
then the torque followed by the replayed handwheel angle (column angle plus the twist that
passes the replayed torque, :func:`parksteer.model.numeric.prescribed.solve`), shifted by the
fitted zero of the angle sensor. The angle's attainable error combines its channel's noise
floor, the replay ensemble's spread in angle, and the twist that a torque off by its own
attainable error would give (:func:`parksteer.model.numeric.prescribed.twist_spread`: error / k
on a linear column, a lash's whole band where the torque is that close to zero).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import portable as pm
from ..errors import UsageError, naming
from ..geometry import pinion_angle_from_column
from ..measure.importers import load_record
from ..measure.io import Measurement
from ..measure.metrics import NoiseFloor, noise_floor
from ..measure.phases import CyclePhases, find_phases
from ..measure.smoothing import SmoothedRack, smooth_rack
from ..model.numeric.prescribed import column_twist
from ..parameters import Parameters
from ..measure.converter import quantisation_step
from .settings import DEFAULT_SETTINGS

TORQUE = "handwheel_torque_Nm"
ANGLE = "handwheel_angle_rad"
# An assisted car's motor channel (the second measured signal of its diagnosis), the current preferred.
MOTOR_COLUMNS = ("motor_current_A", "motor_torque_Nm")


@dataclass(frozen=True, eq=False)
class FileData:
    """One measurement file, ready to be replayed (frozen: what a diagnosis derives for it goes into a copy)."""

    label: str
    measurement: Measurement
    case: str
    surface: str
    rack: SmoothedRack
    phases: CyclePhases
    noise: NoiseFloor
    replay_uncertainty_Nm: np.ndarray | None = None
    # each draw's replayed torque less the draws' mean (draws x samples), from the latest estimate
    replay_draws_Nm: np.ndarray | None = None
    # the measured handwheel angle (rad) when the file has one beside a measured rack, and its noise floor
    angle_rad: np.ndarray | None = None
    angle_noise: NoiseFloor | None = None
    # whether the diagnosis fits the angle as a second signal (in the copies parksteer.diagnose.stages makes)
    uses_angle: bool = False
    replay_uncertainty_rad: np.ndarray | None = None
    replay_draws_rad: np.ndarray | None = None
    # how far the torque channel runs behind the rack's (s), estimated by the diagnosis (stages/torque_lag.py)
    torque_lag_s: float = 0.0
    # an assisted car's motor channel (MOTOR_COLUMNS: its name, values and noise floor), and whether the diagnosis
    # fits it as a second signal (in the copies parksteer.diagnose.select makes for an assisted model)
    motor_column: str | None = None
    motor: np.ndarray | None = None
    motor_noise: NoiseFloor | None = None
    uses_motor: bool = False
    replay_uncertainty_motor: np.ndarray | None = None
    replay_draws_motor: np.ndarray | None = None

    @property
    def time_s(self) -> np.ndarray:
        return self.measurement.time_s

    @property
    def replay_time_s(self) -> np.ndarray:
        """The instants the model is replayed at to predict the samples: the torque sample at t_i was taken by
        the sensor at t_i - torque_lag_s on the rack's clock."""
        return self.measurement.time_s - self.torque_lag_s

    @property
    def rack_m(self) -> np.ndarray:
        return self.measurement.rack_m

    @property
    def torque_Nm(self) -> np.ndarray:
        return self.measurement.handwheel_torque_Nm

    @property
    def n(self) -> int:
        return self.measurement.n_samples

    @property
    def sigma_Nm(self) -> np.ndarray:
        """Attainable error at each sample: noise floor combined with the replay uncertainty (if estimated)."""
        delta = self.replay_uncertainty_Nm if self.replay_uncertainty_Nm is not None else np.zeros(self.n)
        return np.sqrt(self.noise.total_rms**2 + delta**2)

    @property
    def sigma_rad(self) -> np.ndarray:
        """Attainable error of the angle at each sample: its noise floor combined with the replay's uncertainty."""
        delta = self.replay_uncertainty_rad if self.replay_uncertainty_rad is not None else np.zeros(self.n)
        return np.sqrt(self.angle_noise.total_rms**2 + delta**2)

    @property
    def sigma_motor(self) -> np.ndarray:
        """Attainable error of the motor channel at each sample: its noise floor combined with the replay's."""
        delta = self.replay_uncertainty_motor if self.replay_uncertainty_motor is not None else np.zeros(self.n)
        return np.sqrt(self.motor_noise.total_rms**2 + delta**2)

    @property
    def signals(self) -> int:
        """Measured signals fitted: the torque, then the handwheel angle and the motor channel where fitted."""
        return 1 + int(self.uses_angle) + int(self.uses_motor)

    @property
    def m(self) -> int:
        """Residuals of the file: its samples times its signals."""
        return self.n * self.signals

    @property
    def measured(self) -> np.ndarray:
        """The fitted signals, stacked: the torque (N m), then with an angle the handwheel angle (rad), then with a
        motor channel the motor's current (A) or torque (N m)."""
        if not (self.uses_angle or self.uses_motor):
            return self.torque_Nm
        return np.concatenate([self.torque_Nm] + ([self.angle_rad] if self.uses_angle else [])
                              + ([self.motor] if self.uses_motor else []))

    @property
    def sigma(self) -> np.ndarray:
        """The attainable error of each fitted signal's samples, stacked as :attr:`measured`."""
        if not (self.uses_angle or self.uses_motor):
            return self.sigma_Nm
        return np.concatenate([self.sigma_Nm] + ([self.sigma_rad] if self.uses_angle else [])
                              + ([self.sigma_motor] if self.uses_motor else []))

    @property
    def replay_draws(self) -> np.ndarray | None:
        """Each draw's replayed signals less the draws' mean, stacked as :attr:`measured`."""
        if not (self.uses_angle or self.uses_motor) or self.replay_draws_Nm is None:
            return self.replay_draws_Nm
        parts = [self.replay_draws_Nm] + ([self.replay_draws_rad] if self.uses_angle else []) \
            + ([self.replay_draws_motor] if self.uses_motor else [])
        return None if any(p is None for p in parts) else np.concatenate(parts, axis=1)

    def torque_part(self, prediction: np.ndarray) -> np.ndarray:
        return prediction[: self.n]

    def angle_part(self, prediction: np.ndarray) -> np.ndarray | None:
        return prediction[self.n : 2 * self.n] if self.uses_angle else None

    def motor_part(self, prediction: np.ndarray) -> np.ndarray | None:
        return prediction[self.m - self.n :] if self.uses_motor else None


def prepare_file(measurement: Measurement, case: str | None = None, label: str | None = None,
                 rest_resolution_m: float = 0.0) -> FileData:
    """Smooth the rack, find the phases and the noise floor of one measurement (`rest_resolution_m`: the rounding
    step of an angle-derived rack, :func:`parksteer.measure.smoothing.smooth_rack`)."""
    case = case or measurement.case
    if TORQUE not in measurement.columns:
        raise UsageError(f"{measurement.path}: no column {TORQUE!r}")
    label = label or (measurement.path.name if measurement.path is not None else "measurement")
    rack = smooth_rack(measurement.time_s, measurement.rack_m, rest_resolution_m=rest_resolution_m)
    phases = find_phases(measurement.time_s, measurement.rack_m, measurement.handwheel_torque_Nm,
                         surface=measurement.surface)
    floor = noise_floor(measurement.handwheel_torque_Nm, measurement.quantisation_step(TORQUE))
    angle = angle_floor = None
    if ANGLE in measurement.columns and "rack_derived" not in measurement.metadata:
        angle = measurement.columns[ANGLE]
        angle_floor = noise_floor(angle, measurement.quantisation_step(ANGLE))
    motor_column = next((c for c in MOTOR_COLUMNS if c in measurement.columns), None)
    motor = motor_floor = None
    if motor_column is not None:  # its noise floor estimated as the torque's (metrics.noise_floor)
        motor = measurement.columns[motor_column]
        motor_floor = noise_floor(motor, measurement.quantisation_step(motor_column))
    return FileData(label, measurement, case, measurement.surface, rack, phases, floor, angle_rad=angle,
                    angle_noise=angle_floor, motor_column=motor_column, motor=motor, motor_noise=motor_floor)


def load_files(paths: list[str | Path], params: Parameters, case: str | None = None, surface: str | None = None,
               channel_map=None, assist: str | None = None) -> list[FileData]:
    """Read (through :func:`parksteer.measure.importers.load_record`), validate and prepare measurement files;
    `case` replaces the case every file names, `surface` fills the surface a file does not state; `assist` (an
    assisted car's effect) derives an angle-only record's rack through its torsion bar (:func:`rack_from_angle`)."""
    if not paths:
        raise UsageError("no measurement file given")
    if case is not None:
        params.case(case)  # one-line error for an unknown case
    files = []
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
        resolution = 0.0
        if "rack_derived" in measurement.metadata:
            measurement = rack_from_angle(measurement, params, assist)
            logger = rack_logger(measurement, params)
            resolution = 0.0 if logger is None else quantisation_step(logger[0], logger[1])
        with naming(path):
            files.append(prepare_file(measurement, chosen, rest_resolution_m=resolution))
    return files


def rack_from_angle(measurement: Measurement, params: Parameters, assist: str | None = None) -> Measurement:
    """A copy of an angle-only record (its rack derived by the importer) with the rack derived through the model's
    column: the column angle is the handwheel angle less the twist that passes the measured torque through the
    column's spring and damper, ``c dtwist/dt + k twist = T`` (:func:`parksteer.model.numeric.prescribed.column_twist`,
    exact for a torque linear between samples, from the static twist T(0) / k at the first sample), the Hooke joint
    turns it into the pinion angle (:func:`parksteer.geometry.pinion_angle_from_column`) and
    rack = theta_p / handwheel_to_rack_ratio. This is the inverse of the replay's own handwheel angle
    (:func:`parksteer.model.numeric.prescribed.solve`: column angle plus that twist).

    The importer's static column law (:func:`parksteer.geometry.rack_from_handwheel`, twist T / k) leaves out the
    damper: the twist lags the torque by c / k (0.2 s on the paper's car), and where the torque swings at a reversal
    the static twist is off by (c / k) dtwist/dt, up to 4.8e-3 rad at the handwheel, a 26 um rack error, five times
    the angle-derived rack's own noise (a 14-bit angle on +-16 rad: 1.05e-5 m steps). That error sits at the
    reversals, where the rack friction flips, and made a null record unexplained. The torque's noise reaches the
    rack through the twist only, divided by k and the ratio (0.1 N m: 5e-7 m) and low-passed by the damper.

    Of an assisted car (`assist`, the effect's name), the torque is the torsion bar's and the bar is in series with
    the column shaft: the twist is through their series stiffness k k_t / (k + k_t), with the damping that keeps
    the column's time constant (as the assist's deflection law); a bar on the pinion (pinion, rack and hydraulic
    gears) reads the column torque through the joint, T_s = T dtheta_c/dtheta_p.
    """
    s = params.sections["steering"]
    columns = measurement.columns
    stiffness, damping = s["column_torsional_stiffness"], s["column_torsional_damping"]
    torque = columns[TORQUE]
    if assist is not None:  # the torsion bar in series with the column shaft (assist_common.series_deflection)
        bar = params[f"{assist}.torsion_bar_stiffness"]
        series = stiffness * bar / (stiffness + bar)
        stiffness, damping = series, damping * series / stiffness
    twist, _ = column_twist(columns["time_s"], torque, stiffness, damping)
    joint = (s["hooke_joint_angle"], s["hooke_joint_phase"])
    pinion = pinion_angle_from_column(columns[ANGLE] - twist, *joint)
    if assist is not None and not assist.endswith("_column"):
        # the bar on the pinion reads T_s = T dtheta_c/dtheta_p: the column carries T_s dtheta_p/dtheta_c, the
        # joint's speed ratio taken at the column angle of the first pass (it varies by 1e-4 over the twist)
        column = columns[ANGLE] - twist
        h = 1e-6
        ratio = (pinion_angle_from_column(column + h, *joint) - pinion_angle_from_column(column - h, *joint)) / (2 * h)
        twist, _ = column_twist(columns["time_s"], torque * ratio, stiffness, damping)
        pinion = pinion_angle_from_column(columns[ANGLE] - twist, *joint)
    metadata = dict(measurement.metadata)
    metadata["rack_derived"] = (
        f"from {ANGLE} and {TORQUE} through the model's column (parksteer.diagnose.problem.rack_from_angle): twist "
        f"from c dtwist/dt + k twist = T with k {stiffness:g} N m/rad and c "
        f"{damping:g} N m s/rad, Hooke joint angle {s['hooke_joint_angle']:g} rad and phase "
        f"{s['hooke_joint_phase']:g} rad, ratio {s['handwheel_to_rack_ratio']:g} rad/m"
        + (f"; the torsion bar of {assist} in series" if assist is not None else "")
    )
    return replace(measurement, columns={**columns, "rack_m": pinion / s["handwheel_to_rack_ratio"]},
                   metadata=metadata)


class Problem:
    """The files of a comparison or a diagnosis, the parameters and the one setting the replayed signals read.

    A problem is not changed once made: :meth:`with_files` makes a new one (the files derived). It replays
    nothing itself: the replays, their counts and the worker processes are the replay engine's
    (:class:`parksteer.diagnose.engine.ReplayEngine`). `angle_offset_fitted` is the setting the replayed angle
    reads (:meth:`parksteer.diagnose.engine.ReplayEngine.signals`); `instants` numbers the generation of the files'
    replay instants (a new one when a torque lag moves), so that the engine's replays are made again at the new
    instants. The diagnosis's settings are owned by the diagnosis.
    """

    def __init__(self, files, params: Parameters,
                 angle_offset_fitted: bool = DEFAULT_SETTINGS.angle_offset_fitted, instants: int = 0):
        self.files: tuple[FileData, ...] = tuple(files)
        self.params = params
        self.angle_offset_fitted = angle_offset_fitted
        self.instants = instants

    def with_files(self, files, new_instants: bool = False) -> Problem:
        """The same problem on other files (derived from these: the same records, one per index).

        With `new_instants` (a file's torque lag moved), the replays made so far are not this problem's: each is
        made again at the files' instants when first asked for (the solves already run stay counted). Without,
        the replays made so far are kept, at the instants they were made for: a lag moved by less than a search
        step keeps them (parksteer.diagnose.stages.torque_lag)."""
        return Problem(files, self.params, angle_offset_fitted=self.angle_offset_fitted,
                       instants=self.instants + 1 if new_instants else self.instants)

    @property
    def n(self) -> int:
        """Residuals of all files: every fitted signal's samples (the torque's, and the angle's where fitted)."""
        return sum(f.m for f in self.files)

    @property
    def uses_angle(self) -> bool:
        return any(f.uses_angle for f in self.files)

    def weighted(self, predictions: list[np.ndarray]) -> np.ndarray:
        """Weighted residuals (measured - model) / sigma_i of all files, concatenated."""
        return np.concatenate([(f.measured - m) / f.sigma for f, m in zip(self.files, predictions)])

    def scale(self, values: list[np.ndarray]) -> np.ndarray:
        """Model differences divided by sigma_i, concatenated (the weighted units of a sensitivity)."""
        return np.concatenate([v / f.sigma for f, v in zip(self.files, values)])

    def in_torque_floors(self, values: list[np.ndarray]) -> np.ndarray:
        """Model differences with each angle sample rescaled by the torque's over the angle's noise floor: a change
        of one angle floor counts as one torque floor (N m), so that torque and angle changes add up."""
        return np.concatenate([_in_torque_floors(f, v) for f, v in zip(self.files, values)])

def _in_torque_floors(f: FileData, v: np.ndarray) -> np.ndarray:
    """`v` (a file's stacked signals) with the angle's and the motor's samples in torque floors per own floor."""
    if not (f.uses_angle or f.uses_motor):
        return v
    parts = [v[: f.n]]
    if f.uses_angle:
        parts.append(f.angle_part(v) * (f.noise.total_rms / f.angle_noise.total_rms))
    if f.uses_motor:
        parts.append(f.motor_part(v) * (f.noise.total_rms / f.motor_noise.total_rms))
    return np.concatenate(parts)


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


def fit_statistics(problem: Problem, predictions: list[np.ndarray]) -> dict:
    """Plain and weighted RMS, the noise floor and the attainable floor over all files.

    ``weighted_rms_Nm`` is sqrt(mean(r_i^2 floor_f^2)) with r_i the weighted residual and
    floor_f the file's noise floor: it equals the noise floor for a perfect model, and
    sqrt(floor^2 + e^2) for a model off by e where the replay is certain.
    """
    files = problem.files
    residual = np.concatenate([f.torque_Nm - f.torque_part(m) for f, m in zip(files, predictions)])
    weighted = problem.weighted(predictions)
    is_torque = np.concatenate([np.arange(f.m) < f.n for f in files])
    floors = np.concatenate([np.full(f.n, f.noise.total_rms) for f in files])
    attainable = np.concatenate([f.sigma_Nm for f in files])
    floor = float(np.sqrt(np.mean(floors**2)))
    out = {
        "rms_Nm": float(np.sqrt(np.mean(residual**2))),
        "peak_Nm": float(np.max(np.abs(residual))),
        "weighted_rms_Nm": float(np.sqrt(np.mean((weighted[is_torque] * floors) ** 2))),
        "noise_floor_Nm": floor,
        "attainable_floor_Nm": float(np.sqrt(np.mean(attainable**2))),
        "weighted_rss": float(np.sum(weighted**2)),
        "samples": int(weighted.size),
    }
    with_angle = [(f, m) for f, m in zip(files, predictions) if f.uses_angle]
    if with_angle:  # the angle's residual beside the torque's (the same definitions, in rad and degrees)
        angle = np.concatenate([f.angle_rad - f.angle_part(m) for f, m in with_angle])
        angle_floors = np.concatenate([np.full(f.n, f.angle_noise.total_rms) for f, _ in with_angle])
        angle_weighted = np.concatenate([(f.angle_rad - f.angle_part(m)) / f.sigma_rad for f, m in with_angle])
        angle_attainable = np.concatenate([f.sigma_rad for f, _ in with_angle])
        rms = float(np.sqrt(np.mean(angle**2)))
        out["angle"] = {
            "rms_rad": rms,
            "rms_deg": math.degrees(rms),
            "peak_rad": float(np.max(np.abs(angle))),
            "weighted_rms_rad": float(np.sqrt(np.mean((angle_weighted * angle_floors) ** 2))),
            "noise_floor_rad": float(np.sqrt(np.mean(angle_floors**2))),
            "attainable_floor_rad": float(np.sqrt(np.mean(angle_attainable**2))),
            "weighted_rss": float(np.sum(angle_weighted**2)),
            "samples": int(angle.size),
        }
    with_motor = [(f, m) for f, m in zip(files, predictions) if f.uses_motor]
    if with_motor:  # an assisted car's motor channel beside the torque (in its own unit, A or N m)
        motor = np.concatenate([f.motor - f.motor_part(m) for f, m in with_motor])
        motor_floors = np.concatenate([np.full(f.n, f.motor_noise.total_rms) for f, _ in with_motor])
        motor_weighted = np.concatenate([(f.motor - f.motor_part(m)) / f.sigma_motor for f, m in with_motor])
        out["motor"] = {
            "column": with_motor[0][0].motor_column,
            "rms": float(np.sqrt(np.mean(motor**2))),
            "peak": float(np.max(np.abs(motor))),
            "weighted_rms": float(np.sqrt(np.mean((motor_weighted * motor_floors) ** 2))),
            "noise_floor": float(np.sqrt(np.mean(motor_floors**2))),
            "weighted_rss": float(np.sum(motor_weighted**2)),
            "samples": int(motor.size),
        }
    return out


def pooled_lag1(segments) -> float:
    """Lag-1 autocorrelation pooled over `segments` (arrays; pairs within a segment, each about its own mean)."""
    num = den = 0.0
    for r in segments:
        r = r - r.mean()
        num += float(np.sum(r[1:] * r[:-1]))
        den += float(np.sum(r * r))
    return num / den if den > 0 else 0.0


def lag1_autocorrelation(problem: Problem, weighted: np.ndarray) -> float:
    """Lag-1 autocorrelation of the weighted residuals, pooled over files (pairs within a file and signal)."""
    bounds = np.cumsum([0] + [f.n for f in problem.files for _ in range(f.signals)])
    return pooled_lag1(weighted[a:b] for a, b in zip(bounds[:-1], bounds[1:]))


def effective_samples(n: int, rho: float) -> float:
    """n (1 - rho) / (1 + rho) for AR(1)-like residuals, rho clipped to [0, 0.95]."""
    rho = min(max(rho, 0.0), 0.95)
    return max(n * (1.0 - rho) / (1.0 + rho), 2.0)


def bic_gain(rss_without: float, rss_with: float, n_eff: float, parameters: int) -> float:
    """The fall of the BIC over the effective sample size, ``BIC = n_eff ln(RSS / n) + k ln(n_eff)``, when
    `parameters` more columns take the weighted residual sum of squares from `rss_without` to `rss_with`:
    ``n_eff ln(rss_without / rss_with) - k ln(n_eff)`` (positive: the richer model is the better)."""
    return n_eff * pm.log(rss_without / max(rss_with, 1e-300)) - parameters * pm.log(n_eff)
