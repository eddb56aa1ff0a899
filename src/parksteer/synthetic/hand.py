"""The driver's hand: the handwheel angle a person turns, as the model's piecewise-quadratic input.

:func:`sawtooth_hand_profile` is the paper's Section 4 saw tooth; :func:`irregular_hand_profile` a hand whose
speed wanders smoothly (:class:`HandVariation`), as a real driver's does.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..parameters import Parameters


# --- the driver's hand -------------------------------------------------------------------
#
# A hand profile is a list of pieces (start time s, angle rad, rate rad/s, acceleration rad/s^2):
# a piecewise-quadratic angle, which is what the compiled model takes as its handwheel input
# (parksteer.model.inputs.HandwheelProfile, at most 24 pieces).


def _evaluate_pieces(pieces: tuple[tuple[float, float, float, float], ...], t_s: np.ndarray):
    """Angle and rate of piecewise-quadratic `pieces` at `t_s` (held at the first angle before the start)."""
    t = np.asarray(t_s, dtype=float)
    table = np.array(pieces)
    k = np.clip(np.searchsorted(table[:, 0], t, side="right") - 1, 0, len(table) - 1)
    dt = np.maximum(t - table[k, 0], 0.0)
    angle = table[k, 1] + table[k, 2] * dt + 0.5 * table[k, 3] * dt**2
    rate = np.where(t < table[0, 0], 0.0, table[k, 2] + table[k, 3] * dt)
    return angle, rate


@dataclass(frozen=True)
class HandProfile:
    """Handwheel angle (rad, positive to the right) and its rate (rad/s), sampled against time (s).

    `pieces` holds the same profile exactly, in the model's input form; `anchor_times_s` the
    start, each reversal and the end.
    """

    time_s: np.ndarray
    angle_rad: np.ndarray
    rate_rad_s: np.ndarray
    anchor_times_s: np.ndarray
    pieces: tuple[tuple[float, float, float, float], ...]
    metadata: Mapping[str, Any]

    def angle_rate(self, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Angle and rate at any times (exact, from the pieces)."""
        return _evaluate_pieces(self.pieces, t_s)

    def handwheel_profile(self):
        """The profile as the model's input (parksteer.model.inputs.HandwheelProfile)."""
        from ..model.numeric.inputs import HandwheelProfile

        return HandwheelProfile(tuple(self.pieces))


def _anchor_times(params: Parameters) -> np.ndarray:
    p = params.sections["input"]
    return np.cumsum([0.0, p["time_to_right_lock"], p["time_right_to_left_lock"], p["time_left_lock_to_centre"]])


def _sampled(pieces, anchors: np.ndarray, output_dt_s: float, metadata: dict[str, Any]) -> HandProfile:
    if output_dt_s <= 0.0:
        raise UsageError(f"output_dt_s must be positive, got {output_dt_s:g}")
    n = int(round(anchors[-1] / output_dt_s)) + 1
    time_s = np.linspace(anchors[0], anchors[-1], n)
    angle, rate = _evaluate_pieces(pieces, time_s)
    return HandProfile(time_s, angle, rate, anchors, tuple(tuple(float(v) for v in p) for p in pieces), metadata)


def sawtooth_hand_profile(params: Parameters, output_dt_s: float = 0.01) -> HandProfile:
    """The model's own input (parksteer.model.inputs.sawtooth_profile): the Section 4 saw tooth.

    Straight ahead to right lock in 4.5 s, to left lock 9 s later, back to straight ahead at
    18 s, each corner rounded so that the hand stops exactly at each lock at the corner time.
    """
    from ..model.numeric.inputs import sawtooth_profile

    meta = {"hand_profile": "saw tooth of Section 4 (parksteer.model.inputs.sawtooth_profile)"}
    return _sampled(sawtooth_profile(params).pieces, _anchor_times(params), output_dt_s, meta)


