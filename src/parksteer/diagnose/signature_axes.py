"""The axes a residual's signature is read along (:class:`Axes`, :func:`axes_of`) and the bases fitted on them
(:class:`Basis`, :func:`bases`); the module docstring of :mod:`parksteer.diagnose.signature` gives the families."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..parameters import Parameters
from .settings import DEFAULT_SETTINGS, DiagnosisSettings


@dataclass(frozen=True)
class Axes:
    """Per-sample coordinates of every record, concatenated: what the residual is decomposed along.

    ``residual_Nm``: measured minus calibrated model torque; ``sigma_Nm``: each sample's attainable error;
    ``phase``: the cycle-phase label; ``record``: the index of the record; ``conditions``: each record's
    (load case, surface). ``smoothing_s_m``: beta of the smoothed sign; ``ratio_rad_m``: handwheel-to-rack ratio.
    """

    rack_m: np.ndarray
    speed_m_s: np.ndarray
    column_rad: np.ndarray
    phase: np.ndarray
    record: np.ndarray
    residual_Nm: np.ndarray
    sigma_Nm: np.ndarray
    conditions: tuple[tuple[str, str], ...]
    smoothing_s_m: float
    ratio_rad_m: float

    def __post_init__(self):
        n = len(self.residual_Nm)
        for name in ("rack_m", "speed_m_s", "column_rad", "phase", "record", "sigma_Nm"):
            if len(getattr(self, name)) != n:
                raise UsageError(f"signature: axis {name} has {len(getattr(self, name))} samples, the residual {n}")
        if n < 20:
            raise UsageError(f"signature: {n} samples are too few to decompose a residual")
        if not np.all(np.isfinite(self.residual_Nm)) or not np.all(self.sigma_Nm > 0):
            bad = int(np.flatnonzero(~np.isfinite(self.residual_Nm) | ~(self.sigma_Nm > 0))[0])
            raise UsageError(f"signature: sample {bad}: residual not finite or attainable error not positive")


@dataclass(frozen=True)
class Basis:
    """One model of the decomposition: its class, label, columns (samples x k, N m per unit coefficient)."""

    family: str
    label: str
    columns: np.ndarray
    # knots of the shape (m for the rack position, 1 for the speed over v_90) and their spacing; or the orders
    knots: tuple[float, ...] = ()
    width: float = 0.0
    orders: tuple[int, ...] = ()


def rbf(z: np.ndarray, knots, width: float) -> np.ndarray:
    """Radial basis columns exp(-((z - c_k) / h)^2), one per knot (samples x knots)."""
    z = np.asarray(z, dtype=float)
    return np.column_stack([pm.exp(-(((z - c) / width) ** 2)) for c in knots])


def position_knots(rack_m: np.ndarray, count: int) -> tuple[tuple[float, ...], float]:
    """`count` knots evenly over the rack travel the records cover, and their spacing (the functions' width)."""
    # whole millimetres outward, so that records over the same travel share their knots (and a suggested
    # effect's source, and its compiled model)
    low, high = math.floor(1000.0 * float(np.min(rack_m))) / 1000.0, math.ceil(1000.0 * float(np.max(rack_m))) / 1000.0
    if not high > low:
        raise UsageError("signature: the rack does not move in these records")
    knots = tuple(float(v) for v in np.linspace(low, high, count))
    return knots, (high - low) / (count - 1)


def column_angle(rack_m: np.ndarray, ratio_rad_m: float, joint_rad: float, phase_rad: float) -> np.ndarray:
    """Column angle of a rack position through the pinion and the Hooke joint: the pinion turns G x, and
    tan(theta_c - phase) = tan(theta_p - phase) cos(joint) (the inverse of the joint's
    tan(theta_p - phase) = tan(theta_c - phase) / cos(joint)), continuous in theta_p."""
    pinion = ratio_rad_m * np.asarray(rack_m, dtype=float)
    u = pinion - phase_rad
    lead = pm.atan2(pm.sin(u) * pm.cos(joint_rad), pm.cos(u)) - u
    lead = (lead + np.pi) % (2.0 * np.pi) - np.pi
    return pinion + lead


def smooth_sign(axes: Axes) -> np.ndarray:
    return pm.tanh(axes.smoothing_s_m * axes.speed_m_s)


def bases(axes: Axes, settings: DiagnosisSettings = DEFAULT_SETTINGS) -> list[Basis]:
    """Every model of the decomposition (module docstring), simplest first within each family."""
    s = smooth_sign(axes)
    out = [Basis("dissipative", "uniform", s[:, None]), Basis("direction", "uniform", (s * s)[:, None])]
    for count in settings.signature.position_knots:
        knots, width = position_knots(axes.rack_m, count)
        phi = rbf(axes.rack_m, knots, width)
        out.append(Basis("dissipative", f"{count} knots", s[:, None] * phi, knots, width))
        out.append(Basis("elastic", f"{count} knots", phi, knots, width))
        out.append(Basis("direction", f"{count} knots", (s * s)[:, None] * phi, knots, width))
    speed = np.abs(axes.speed_m_s)
    scale = float(np.quantile(speed, 0.9))
    if scale > 0.0:
        knots = tuple(float(v) for v in np.linspace(0.0, 1.25, settings.signature.speed_knots))
        width = knots[1] - knots[0]
        out.append(Basis("speed", f"{settings.signature.speed_knots} knots", s[:, None] * rbf(speed / scale, knots, width),
                         knots, width))
    for orders in (*settings.signature.column_orders, (settings.signature.mesh_order,)):
        columns = np.column_stack([f(m * axes.column_rad) for m in orders for f in (pm.sin, pm.cos)])
        label = " + ".join(f"{m} per turn" for m in orders)
        out.append(Basis("column", label, columns, orders=tuple(orders)))
    out += combined_bases(axes, s, settings)
    return out


def combined_bases(axes: Axes, s: np.ndarray, settings: DiagnosisSettings = DEFAULT_SETTINGS) -> list[Basis]:
    """The products of two classes: a dissipative force shaped by the column angle, ``s sin(m theta)``,
    ``s cos(m theta)`` for the combined orders of the settings (a column bearing pinched once per turn, a joint's
    friction rising twice per turn). Its uniform part is the dissipative class's (and the calibrated friction's):
    only the periodic part is a column of its own."""
    out = []
    for orders in settings.signature.combined_orders:
        columns = np.column_stack([s * f(m * axes.column_rad) for m in orders for f in (pm.sin, pm.cos)])
        label = " + ".join(f"{m} per turn" for m in orders)
        out.append(Basis("dissipative_column", label, columns, orders=tuple(orders)))
    return out


def steering_values(params: Parameters) -> dict[str, float]:
    """The steering quantities the axes are read with, by key, from the parameters."""
    s = params.sections["steering"]
    return {f"steering.{k}": float(s[k]) for k in ("handwheel_to_rack_ratio", "friction_smoothing",
                                                   "hooke_joint_angle", "hooke_joint_phase", "rack_friction_force")}


def axes_of(files, predictions: list[np.ndarray], params: Parameters, overrides: dict[str, float] | None = None
            ) -> Axes:
    """The axes of every file, concatenated: its smoothed rack's position and speed at the torque's instants,
    the column angle through the pinion and the Hooke joint, the phase labels, the torque residual and each
    sample's attainable error."""
    values = {**steering_values(params), **(overrides or {})}
    ratio = values["steering.handwheel_to_rack_ratio"]
    parts: dict[str, list] = {k: [] for k in ("x", "v", "phase", "record", "r", "sigma")}
    for i, (f, prediction) in enumerate(zip(files, predictions)):
        x, v, _ = f.rack.evaluate(f.replay_time_s)
        parts["x"].append(x)
        parts["v"].append(v)
        parts["phase"].append(np.asarray(f.phases.labels))
        parts["record"].append(np.full(f.n, i))
        parts["r"].append(f.torque_Nm - np.asarray(prediction)[: f.n])
        parts["sigma"].append(f.sigma_Nm)
    x = np.concatenate(parts["x"])
    return Axes(x, np.concatenate(parts["v"]),
                column_angle(x, ratio, values["steering.hooke_joint_angle"], values["steering.hooke_joint_phase"]),
                np.concatenate(parts["phase"]), np.concatenate(parts["record"]), np.concatenate(parts["r"]),
                np.concatenate(parts["sigma"]), tuple((f.case, f.surface) for f in files),
                values["steering.friction_smoothing"], ratio)
