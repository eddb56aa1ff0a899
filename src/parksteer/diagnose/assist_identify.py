"""An electric assist's boost table and its gear's hidden numbers identified from the car's own records.

:func:`identify_boost` (``parksteer assist identify``) takes one or more records of an assisted car (the torsion-bar
torque S as the car's bus logs it, the motor current i, the rack or the handwheel angle) and the car's vehicle file
(its gear's data: reduction N, efficiencies, torque constant, rotor inertia, motor limit) and gives an
:class:`Identified`, which writes the vehicle file again with what the records fix (:meth:`Identified.to_vehicle_toml`).

Two steps, each a least-squares fit with its 95 % intervals:

1. **The map** (model-free: S and i alone). The control unit commands the current its map gives the reading it
   takes, so the samples (S, i) lie on one curve, i = K(S - c): a boost table in ampere
   (:mod:`parksteer.boost_table`'s law: monotone cubic Hermite, odd, exactly zero in its dead band |T| <= D), with
   c the map's zero in the logged torque (0 when the log and the control unit read one sensor). Its points are the
   origin, the dead band D and :data:`SPAN_POINTS` points evenly spaced from D to the largest |S|; the
   fitted values are D, c and the rises between points (positive, so the table is a boost curve). What the map
   cannot hold is reported: the residual's RMS against what the two channels' noise floors allow (scatter), and
   the mean residual on loading (|S| rising) less that on unloading at equal torque (hysteresis: a current that
   depends on the way the torque goes, which a map of S cannot give).

2. **The gear** (the mechanics: the car's manual model replayed on the record's rack). The torques on the massless
   column balance at every sample (:mod:`parksteer.model.numeric.assisted`):

       (S - o) + p D(t) = y(t; theta),   D(t) = e(t) (P_file / eta_f) K(S - c),

   S - o the torque the bar carries (o the sensor's zero offset, read by the control unit and the log alike), D(t)
   what the file's gear would deliver for the identified current (P_file = k_t eta_f N, e(t) the gear's efficiency
   in the direction the power flows), p the factor on the product k_t eta_f N that the data fix, and y the column
   torque the car without boost needs on this rack (the assisted model replayed with its boost off: the rotor's
   inertia in it), which depends on the calibrated parameters theta (:data:`MECHANICS`: the motor's Coulomb
   friction and rotor inertia, the rack friction), all linearly, so the fit is one linear least-squares step on
   finite-difference sensitivities, o and p with them. Where enough samples are back-driven
   (:data:`BACK_DRIVEN_SHARE`), D is split into the samples the motor drives and those it is driven back, with
   factors p and p eta_b,file / eta_b: the back-driven efficiency is fitted too. The tyre-ground friction is not
   fitted: it scales the road torque as p scales the assist, and S, their small difference, cannot tell them
   apart; the product's change per step of it is reported.

Intervals are the least squares' with the residuals' correlation in time left in (a sandwich over blocks of
:data:`BLOCK_S`, with Student's t for its blocks): a record of a few cycles fixes less than its sample count says.
The map's points carry two errors the samples do not average: the table's own (the change from a table of two
points fewer, halved) and the current's rounding (one current per reading of the sensor); the dead band and the
map's centre the torque's rounding (the map between two readings is never seen); the product the map's error,
relative, since it is read through the map. The identified table is the map
times the identified product, P K(S - c), at the point of action; the written file carries it in ``[assist.boost]``
and the product as the torque constant k_t = P / (eta_f N) (only the product is fixed: eta_f and N stay the file's),
and the motor friction; each entry's ``source`` names the records. The sensor offset and the map's centre have no
place in a vehicle file (the model's law is odd about the reading's zero): they are reported, and a later
diagnosis that names an offset of the same size names the baseline's.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import portable as pm
from ..boost_table import entries
from ..errors import UsageError
from ..model.symbolic.effects.assist_common import directional_efficiency, table_law
from ..parameters import Parameters
from .problem import FileData

SPAN_POINTS = 7  # table points beyond the dead band (9 with the origin and the dead band; the law allows 10)
BLOCK_S = 1.0  # s: the blocks of the intervals' sandwich (residuals closer than this are taken as correlated)
Z95 = 1.959963984540054
# The mechanics' calibrated parameters (key, finite-difference step) beside the offset and the product: the column
# torque is linear in the two frictions and the rotor's inertia, so one linear least-squares step is exact.
MECHANICS = (
    ("motor_friction_torque", 0.01),  # of the assist's section
    ("motor_inertia", 1.0e-4),  # of the assist's section: its torque N^2 J theta'' is linear in J
    ("steering.rack_friction_force", 50.0),
)
# The back-driven efficiency is fitted when at least this share of the samples read while the gear moves is
# back-driven (the rack returning the motor after a reversal); else the file's stays.
BACK_DRIVEN_SHARE = 0.03
# Not calibrated: the tyre-ground friction scales the road torque as the product scales the assist (the column
# balance cannot tell them apart: S is the small difference of the two), so the product is identified at the file's
# value, and its dependence on it reported (the product's change for this change of the friction).
TYRE_FRICTION = ("tyre.friction_coefficient", 0.05)
# The column balance is read where the gear moves: the friction's smooth sign tanh(beta v) at least this.
MOVING_SIGN = 0.95
# A residual shape counts as beyond the noise at this many of its standard errors.
BEYOND_SE = 4.0


@dataclass(frozen=True)
class Estimate:
    """One identified number: value, 95 % interval, unit."""

    value: float
    ci95: tuple[float, float]
    unit: str

    def as_dict(self) -> dict:
        return {"value": self.value, "ci95": list(self.ci95), "unit": self.unit}

    def text(self, digits: int = 4) -> str:
        unit = "" if self.unit == "1" else f" {self.unit}"
        return (f"{self.value:.{digits}g}{unit} (95 % {self.ci95[0]:.{digits}g} to "
                f"{self.ci95[1]:.{digits}g})")


def _estimate(value: float, se: float, unit: str, z: float = Z95) -> Estimate:
    return Estimate(float(value), (float(value - z * se), float(value + z * se)), unit)


def _t95(dof: int) -> float:
    """The two-sided 95 % quantile of Student's t: a sandwich over few blocks estimates its variance from few."""
    from scipy.stats import t

    return float(t.ppf(0.975, max(dof, 1)))


