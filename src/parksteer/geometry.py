"""Steer-axis geometry (Appendix A, reconstructed) and the lifting torque, equation (A1).

Axes are fixed in the car body: x forward, y to the right, z down, origin on the
centreline at height datum z = 0. For each side the king-pin axis passes through the
upper point O = (-trail, +-y1, z1) and points downward along
``R_y(castor) R_x(+-kpi) e_z``; the sign of the king-pin rotation makes the axis lean
outboard at its foot on both sides (left: +kpi about x, right: -kpi). The wheel centre
C = (0, +-y2, z2) lies on the axis in side view because the trail equals
(z2 - z1) tan(castor). A steer angle ``delta`` rotates the wheel about that axis; positive
``delta`` turns both wheels to the right (a right-hand rotation about the downward axis).

Everything here is kinematics of a rigid body on a fixed axis: it is used by equation
(A1), by Fig. A3 and as the single source of axis geometry for the multibody model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import portable as pm
from .names import SIDES
from .parameters import Parameters


def _rot_x(a: float) -> np.ndarray:
    c, s = pm.cos(a), pm.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rot_y(a: float) -> np.ndarray:
    c, s = pm.cos(a), pm.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


@dataclass(frozen=True)
class SteerAxis:
    """One side's king-pin axis and wheel centre, in body axes (m)."""

    side: str
    top: np.ndarray  # O, the upper king-pin point
    axis_frame: np.ndarray  # columns: X2, Y2, Z2 (Z2 = unit axis direction, downward)
    wheel_centre: np.ndarray  # C at zero steer
    wheel_radius_m: float

    @property
    def direction(self) -> np.ndarray:
        return self.axis_frame[:, 2]

    @property
    def foot(self) -> np.ndarray:
        """A: the foot of the perpendicular from C onto the axis."""
        oc = self.wheel_centre - self.top
        return self.top + pm.dot(oc, self.direction) * self.direction

    @property
    def offset_d_m(self) -> float:
        """d: perpendicular distance from the wheel centre to the steer axis."""
        return pm.norm(self.wheel_centre - self.foot)

    def ground_intercept(self) -> np.ndarray:
        """Where the axis meets the ground plane (z = ground)."""
        ground_z = self.wheel_centre[2] + self.wheel_radius_m
        t = (ground_z - self.top[2]) / self.direction[2]
        return self.top + t * self.direction

    def scrub_radius_m(self) -> float:
        """Lateral distance at the ground from the axis intercept to the contact centre, outboard positive."""
        outboard = -1.0 if self.side == "left" else 1.0
        return float(outboard * (self.wheel_centre[1] - self.ground_intercept()[1]))

    def rotation(self, steer_rad: float) -> np.ndarray:
        """Rotation matrix (body axes) of the wheel about this axis by `steer_rad`."""
        k = self.direction
        kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        return np.eye(3) + pm.sin(steer_rad) * kx + (1.0 - pm.cos(steer_rad)) * pm.matmul(kx, kx)

    def wheel_centre_at(self, steer_rad: float) -> np.ndarray:
        """C' : the wheel centre after steering by `steer_rad` (Rodrigues rotation about the axis)."""
        a = self.foot
        return a + pm.matmul(self.rotation(steer_rad), self.wheel_centre - a)

    def wheel_drop_m(self, steer_rad: float | np.ndarray) -> np.ndarray | float:
        """Downward displacement of the wheel centre (and contact point) relative to the body, from zero steer."""
        steer = np.atleast_1d(np.asarray(steer_rad, dtype=float))
        z0 = self.wheel_centre[2]
        drop = np.array([self.wheel_centre_at(s)[2] - z0 for s in steer])
        return drop if np.ndim(steer_rad) else float(drop[0])


def steer_axis(params: Parameters, case: str, side: str) -> SteerAxis:
    """The king-pin axis of `side` for a Table B1 `case` (spacers move only the wheel centre)."""
    if side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}, got {side!r}")
    g = params.sections["geometry"]
    c = params.case(case)
    sign = -1.0 if side == "left" else 1.0  # y of the left side is negative
    kpi = g["kingpin_inclination"] * (1.0 if side == "left" else -1.0)
    frame = pm.matmul(_rot_y(g["castor_angle"]), _rot_x(kpi))
    top = np.array([-g["mechanical_trail"], sign * g["kingpin_top_y"], g["kingpin_top_z"]])
    centre = np.array([0.0, sign * c["wheel_centre_y"], g["wheel_centre_z"]])
    return SteerAxis(side, top, frame, centre, g["ground_z"] - g["wheel_centre_z"])


