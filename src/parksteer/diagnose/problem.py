"""The data of a comparison or a diagnosis: measurement files, their smoothed racks, noise and weights.

Each file (:class:`FileData`) carries what its residuals need: the measured torque, the phases of its cycle
(:mod:`parksteer.measure.phases`), its noise floor (:mod:`parksteer.measure.metrics`) and, in the files
:func:`parksteer.diagnose.ensemble.with_replay_uncertainty` makes, the replay's own uncertainty at every sample. A
file is never changed: what a diagnosis derives for it (its replay uncertainty, its torque lag, whether its angle is
fitted) goes into a new :class:`FileData` (``dataclasses.replace``) and a new :class:`Problem` that holds it.

A file with no rack channel (a car's own bus: handwheel angle and torque) is replayed from a rack derived from the
angle through the model's column (:mod:`parksteer.measure.column`, which :func:`load_files` reads through).

A file with a handwheel angle beside a measured rack may be fitted on both signals (:attr:`FileData.uses_angle`):
each prediction is then the torque followed by the replayed handwheel angle
(:func:`parksteer.model.numeric.prescribed.solve`), shifted by the fitted zero of the angle sensor. The angle's
attainable error combines its channel's noise floor, the replay ensemble's spread in angle, and the twist a torque
off by its own attainable error would give (:func:`parksteer.model.numeric.prescribed.twist_spread`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import UsageError, naming
from ..measure.column import TorsionBar, load_measurements
from ..measure.channel_map import ANGLE
from ..names import TORQUE
from ..measure.io import Measurement
from ..measure.metrics import NoiseFloor, noise_floor
from ..measure.phases import CyclePhases, find_phases
from ..measure.smoothing import SmoothedRack, smooth_rack
from ..parameters import Parameters
from .settings import DEFAULT_SETTINGS
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


def torsion_bar(assist: str | None) -> TorsionBar | None:
    """The torsion bar of the assist effect named `assist` (None: no assist): in the column for a column assist."""
    if assist is None:
        return None
    from ..model.symbolic.components import discover_effects

    return TorsionBar(assist, discover_effects()[assist].location == "column")


def load_files(paths: list[str | Path], params: Parameters, case: str | None = None, surface: str | None = None,
               channel_map=None, assist: str | None = None) -> list[FileData]:
    """Read and validate measurement files (:func:`parksteer.measure.column.load_measurements`, which says what
    `case`, `surface`, `channel_map` and `assist` do) and prepare each (:func:`prepare_file`); the assist's torsion
    bar is the car's, else its effect's default."""
    if assist is not None:
        from ..model.symbolic.components import with_effect_quantities

        params = with_effect_quantities(params)
    files = []
    for path, measurement, chosen, resolution in load_measurements(paths, params, case, surface, channel_map,
                                                                   torsion_bar(assist)):
        with naming(path):
            files.append(prepare_file(measurement, chosen, rest_resolution_m=resolution))
    return files


class Problem:
    """The files of a comparison or a diagnosis, the parameters and the one setting the replayed signals read.

    A problem is not changed once made: :meth:`with_files` makes a new one (the files derived). It replays
    nothing itself: the replays, their counts and the worker processes are the replay engine's
    (:class:`parksteer.diagnose.engine.ReplayEngine`, which keeps one replay per effect set, file and torque lag, so
    that a file whose lag moved is replayed at its new instants). `angle_offset_fitted` is the setting the replayed
    angle reads (:meth:`parksteer.diagnose.engine.ReplayEngine.signals`). The diagnosis's settings are owned by the
    diagnosis.
    """

    def __init__(self, files, params: Parameters,
                 angle_offset_fitted: bool = DEFAULT_SETTINGS.angle_offset_fitted):
        self.files: tuple[FileData, ...] = tuple(files)
        self.params = params
        self.angle_offset_fitted = angle_offset_fitted

    def with_files(self, files) -> Problem:
        """The same problem on other files (derived from these: the same records, one per index)."""
        return Problem(files, self.params, angle_offset_fitted=self.angle_offset_fitted)

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