@dataclass(frozen=True)
class Identified:
    """What :func:`identify_boost` found (module docstring). ``torques`` (N m) and ``assist`` (at the point of
    action, N m at the column or pinion, N at the rack) are the table with ``assist_ci95`` per point; ``current_A``
    the same map in motor current. ``beyond_map`` lists what the map cannot hold (empty: scatter and hysteresis
    within the noise)."""

    vehicle: str
    records: tuple[str, ...]
    assist_name: str
    torques: tuple[float, ...]
    assist: tuple[float, ...]
    assist_ci95: tuple[tuple[float, float], ...]
    current_A: tuple[float, ...]
    current_ci95: tuple[tuple[float, float], ...]
    dead_band: Estimate
    map_centre: Estimate
    product: Estimate  # k_t eta_f N, N m (or N) at the point of action per A
    motor_friction: Estimate
    motor_inertia: Estimate
    back_efficiency: Estimate | None  # None: too few back-driven samples, the file's kept
    offset: Estimate
    rack_friction: Estimate
    tyre_friction: float  # the file's, at which the product is identified
    product_per_tyre_friction: float  # the product's change per unit of the tyre-ground friction
    map_rms_A: float
    map_noise_A: float
    hysteresis_A: Estimate
    hysteresis_Nm: float
    balance_rms_Nm: float
    torque_noise_Nm: float
    beyond_map: tuple[str, ...]
    file_values: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        est = {k: getattr(self, k).as_dict() for k in ("dead_band", "map_centre", "product", "motor_friction",
                                                         "motor_inertia", "offset", "rack_friction", "hysteresis_A")}
        est["back_efficiency"] = None if self.back_efficiency is None else self.back_efficiency.as_dict()
        return {"vehicle": self.vehicle, "records": list(self.records), "assist": self.assist_name,
                "table": {"torsion_bar_torque_Nm": list(self.torques), "assist": list(self.assist),
                          "assist_ci95": [list(c) for c in self.assist_ci95], "current_A": list(self.current_A),
                          "current_ci95": [list(c) for c in self.current_ci95]},
                **est, "tyre_friction": self.tyre_friction,
                "product_per_tyre_friction": self.product_per_tyre_friction, "map_rms_A": self.map_rms_A,
                "map_noise_A": self.map_noise_A,
                "hysteresis_Nm": self.hysteresis_Nm if math.isfinite(self.hysteresis_Nm) else None,
                "balance_rms_Nm": self.balance_rms_Nm,
                "torque_noise_Nm": self.torque_noise_Nm, "beyond_map": list(self.beyond_map),
                "file_values": dict(self.file_values)}

    def summary_lines(self) -> list[str]:
        unit = "N" if self.assist_name.endswith("_rack") else "N m"
        lines = [f"boost table from {', '.join(self.records)} ({self.assist_name}):",
                 "  torsion-bar N m   assist " + unit + "   95 %              current A"]
        for t, a, (lo, hi), i in zip(self.torques, self.assist, self.assist_ci95, self.current_A):
            lines.append(f"  {t:15.3f}  {a:10.3f}   {lo:7.3f} to {hi:7.3f}   {i:9.2f}")
        lines += [f"dead band {self.dead_band.text()}",
                  f"map centre in the logged torque {self.map_centre.text()}",
                  f"product k_t eta N {self.product.text()} "
                  f"(file: {self.file_values.get('product', float('nan')):.4g})",
                  f"  at the file's tyre-ground friction {self.tyre_friction:g}: the product moves by "
                  f"{self.product_per_tyre_friction * 0.05:+.4g} per +0.05 of it (the balance cannot tell them apart)",
                  f"motor friction {self.motor_friction.text()} (file: "
                  f"{self.file_values.get('motor_friction_torque', float('nan')):.4g})",
                  f"motor inertia {self.motor_inertia.text()} (file: "
                  f"{self.file_values.get('motor_inertia', float('nan')):.4g})",
                  ("back-driven efficiency " + (self.back_efficiency.text() if self.back_efficiency is not None
                                                else "not fixed (too few back-driven samples)")
                   + f" (file: {self.file_values.get('back_efficiency', float('nan')):.4g})"),
                  f"torsion-bar offset {self.offset.text()}",
                  f"rack friction {self.rack_friction.text()}",
                  f"map residual RMS {self.map_rms_A:.3f} A against {self.map_noise_A:.3f} A of noise; hysteresis "
                  f"{self.hysteresis_A.text()} ({self.hysteresis_Nm:.4f} N m of torque)",
                  f"column balance RMS {self.balance_rms_Nm:.4f} N m against a torque noise floor of "
                  f"{self.torque_noise_Nm:.4f} N m"]
        lines += [f"the map cannot hold: {b}" for b in self.beyond_map] or ["the map holds the records within "
                                                                            "their noise"]
        return lines

    def to_vehicle_toml(self, text: str) -> str:
        """The vehicle file `text` with its ``[assist]`` written again: the identified table, the product as the
        torque constant, the motor friction; every other entry kept, the boost line's quantities dropped."""
        return replace_assist_section(text, self)