def steering_ratio(params: Parameters) -> float:
    """G: handwheel angle per road-wheel steer angle (186.47 / 8.3682 = 22.28)."""
    s = params.sections["steering"]
    return s["handwheel_to_rack_ratio"] / s["roadwheel_to_rack_ratio"]


def lifting_torque_a1(params: Parameters, case: str, steer_rad: float | np.ndarray) -> np.ndarray | float:
    """Equation (A1): handwheel torque (N m) from lifting the fixed body against the static wheel loads.

    tau = d {(W_r - W_l) sin(castor) cos(delta) + (W_r + W_l) cos(castor) sin(kpi) sin(delta)} / G,
    with d the perpendicular wheel-centre-to-axis distance and delta the road-wheel steer angle.
    """
    g = params.sections["geometry"]
    c = params.case(case)
    d = steer_axis(params, case, "left").offset_d_m
    eps, chi = g["castor_angle"], g["kingpin_inclination"]
    wl, wr = c["load_left"], c["load_right"]
    delta = np.asarray(steer_rad, dtype=float)
    tau = d * ((wr - wl) * pm.sin(eps) * pm.cos(delta) + (wr + wl) * pm.cos(eps) * pm.sin(chi) * pm.sin(delta))
    return tau / steering_ratio(params)


def lock_steer_angle(params: Parameters) -> float:
    """Road-wheel steer angle at full lock (rad)."""
    return params["input.handwheel_lock_angle"] / steering_ratio(params)


def pinion_angle_from_column(column_angle_rad, joint_angle_rad: float, phase_rad: float) -> np.ndarray:
    """theta_p from theta_c through the Hooke joint: tan(theta_p - phase) = tan(theta_c - phase) / cos(alpha).

    The inverse of the joint's map in :mod:`parksteer.model.symbolic.effects.hooke_joint`, written in the same
    branch-free form: with psi = theta_c - phase,
    theta_p - theta_c = atan((1 - cos a) sin psi cos psi / (cos a cos^2 psi + sin^2 psi)), whose denominator is at
    least cos(alpha) > 0, so the angle stays continuous over any number of turns.
    """
    theta_c = np.asarray(column_angle_rad, dtype=float)
    cos_a = pm.cos(joint_angle_rad)
    psi = theta_c - phase_rad
    s, c = pm.sin(psi), pm.cos(psi)
    return theta_c + pm.atan((1.0 - cos_a) * s * c / (cos_a * c**2 + s**2))


def rack_from_handwheel(handwheel_angle_rad, handwheel_torque_Nm, params: Parameters) -> np.ndarray:
    """The column law: rack displacement (m) from the handwheel angle and torque.

    The column twists by T / column_torsional_stiffness (its damping is left out: at parking speeds the twist
    rate is at most about 0.024 rad/s, at a reversal, where with c / k = 0.2 s the damper moves the rack by up to
    26 um), the Hooke joint turns the column angle into the pinion angle, and rack = theta_p /
    handwheel_to_rack_ratio. A diagnosis re-derives the rack with the damper
    (:func:`parksteer.measure.column.rack_from_angle`): at a reversal those 26 um decide the friction's flip.
    """
    s = params.sections["steering"]
    column = np.asarray(handwheel_angle_rad, dtype=float) - (
        np.asarray(handwheel_torque_Nm, dtype=float) / s["column_torsional_stiffness"])
    pinion = pinion_angle_from_column(column, s["hooke_joint_angle"], s["hooke_joint_phase"])
    return pinion / s["handwheel_to_rack_ratio"]


def column_twist(t: np.ndarray, torque: np.ndarray, stiffness: float, damping: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Twist (rad) and twist rate (rad/s) of the column from ``c dtwist/dt + k twist = T``, from rest at T(t[0]) / k.

    Exact for a torque linear between the samples `t`. Without damping the twist is T / k.
    """
    if damping <= 0.0:
        twist = torque / stiffness
        return twist, np.gradient(twist, t)
    tau = damping / stiffness
    h = np.diff(t)
    decay = pm.exp(-h / tau)
    slope = np.diff(torque) / h
    # x(t0 + h) = T1/k - tau s/k + (x0 - T0/k + tau s/k) e^(-h/tau), s the torque's slope over the interval
    twist = np.empty(len(t))
    twist[0] = torque[0] / stiffness
    for k in range(len(h)):
        lag = tau * slope[k] / stiffness
        twist[k + 1] = torque[k + 1] / stiffness - lag + (twist[k] - torque[k] / stiffness + lag) * decay[k]
    return twist, (torque - stiffness * twist) / damping