@dataclass(frozen=True)
class HandVariation:
    """Smooth random variation of the hand speed: a speed factor ``1 + sum_k a_k sin(2 pi f_k t + phi_k)``.

    The `components` frequencies are drawn uniformly from `frequency_range_hz`, the phases
    uniformly, and the amplitudes as random positive shares of `speed_variation`, so the factor
    stays within ``1 +- speed_variation`` (below 1, so that the hand never stops or backs up
    between reversals). The factor is applied at `knots_per_stroke` evenly spaced instants of
    each stroke's cruise (the rate is linear between them), which keeps the profile a short list
    of quadratic pieces the compiled model can take.
    """

    speed_variation: float
    components: int
    frequency_range_hz: tuple[float, float]
    knots_per_stroke: int
    seed: int

    def __post_init__(self) -> None:
        if not 0.0 <= self.speed_variation < 1.0:
            raise UsageError(f"hand speed variation must be in [0, 1), got {self.speed_variation:g}")
        low, high = self.frequency_range_hz
        if not 0.0 < low <= high:
            raise UsageError(f"hand frequency range must be positive and ordered, got {self.frequency_range_hz}")
        if self.components < 1:
            raise UsageError(f"hand variation needs at least one component, got {self.components}")
        if self.knots_per_stroke < 0:
            raise UsageError(f"knots per stroke must not be negative, got {self.knots_per_stroke}")

    def speed_factor(self, t_s: np.ndarray) -> np.ndarray:
        """1 + sum_k a_k sin(2 pi f_k t + phi_k), with the seeded draw."""
        rng = np.random.default_rng(self.seed)
        frequencies = rng.uniform(*self.frequency_range_hz, size=self.components)
        phases = rng.uniform(0.0, 2.0 * np.pi, size=self.components)
        shares = rng.uniform(0.5, 1.0, size=self.components)
        amplitudes = self.speed_variation * shares / shares.sum()
        t = np.asarray(t_s, dtype=float)[..., None]
        return 1.0 + np.sum(amplitudes * pm.sin(2.0 * np.pi * frequencies * t + phases), axis=-1)

    def metadata(self) -> dict[str, Any]:
        low, high = self.frequency_range_hz
        return {
            "hand_speed_variation": float(self.speed_variation),
            "hand_components": int(self.components),
            "hand_frequency_range_hz": f"{low:g} to {high:g}",
            "hand_knots_per_stroke": int(self.knots_per_stroke),
            "hand_seed": int(self.seed),
        }


def irregular_hand_profile(params: Parameters, variation: HandVariation, output_dt_s: float = 0.01) -> HandProfile:
    """The Section 4 cycle turned by a hand whose speed wanders, with the same reversal times and lock angles.

    Each stroke (straight ahead to right lock, right to left lock, left lock to straight ahead)
    keeps the saw tooth's structure: from rest, the rate ramps linearly over half the rounding
    time, cruises, and ramps back to rest at the lock at the corner time. In the cruise the rate
    is linear between knots at the ramp ends and `knots_per_stroke` evenly spaced instants
    between them, where it equals c * speed_factor(t); c is set so that the stroke covers exactly
    its travel (the integral is linear in c). So the angle reaches each lock at its corner time and
    is monotone between reversals. With no variation this is the model's saw tooth exactly.
    """
    p = params.sections["input"]
    lock = p["handwheel_lock_angle"]
    anchors = _anchor_times(params)
    travels = (lock, -2.0 * lock, lock)
    half = p["reversal_rounding_time"] / 2.0
    pieces: list[tuple[float, float, float, float]] = []
    angle = 0.0
    for (t0, t1), travel in zip(zip(anchors[:-1], anchors[1:]), travels):
        if t1 - t0 <= 2.0 * half:
            raise UsageError(f"input: a segment of {t1 - t0:g} s is shorter than the rounding time {2 * half:g} s")
        cruise = np.linspace(t0 + half, t1 - half, variation.knots_per_stroke + 2)
        factor = variation.speed_factor(cruise)
        if half > 0.0:  # from rest and back to rest at the lock
            knots = np.concatenate(([t0], cruise, [t1]))
            shape = np.concatenate(([0.0], factor, [0.0]))
        else:  # ideal saw tooth: the rate jumps at the corners
            knots, shape = cruise, factor
        area = float(np.sum(0.5 * (shape[1:] + shape[:-1]) * np.diff(knots)))
        rates = travel / area * shape
        for j in range(len(knots) - 1):
            accel = (rates[j + 1] - rates[j]) / (knots[j + 1] - knots[j])
            pieces.append((float(knots[j]), angle, float(rates[j]), float(accel)))
            angle += 0.5 * (rates[j] + rates[j + 1]) * (knots[j + 1] - knots[j])
    pieces.append((float(anchors[-1]), angle, 0.0, 0.0))
    meta: dict[str, Any] = {"hand_profile": "Section 4 saw tooth with an irregular hand speed"}
    meta.update(variation.metadata())
    return _sampled(tuple(pieces), anchors, output_dt_s, meta)