def _map_law(torques: list[float], values: list[float]):
    """The boost table's law (:func:`parksteer.model.symbolic.effects.assist_common.table_law`) of one row."""
    scalars = entries([float(t) for t in torques], None, [[float(a) for a in values]])

    def law(x):
        return table_law(np.asarray(x, dtype=float), scalars.__getitem__, 0.0)

    return law


def _knots(dead_band: float, top: float, span: int = SPAN_POINTS) -> list[float]:
    return [0.0, dead_band] + [dead_band + (top - dead_band) * j / span for j in range(1, span + 1)]


def _blocks(time_s: np.ndarray, block_s: float) -> np.ndarray:
    return np.floor((time_s - time_s[0]) / block_s).astype(int)


def _sandwich(jacobian: np.ndarray, residual: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    """Covariance of a least-squares fit with residuals correlated within blocks (the cluster sandwich), scaled
    so that it is never smaller than the plain one of independent residuals."""
    n, k = jacobian.shape
    bread = pm.generalized_inverse(pm.matmul(jacobian.T, jacobian))
    meat = np.zeros((k, k))
    for b in np.unique(blocks):
        g = pm.matmul(jacobian[blocks == b].T, residual[blocks == b])
        meat += np.outer(g, g)
    count = len(np.unique(blocks))
    correction = count / max(count - k, 1)
    plain = bread * pm.dot(residual, residual) / max(n - k, 1)
    cluster = pm.matmul(pm.matmul(bread, meat), bread) * correction
    return np.where(np.diag(cluster)[:, None] * np.diag(cluster)[None, :] >=
                    np.diag(plain)[:, None] * np.diag(plain)[None, :], cluster, plain)


@dataclass
class _Map:
    torques: list[float]
    current: list[float]
    centre: float
    covariance: np.ndarray
    jacobian_values: np.ndarray  # d(current at the points) / d(parameters)
    representation: np.ndarray  # A: the table's own error at each point (a standard error)
    torque_step: float  # N m: the logged torque's rounding
    dead_band_representation: float  # N m: the table's own error of its dead band (the change from a coarser one)
    rms: float
    noise: float
    hysteresis: float
    hysteresis_se: float
    hysteresis_Nm: float

    def law(self):
        return _map_law(self.torques, self.current)


def _currents(x) -> list[float]:
    return [0.0, 0.0, *(float(c) for c in np.cumsum(pm.exp(np.asarray(x[2:], dtype=float))))]


def _fit_table(S: np.ndarray, i: np.ndarray, top: float, d0: float, span: int):
    """The least-squares table of `span` points beyond the dead band: parameters (D, c, log rises), residuals and
    their Jacobian."""
    magnitude = np.abs(S)
    active = magnitude > d0
    start = []
    previous = 0.0
    for k in _knots(d0, top, span)[2:]:
        near = active & (np.abs(magnitude - k) <= (top - d0) / span)
        level = float(np.median(np.abs(i[near]))) if near.any() else previous + 1.0
        start.append(math.log(max(level - previous, 0.05)))
        previous = max(level, previous + 0.05)
    x0 = np.array([d0, 0.0, *start])

    def residual(x):
        return _map_law(_knots(x[0], top, span), _currents(x))(S - x[1]) - i

    lower = np.r_[0.01, -0.5, np.full(span, -12.0)]
    upper = np.r_[0.9 * top, 0.5, np.full(span, 8.0)]
    return bounded_least_squares(residual, np.clip(x0, lower + 1e-9, upper - 1e-9), lower, upper)


def bounded_least_squares(residual, x0: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                          max_iterations: int = 200, tolerance: float = 1e-12):
    """(x, residual(x), its Jacobian) minimising the sum of squares of `residual` within the box [lower, upper]:
    Levenberg-Marquardt with a forward-difference Jacobian, on the fixed-order arithmetic of parksteer.portable,
    so that the same records give the same table on any machine (a BLAS-backed solver rounds by its kernel)."""
    def jacobian(x, r):
        out = np.empty((r.size, x.size))
        for j in range(x.size):
            h = 1e-7 * max(1.0, abs(float(x[j])))
            moved = x.copy()
            moved[j] = x[j] + h if x[j] + h <= upper[j] else x[j] - h
            out[:, j] = (residual(moved) - r) / (moved[j] - x[j])
        return out

    x = np.clip(np.asarray(x0, dtype=float), lower, upper)
    r = residual(x)
    rss = pm.dot(r, r)
    J = jacobian(x, r)
    damping = 1e-3
    for _ in range(max_iterations):
        JTJ = pm.matmul(J.T, J)
        scale = np.diag(JTJ).copy()
        scale[scale <= 0] = 1.0
        try:
            step = -pm.solve(JTJ + damping * np.diag(scale), pm.matmul(J.T, r))
        except pm.LinAlgError:
            damping *= 4.0
            continue
        trial = np.clip(x + step, lower, upper)
        if not np.any(trial != x):
            break
        trial_r = residual(trial)
        trial_rss = pm.dot(trial_r, trial_r)
        if trial_rss < rss:
            done = rss - trial_rss <= tolerance * rss
            x, r, rss = trial, trial_r, trial_rss
            J = jacobian(x, r)
            damping = max(damping / 3.0, 1e-12)
            if done:
                break
        else:
            damping *= 4.0
            if damping > 1e12:
                break
    return x, r, J


def fit_map(files: list[FileData]) -> _Map:
    """Step 1 of the module docstring: the current's map of the logged torsion-bar torque."""
    from ..model.numeric.assisted import rack_speed_mps

    S = np.concatenate([f.torque_Nm for f in files])
    i = np.concatenate([f.motor for f in files])
    times = np.concatenate([f.time_s + 1e6 * k for k, f in enumerate(files)])
    magnitude = np.abs(S)
    top = float(np.max(magnitude))  # the last point at the largest torque: no sample on the straight continuation
    step_i = max(max(f.measurement.quantisation_step(f.motor_column) for f in files), 1e-6)
    quiet = magnitude[np.abs(i) <= 2.0 * step_i + 0.02 * np.max(np.abs(i))]
    d0 = float(np.clip(np.quantile(quiet, 0.9) if quiet.size else 0.1 * top, 0.02, 0.6 * top))
    x, r, jacobian = _fit_table(S, i, top, d0, SPAN_POINTS)
    covariance = _sandwich(jacobian, r, _blocks(times, BLOCK_S))
    # the points' currents against the parameters (exp of the rises, summed)
    rises = pm.exp(np.asarray(x[2:], dtype=float))
    jac_values = np.zeros((SPAN_POINTS + 2, len(x)))
    for k in range(2, SPAN_POINTS + 2):
        jac_values[k, 2:k + 1] = rises[: k - 1]
    # what a table of these points cannot follow: the change at the points from a table of two points fewer (the
    # cubic's error falls as the spacing's fourth power, so the finer table's is less than half of it), taken
    # as a standard error of its own beside the noise's
    coarse, _, _ = _fit_table(S, i, top, d0, SPAN_POINTS - 2)
    coarse_law = _map_law(_knots(coarse[0], top, SPAN_POINTS - 2), _currents(coarse))
    points = np.array(_knots(x[0], top))
    representation = np.abs(coarse_law(points) - np.array(_currents(x))) / 2.0
    # ... and the current's rounding: the control unit gives one current at one reading of the sensor, so repeated
    # samples at a torque level carry the same rounding error and do not average it away
    representation = pm.hypot(representation, np.full_like(representation, step_i / math.sqrt(12.0)))
    representation[:2] = 0.0
    dead_band_representation = abs(float(coarse[0] - x[0])) / 2.0
    torques, current = _knots(x[0], top), _currents(x)
    # what the two channels' rounding allows: the current's step, and the torque's through the map's slope (the
    # control unit reads the sensor the log reads, so the sensor's own noise moves both together and is no scatter)
    law = _map_law(torques, current)
    slope = (law(S - x[1] + 1e-4) - law(S - x[1] - 1e-4)) / 2e-4
    step_s = max(f.measurement.quantisation_step("handwheel_torque_Nm") for f in files)
    noise_i, noise_s = step_i / math.sqrt(12.0), step_s / math.sqrt(12.0)
    on = magnitude > x[0] + 0.05 * (top - x[0])
    expected = float(np.sqrt(noise_i ** 2 + np.mean((slope[on] * noise_s) ** 2))) if on.any() else float(noise_i)
    rms = float(np.sqrt(np.mean(r[on] ** 2))) if on.any() else float(np.sqrt(np.mean(r ** 2)))
    # hysteresis: the residual (signed with the torque) while the steering turns outward (the torque's way, the
    # motor driving) against while it comes back, at equal torque
    rate = np.concatenate([rack_speed_mps(f.rack, f.time_s) for f in files])
    loading = np.sign(S) * rate
    moving = np.abs(rate) > 0.1 * np.quantile(np.abs(rate), 0.9)
    signed = -np.sign(S) * r  # measured less the map, in the torque's direction
    use = on & moving
    up, down = use & (loading > 0), use & (loading < 0)
    if up.sum() > 10 and down.sum() > 10:
        design = np.column_stack([up[use].astype(float), down[use].astype(float)])
        coef = pm.lstsq(design, signed[use])
        resid = signed[use] - pm.matmul(design, coef)
        cov = _sandwich(design, resid, _blocks(times[use], BLOCK_S))
        contrast = np.array([1.0, -1.0])
        hysteresis, hysteresis_se = float(coef[0] - coef[1]), math.sqrt(pm.dot(contrast, pm.matmul(cov, contrast)))
        hysteresis_Nm = hysteresis / float(np.median(slope[use])) if np.median(slope[use]) > 0 else math.nan
    else:
        hysteresis, hysteresis_se, hysteresis_Nm = 0.0, math.inf, math.nan
    return _Map(torques, current, float(x[1]), covariance, jac_values, representation, step_s,
                dead_band_representation, rms, expected, hysteresis,
                hysteresis_se, hysteresis_Nm)


def _files(records, params, case, surface, channel_map, name) -> list[FileData]:
    """The records ready to replay, in their order: paths read as ``parksteer diagnose`` reads them, and records
    already in memory (:class:`parksteer.measure.io.Measurement`, e.g. a benchmark's) prepared the same way (an
    angle-only one's rack derived through the column and the torsion bar)."""
    from ..measure.column import rack_from_angle, rack_logger
    from ..measure.converter import quantisation_step
    from ..measure.io import Measurement
    from .problem import load_files, prepare_file

    out = []
    for k, record in enumerate(records):
        if isinstance(record, Measurement):
            resolution = 0.0
            if "rack_derived" in record.metadata:
                record = rack_from_angle(record, params, name)
                logger = rack_logger(record, params)
                resolution = 0.0 if logger is None else quantisation_step(logger[0], logger[1])
            label = record.path.name if record.path is not None else f"record {k + 1}"
            out.append(prepare_file(record, case or record.case, label=label, rest_resolution_m=resolution))
        else:
            out += load_files([str(record)], params, case, surface, channel_map, name)
    return out


def _assist_name(effects) -> str:
    from ..model.symbolic.components import power_assist_of

    effect = power_assist_of(effects)
    if effect is None or not effect.name.startswith("electric_assist_"):
        raise UsageError("assist identify: the vehicle file's [assist] must be an electric one (type column, pinion "
                         "or rack): a hydraulic gear has no motor current to read its map from")
    return effect.name


def identify_boost(records, vehicle, case: str | None = None, surface: str | None = None, channel_map=None,
                   quiet: bool = True) -> Identified:
    """The boost table and the gear's hidden numbers of an electric assist from its records (module docstring).

    `records`: paths of measurement files (any format :func:`parksteer.measure.importers.load_record` reads, with
    `channel_map` for a logger's or a bus's) or records in memory (:class:`parksteer.measure.io.Measurement`), each
    with the torsion-bar torque (``torque_sensor: torsion_bar``),
    the motor current ``motor_current_A`` and a rack or a handwheel angle. `vehicle`: the vehicle file's path, or
    its loaded :class:`~parksteer.parameters.Parameters` (its ``[assist]`` gives the gear; its boost curve, table or
    line, is not used). `case`, `surface`: as for
    ``parksteer diagnose``. Returns an :class:`Identified`; :meth:`Identified.to_vehicle_toml` writes the file."""
    from ..model.numeric.assist import check_assist, effects_with_assist
    from ..model.numeric.assisted import boost_keys, rack_speed_mps
    from ..model.symbolic.components import discover_effects, resolve_effects
    from ..vehicle import load_vehicle
    from .engine import ReplayEngine
    from .problem import Problem

    discover_effects()  # a vehicle file's [assist] entries are the assist effect's quantities
    if isinstance(vehicle, Parameters):
        params, vehicle_path = vehicle, Path(vehicle.path)
    else:
        vehicle_path = Path(vehicle)
        params = load_vehicle(vehicle_path)
    if check_assist(params) is None:
        raise UsageError(f"{vehicle_path}: no [assist] section: identify needs the gear's data (type, reduction, "
                         "efficiency, torque constant)")
    effects = resolve_effects(effects_with_assist(None, params))
    name = _assist_name(effects)
    files = _files(records, params, case, surface, channel_map, name)
    for f in files:
        if f.motor_column != "motor_current_A":
            raise UsageError(f"{f.measurement.path or f.label}: column 'motor_current_A': missing; identify reads the "
                             "map from the motor current beside the torsion-bar torque")
        if f.measurement.torque_sensor != "torsion_bar":
            raise UsageError(f"{f.measurement.path or f.label}: column 'handwheel_torque_Nm': a handwheel torque; "
                             "identify needs the torsion-bar torque of an assisted car (torque_sensor: torsion_bar)")
    say = (lambda text: None) if quiet else (lambda text: print(text, flush=True))
    say("identify: the map of current against torsion-bar torque")
    fitted = fit_map(files)
    law = fitted.law()

    v = lambda key: float(params[f"{name}.{key}"])  # noqa: E731
    location = name.rsplit("_", 1)[1]
    ratio = float(params["steering.handwheel_to_rack_ratio"])
    eta, eta_b, reduction, k_t = v("efficiency"), v("back_efficiency"), v("reduction_ratio"), v("torque_constant")
    product_file = k_t * eta * reduction  # per A, at the point of action
    scale = ratio if location == "rack" else 1.0  # a rack force in torsion-bar torque units: / G_hr

    # Step 2: the column balance on the manual car's replay (boost off).
    problem = Problem(files, params)
    engine = ReplayEngine(1)
    boost_off = {key: 0.0 for key in boost_keys(name)}
    keys = [f"{name}.{k}" if "." not in k else k for k, _ in MECHANICS]
    theta = np.array([float(params[k]) for k in keys])
    delivered, measured, times, moving, backward = [], [], [], [], []
    sharpness = float(params["steering.friction_smoothing"])
    for k, f in enumerate(files):
        S = f.torque_Nm
        motor = law(S - fitted.centre) * k_t
        speed = rack_speed_mps(f.rack, f.time_s)
        e = directional_efficiency(motor, speed, eta, eta_b, v("limit_smoothing"), sharpness)
        delivered.append(e * reduction * motor / scale)
        moving.append(np.abs(pm.tanh(sharpness * speed)) >= MOVING_SIGN)
        backward.append(motor * speed < 0.0)
        measured.append(S)
        times.append(f.time_s + 1e6 * k)
    D = np.concatenate(delivered)
    S_all = np.concatenate(measured)
    t_all = np.concatenate(times)
    sigma = np.concatenate([np.full(f.n, f.noise.total_rms) for f in files])
    use = np.concatenate(moving)
    back = np.concatenate(backward)
    split = (use & back).sum() >= BACK_DRIVEN_SHARE * use.sum()
    if use.sum() < 20 * (len(MECHANICS) + 2):
        raise UsageError(f"{', '.join(str(r) for r in records)}: the steering hardly moves: identify needs records "
                         "in which the wheel turns (the column balance is read while the gear moves)")

    def road(changes: dict[str, float]):
        overrides = {**boost_off, **dict(zip(keys, theta)), **changes}
        return np.concatenate([engine.replay(problem, effects, k).solve(overrides).torque_Nm[: f.n]
                               for k, f in enumerate(files)])

    say("identify: the column balance on the car's replay")
    try:
        y0 = road({})
        columns = [(road({key: value + step}) - y0) / step for key, value, (_, step) in zip(keys, theta, MECHANICS)]
        tyre_key, tyre_step = TYRE_FRICTION
        tyre_column = (road({tyre_key: float(params[tyre_key]) + tyre_step}) - y0) / tyre_step
    finally:
        engine.close()
    # y0 + J dtheta + o - S - p D = 0  ->  [J, 1, -D] [dtheta, o, p] = S - y0, with D split into the samples the
    # motor drives and those it is driven back (their factor p_b = p eta_b,file / eta_b)
    # only while the gear moves: at rest its friction and the direction of its power are not defined
    parts = [-D * ~back, -D * back] if split else [-D]
    design = (np.column_stack([*columns, np.ones_like(S_all), *parts]) / sigma[:, None])[use]
    rhs = ((S_all - y0) / sigma)[use]
    solution = pm.lstsq(design, rhs)
    resid = rhs - pm.matmul(design, solution)
    cov = _sandwich(design, resid, _blocks(t_all[use], BLOCK_S))
    # the product at the tyre friction moved by its step: the same fit on y0 + step x its column
    moved = pm.lstsq(design, ((S_all - y0 - tyre_step * tyre_column) / sigma)[use])
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    values = theta + solution[: len(keys)]
    offset, p = float(solution[len(keys)]), float(solution[len(keys) + 1])
    se_o, se_p = float(se[len(keys)]), float(se[len(keys) + 1])
    product_per_tyre = (float(moved[len(keys) + 1]) - p) * product_file / tyre_step
    back_efficiency = None
    if split:  # eta_b = eta_b,file p / p_b, its standard error by the delta method
        j = len(keys) + 2
        p_b = float(solution[j])
        ratio = p / p_b
        gradient = np.array([1.0 / p_b, -p / p_b ** 2])
        block = cov[np.ix_([len(keys) + 1, j], [len(keys) + 1, j])]
        back_se = eta_b * math.sqrt(max(pm.dot(gradient, pm.matmul(block, gradient)), 0.0))
    z = _t95(len(np.unique(_blocks(t_all[use], BLOCK_S))) - design.shape[1])
    if split:
        back_efficiency = _estimate(eta_b * ratio, back_se, "1", z)
    balance_rms = float(np.sqrt(np.mean((resid * sigma[use]) ** 2)))
    torque_noise = float(np.sqrt(np.mean(sigma ** 2)))

    # the table at the point of action: P K, its interval from the map's and the product's
    P = p * product_file
    point_cov = pm.matmul(pm.matmul(fitted.jacobian_values, fitted.covariance), fitted.jacobian_values.T) \
        + np.diag(fitted.representation ** 2)
    current = np.array(fitted.current)
    assist = P * current
    # the product is read through the map: the map's own error at its points (not averaged by more samples) is a
    # relative error of the product, weighted as the balance weighs the assist (by its size)
    map_relative = float(np.sqrt(np.sum(fitted.representation ** 2) / np.sum(current ** 2)))
    se_p = math.hypot(se_p, p * map_relative)
    rel_p = se_p / p if p > 0 else math.inf
    se_assist = np.sqrt((P ** 2) * np.maximum(np.diag(point_cov), 0.0) + (assist * rel_p) ** 2)
    step_i = max(f.measurement.quantisation_step(f.motor_column) for f in files)
    beyond = []
    if abs(fitted.hysteresis) > BEYOND_SE * fitted.hysteresis_se and abs(fitted.hysteresis) > 0.5 * step_i:
        beyond.append(f"hysteresis: the current on loading is {fitted.hysteresis:+.3f} A from that on unloading at "
                      f"equal torsion-bar torque (+-{Z95 * fitted.hysteresis_se:.3f} A; {fitted.hysteresis_Nm:.4f} N m "
                      "of torque), a current that depends on the way the steering turns (outward or back)")
    if fitted.rms > 1.5 * fitted.noise and fitted.rms - fitted.noise > 0.5 * step_i:
        beyond.append(f"scatter: the current departs from the map by {fitted.rms:.3f} A RMS against {fitted.noise:.3f} "
                      "A of the channels' noise")
    names = [f.label for f in files]
    mech = {k: _estimate(val, s, u, z) for (k, _), val, s, u in zip(MECHANICS, values, se[: len(keys)],
                                                                   ("N m", "kg m^2", "N"))}
    return Identified(
        vehicle=str(vehicle_path), records=tuple(names), assist_name=name,
        torques=tuple(float(t) for t in fitted.torques), assist=tuple(float(a) for a in assist),
        assist_ci95=tuple((float(a - Z95 * s), float(a + Z95 * s)) for a, s in zip(assist, se_assist)),
        current_A=tuple(float(c) for c in current),
        current_ci95=tuple((float(c - Z95 * s), float(c + Z95 * s)) for c, s in
                           zip(current, np.sqrt(np.maximum(np.diag(point_cov), 0.0)))),
        # the log and the control unit read the torque in steps: the map between two of them is never seen
        dead_band=_estimate(fitted.torques[1], math.hypot(math.sqrt(max(fitted.covariance[0, 0], 0.0)),
                                                          fitted.torque_step / math.sqrt(12.0),
                                                          fitted.dead_band_representation), "N m"),
        map_centre=_estimate(fitted.centre, math.hypot(math.sqrt(max(fitted.covariance[1, 1], 0.0)),
                                                       fitted.torque_step / math.sqrt(12.0)), "N m"),
        product=_estimate(P, se_p * product_file, "N/A" if location == "rack" else "N m/A", z),
        motor_friction=mech["motor_friction_torque"], motor_inertia=mech["motor_inertia"],
        back_efficiency=back_efficiency, offset=_estimate(offset, se_o, "N m", z),
        rack_friction=mech["steering.rack_friction_force"], tyre_friction=float(params[TYRE_FRICTION[0]]),
        product_per_tyre_friction=product_per_tyre,
        map_rms_A=fitted.rms, map_noise_A=fitted.noise,
        hysteresis_A=_estimate(fitted.hysteresis, fitted.hysteresis_se, "A"), hysteresis_Nm=float(fitted.hysteresis_Nm),
        balance_rms_Nm=balance_rms, torque_noise_Nm=torque_noise, beyond_map=tuple(beyond),
        file_values={"product": product_file, "motor_friction_torque": v("motor_friction_torque"),
                     "motor_inertia": v("motor_inertia"), "back_efficiency": eta_b,
                     "efficiency": eta, "reduction_ratio": reduction, "torque_constant": k_t},
    )


# ---- writing the vehicle file again -------------------------------------------------------------------------------

_HEADER = re.compile(r"^\s*\[([^\]]+)\]\s*(#.*)?$")


def _toml_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _number(x: float) -> str:
    return repr(float(f"{x:.6g}"))


def replace_assist_section(text: str, found: Identified) -> str:
    """`text` (a vehicle file) with its ``[assist]`` and ``[assist.*]`` tables written again from `found`."""
    import tomllib

    from ..model.numeric.assist import LINE_KEYS  # the boost line's quantities, which a table replaces

    doc = tomllib.loads(text)
    old = doc.get("assist", {})
    kept, inside = [], False
    for line in text.splitlines():
        header = _HEADER.match(line)
        if header:
            inside = header.group(1).strip() == "assist" or header.group(1).strip().startswith("assist.")
        if not inside:
            kept.append(line)
    while kept and not kept[-1].strip():
        kept.pop()
    records = ", ".join(found.records)
    where = f"identified by parksteer assist identify from {records}"
    unit = "N" if found.assist_name.endswith("_rack") else "N m"
    lines = ["", "# Power assistance: the gear's data as the file gave them; the boost table, the product k_t eta N",
             "# (as the torque constant), the motor's friction and inertia" + (" and the back-driven efficiency"
                                                                              if found.back_efficiency is not None
                                                                              else "") + f" {where}.",
             "# Also identified, with no entry in a vehicle file: the torsion-bar sensor's offset "
             f"{found.offset.text()};",
             f"# the map's centre in the logged torque {found.map_centre.text()}; the rack friction",
             f"# {found.rack_friction.text()} (a diagnosis calibrates it again).",
             *(f"# The map cannot hold: {b}" for b in found.beyond_map),
             "[assist]", f"type = {_toml_string(old.get('type', 'column'))}"]
    k_t = found.product.value / (found.file_values["efficiency"] * found.file_values["reduction_ratio"])
    replaced = {
        "torque_constant": (k_t, "N m/A", f"{where}: the product k_t eta N = {found.product.text()} through the "
                                          f"file's efficiency and reduction (only the product is fixed); the file "
                                          f"gave {found.file_values['torque_constant']:g}"),
        "motor_friction_torque": (max(found.motor_friction.value, 0.0), "N m",
                                  f"{where}: {found.motor_friction.text()} (the column balance; the file gave "
                                  f"{found.file_values['motor_friction_torque']:g})"),
        "motor_inertia": (max(found.motor_inertia.value, 0.0), "kg m^2",
                          f"{where}: {found.motor_inertia.text()} (the column balance; the file gave "
                          f"{found.file_values['motor_inertia']:g})"),
    }
    if found.back_efficiency is not None:
        replaced["back_efficiency"] = (min(max(found.back_efficiency.value, 0.5), 0.99), "1",
                                       f"{where}: {found.back_efficiency.text()} (the column balance on the "
                                       f"back-driven samples; the file gave {found.file_values['back_efficiency']:g})")
    for key, entry in old.items():
        if key in ("type", "boost") or key in LINE_KEYS or key in replaced:
            continue
        lines.append(f"{key} = {{ value = {_number(entry['value'])}, unit = {_toml_string(entry['unit'])}, "
                     f"source = {_toml_string(entry['source'])} }}")
    for key, (value, u, source) in replaced.items():
        lines.append(f"{key} = {{ value = {_number(value)}, unit = {_toml_string(u)}, "
                     f"source = {_toml_string(source)} }}")
    torques = ", ".join(_number(t) for t in found.torques)
    assists = ", ".join(_number(max(a, 0.0)) for a in _strictly_rising(found.assist))
    intervals = "; ".join(f"{lo:.3g}-{hi:.3g}" for lo, hi in found.assist_ci95[2:])
    lines += ["", "[assist.boost]",
              f"torsion_bar_torque = {{ value = [{torques}], unit = \"N m\", source = "
              + _toml_string(f"{where}: the dead band {found.dead_band.text()}, then evenly spaced to the largest of "
                             "the records") + " }",
              f"assist = {{ value = [{assists}], unit = \"{unit}\", source = "
              + _toml_string(f"{where}: the current map times the product k_t eta N; 95 % beyond the dead band "
                             f"{intervals}") + " }",
              ""]
    return "\n".join(kept + lines)


def _strictly_rising(values) -> list[float]:
    """The table's assists rounded as written, kept strictly rising beyond the dead band (the reader's check)."""
    out = [0.0, 0.0]
    for a in values[2:]:
        a = float(f"{a:.6g}")
        out.append(a if a > out[-1] else float(f"{out[-1] * (1 + 1e-5) + 1e-6:.6g}"))
    return out
