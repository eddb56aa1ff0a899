"""Split a steering cycle into its phases, from the rack motion and the handwheel torque.

The cycle (Section 3) runs from straight ahead to one lock, to the other, back to straight ahead; each sample gets
exactly one label: ``initial_rise`` (before the rack moves steadily), ``wind_up`` (each stroke's start, until the
torque has covered ``windup_fraction`` of its change to the stroke's plateau; none on air bearings), ``plateau``
(the rest of the stroke), ``reversal`` (around each change of rack direction, at least ``reversal_half_width_s``
either side of the turning point) and ``return`` (the sliding part of a final stroke back to straight ahead, and any
rest after it). The phases are read from the data alone, robustly for noisy, quantised and unevenly sampled records:
the rack's speed from local straight-line fits over ``smoothing_s``, the torque from a running median over
``torque_smoothing_s``; durations in seconds. Boundaries sit within about a quarter of the smoothing window of the
true ones. The rules and their settings: docs/measurement.md, "The cycle's phases".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..names import SURFACES

PHASES = ("initial_rise", "wind_up", "plateau", "reversal", "return")


def local_linear_fit(time_s: np.ndarray, values: np.ndarray, window_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Value and slope at each sample of a least-squares line through the samples within +-window_s/2.

    Near the ends the window is one-sided (it holds fewer samples). Works for uneven sampling.
    """
    t = np.asarray(time_s, dtype=float)
    y = np.asarray(values, dtype=float)
    half = max(window_s / 2.0, 1.5 * float(np.median(np.diff(t))))  # two or more samples per window
    lo = np.searchsorted(t, t - half, side="left")
    hi = np.searchsorted(t, t + half, side="right")
    tc = t - t.mean()  # centred, so the sums do not cancel

    def window_sum(a: np.ndarray) -> np.ndarray:
        c = np.concatenate(([0.0], np.cumsum(a)))
        return c[hi] - c[lo]

    n = (hi - lo).astype(float)
    st, sy, stt, sty = window_sum(tc), window_sum(y), window_sum(tc * tc), window_sum(tc * y)
    spread = n * stt - st * st
    # A window holding a single sample (beside a gap in the record) has no slope: call it flat.
    slope = np.divide(n * sty - st * sy, spread, out=np.zeros_like(spread), where=spread > 0.0)
    value = (sy - slope * st) / n + slope * tc
    return value, slope


def running_median(time_s: np.ndarray, values: np.ndarray, window_s: float) -> np.ndarray:
    """Median over an odd number of samples spanning about `window_s` (edges repeat the end sample)."""
    dt = float(np.median(np.diff(time_s)))
    size = max(1, int(round(window_s / dt)))
    size += 1 - size % 2
    return pm.running_median(np.asarray(values, dtype=float), size)


@dataclass(frozen=True)
class Stroke:
    """One steady motion of the rack, from its first to its last sample (stop exclusive)."""

    direction: int  # +1: rack moving right, -1: left
    start: int
    stop: int
    windup_stop: int  # first sample after the wind-up (== start when there is none)
    start_torque_Nm: float
    plateau_torque_Nm: float
    returns_to_centre: bool


@dataclass(frozen=True)
class Segment:
    """A run of samples with one phase label (stop exclusive)."""

    phase: str
    start: int
    stop: int
    start_s: float
    stop_s: float  # time of the last sample in the segment


@dataclass(frozen=True)
class CyclePhases:
    """Phase label of every sample, and the strokes and reversals it was built from."""

    time_s: np.ndarray
    labels: np.ndarray
    strokes: tuple[Stroke, ...]
    reversal_times_s: np.ndarray
    rack_smoothed_m: np.ndarray
    rack_velocity_m_s: np.ndarray
    torque_smoothed_Nm: np.ndarray

    def mask(self, phase: str) -> np.ndarray:
        if phase not in PHASES:
            raise UsageError(f"unknown phase {phase!r} (known: {', '.join(PHASES)})")
        return self.labels == phase

    @property
    def segments(self) -> tuple[Segment, ...]:
        change = np.flatnonzero(self.labels[1:] != self.labels[:-1]) + 1
        starts = np.concatenate(([0], change))
        stops = np.concatenate((change, [len(self.labels)]))
        return tuple(
            Segment(str(self.labels[a]), int(a), int(b), float(self.time_s[a]), float(self.time_s[b - 1]))
            for a, b in zip(starts, stops)
        )

    def summary(self) -> list[dict]:
        """The segments as plain dicts (for JSON)."""
        return [
            {"phase": s.phase, "start_s": s.start_s, "stop_s": s.stop_s, "samples": s.stop - s.start}
            for s in self.segments
        ]


def _runs(direction: np.ndarray) -> list[tuple[int, int, int]]:
    """(sign, start, stop) of each run of equal non-zero `direction` (stop exclusive)."""
    change = np.flatnonzero(direction[1:] != direction[:-1]) + 1
    starts = np.concatenate(([0], change))
    stops = np.concatenate((change, [len(direction)]))
    return [(int(direction[a]), int(a), int(b)) for a, b in zip(starts, stops) if direction[a] != 0]


def find_phases(
    time_s: np.ndarray,
    rack_m: np.ndarray,
    torque_Nm: np.ndarray,
    *,
    surface: str = "ground",
    smoothing_s: float = 0.5,
    torque_smoothing_s: float = 0.3,
    moving_fraction: float = 0.2,
    min_stroke_s: float = 1.0,
    reversal_half_width_s: float = 0.25,
    windup_fraction: float = 0.9,
    plateau_travel_fraction: float = 0.25,
) -> CyclePhases:
    """Label every sample of a steering cycle with its phase (see the module docstring for the rules)."""
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(rack_m, dtype=float)
    torque = np.asarray(torque_Nm, dtype=float)
    if surface not in SURFACES:
        raise UsageError(f"unknown surface {surface!r} (known: {', '.join(SURFACES)})")
    if not (len(t) == len(x) == len(torque)) or len(t) < 3:
        raise UsageError("phases: time, rack and torque need the same length, at least 3 samples")
    if (np.diff(t) <= 0.0).any():
        raise UsageError("phases: time must be strictly increasing")

    rack_s, velocity = local_linear_fit(t, x, smoothing_s)
    torque_s = running_median(t, torque, torque_smoothing_s)
    motions = _steady_motions(t, velocity, moving_fraction, min_stroke_s)
    bounds, reversal_windows, reversal_times = _reversals(t, rack_s, motions, reversal_half_width_s)

    labels = np.empty(len(t), dtype="<U12")
    labels[: bounds[0][0]] = "initial_rise"
    for w_start, w_stop in reversal_windows:
        labels[w_start:w_stop] = "reversal"
    strokes = _label_strokes(labels, rack_s, torque_s, motions, bounds, surface == "ground", windup_fraction,
                             plateau_travel_fraction)
    return CyclePhases(
        time_s=t,
        labels=labels,
        strokes=tuple(strokes),
        reversal_times_s=np.array(reversal_times),
        rack_smoothed_m=rack_s,
        rack_velocity_m_s=velocity,
        torque_smoothed_Nm=torque_s,
    )


def _steady_motions(t: np.ndarray, velocity: np.ndarray, moving_fraction: float, min_stroke_s: float
                    ) -> list[list[int]]:
    """[sign, start, stop] of each stroke: the runs of steady rack motion of at least `min_stroke_s`, runs in one
    direction joined (a pause of the hand, not a reversal)."""
    typical_speed = float(np.percentile(np.abs(velocity), 90))
    if typical_speed == 0.0:
        raise UsageError("phases: the rack never moves, so the record holds no steering cycle")
    moving = np.abs(velocity) > moving_fraction * typical_speed
    direction = np.where(moving, np.sign(velocity), 0).astype(int)

    runs = [r for r in _runs(direction) if t[r[2] - 1] - t[r[1]] >= min_stroke_s]
    if not runs:
        raise UsageError(f"phases: the rack never moves steadily for {min_stroke_s:g} s")
    merged: list[list[int]] = [list(runs[0])]
    for sign, a, b in runs[1:]:
        if sign == merged[-1][0]:
            merged[-1][2] = b  # a pause of the hand, not a reversal
        else:
            merged.append([sign, a, b])
    return merged


def _reversals(t: np.ndarray, rack_s: np.ndarray, motions: list[list[int]], half_width_s: float
               ) -> tuple[list[list[int]], list[tuple[int, int]], list[float]]:
    """The strokes' [start, stop] trimmed to the reversal windows between strokes of opposite direction, the
    windows (start, stop) and the turning points' times; any rest after the last stroke belongs to it."""
    bounds = [[a, b] for _, a, b in motions]
    reversal_windows: list[tuple[int, int]] = []
    reversal_times: list[float] = []
    for k in range(len(motions) - 1):
        sign = motions[k][0]
        end, next_start = bounds[k][1], bounds[k + 1][0]  # end: first sample after stroke k's motion
        between = slice(end - 1, next_start + 1)
        turn = end - 1 + int(np.argmax(sign * rack_s[between]))
        t_turn = float(t[turn])
        w_start = min(end, int(np.searchsorted(t, t_turn - half_width_s, side="left")))
        w_stop = max(next_start, int(np.searchsorted(t, t_turn + half_width_s, side="right")))
        w_start = max(w_start, bounds[k][0] + 1)  # never swallow a whole stroke
        w_stop = min(w_stop, bounds[k + 1][1] - 1)
        bounds[k][1], bounds[k + 1][0] = w_start, w_stop
        reversal_windows.append((w_start, w_stop))
        reversal_times.append(t_turn)
    bounds[-1][1] = len(t)
    return bounds, reversal_windows, reversal_times


def _label_strokes(labels: np.ndarray, rack_s: np.ndarray, torque_s: np.ndarray, motions: list[list[int]],
                   bounds: list[list[int]], winds_up: bool, windup_fraction: float, plateau_travel_fraction: float
                   ) -> list[Stroke]:
    """Each stroke's wind-up (on the ground only: `winds_up`) and plateau, or return for a last stroke heading back
    to straight ahead, written into `labels`; the strokes."""
    strokes = []
    for k, ((sign, _, _), (a, b)) in enumerate(zip(motions, bounds)):
        travel = np.abs(rack_s[a:b] - rack_s[a])
        late = travel >= (1.0 - plateau_travel_fraction) * travel.max()
        start_torque = float(torque_s[a])
        plateau_torque = float(np.median(torque_s[a:b][late]))
        change = plateau_torque - start_torque
        windup_stop = a
        if winds_up and change != 0.0:
            progress = (torque_s[a:b] - start_torque) / change
            reached = np.flatnonzero(progress >= windup_fraction)
            windup_stop = a + int(reached[0]) if reached.size else b
        returns = k == len(motions) - 1 and sign * rack_s[a] < 0.0
        labels[a:windup_stop] = "wind_up"
        labels[windup_stop:b] = "return" if returns else "plateau"
        strokes.append(Stroke(sign, a, b, windup_stop, start_torque, plateau_torque, returns))
    return strokes
