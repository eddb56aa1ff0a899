"""The few filters the loggers and the import use, designed in closed form, and the running filters of the
import, without scipy (:mod:`parksteer.portable` says why)."""

from __future__ import annotations

import numpy as np

from .elementary import cos, sin, tan


def butterworth_lowpass_sos(order: int, cutoff_hz: float, rate_hz: float) -> np.ndarray:
    """Second-order sections (rows b0 b1 b2 1 a1 a2) of a digital Butterworth low-pass, by the bilinear transform
    with the cutoff prewarped: the design of ``scipy.signal.butter(order, cutoff_hz, fs=rate_hz, output="sos")``
    written out, with c = tan(pi fc / fs) and each analogue pole pair's damping q = 2 sin((2k + 1) pi / 2n):
    H(z) = c^2 (1 + 1/z)^2 / ((1 + q c + c^2) + 2 (c^2 - 1) / z + (1 - q c + c^2) / z^2), and for an odd order a
    first-order section c (1 + 1/z) / ((1 + c) + (c - 1) / z)."""
    if order < 1 or not 0.0 < cutoff_hz < 0.5 * rate_hz:
        raise ValueError(f"Butterworth low-pass: order {order} and cutoff {cutoff_hz} Hz at {rate_hz} Hz")
    c = tan(np.pi * cutoff_hz / rate_hz)
    c2 = c * c
    sections = []
    for k in range(order // 2):
        q = 2.0 * sin((2 * k + 1) * np.pi / (2 * order))
        d = 1.0 + q * c + c2
        g = c2 / d
        sections.append([g, 2.0 * g, g, 1.0, 2.0 * (c2 - 1.0) / d, (1.0 - q * c + c2) / d])
    if order % 2:
        g = c / (1.0 + c)
        sections.append([g, g, 0.0, 1.0, (c - 1.0) / (1.0 + c), 0.0])
    return np.array(sections)


def sos_steady_state(sos: np.ndarray) -> np.ndarray:
    """Initial states (per section, direct form II transposed as scipy.signal.sosfilt) for a filter at rest under a
    unit input: each section's output is its DC gain G = sum(b) / sum(a), its states z2 = b2 - a2 G and
    z1 = b1 - a1 G + z2, scaled by the DC gain of the sections before it (scipy.signal.sosfilt_zi, in closed
    form)."""
    states = np.empty((len(sos), 2))
    scale = 1.0
    for i, (b0, b1, b2, a0, a1, a2) in enumerate(np.asarray(sos, dtype=float)):
        b0, b1, b2, a1, a2 = b0 / a0, b1 / a0, b2 / a0, a1 / a0, a2 / a0
        gain = ((b0 + b1) + b2) / ((1.0 + a1) + a2)
        z2 = b2 - a2 * gain
        states[i] = (scale * ((b1 - a1 * gain) + z2), scale * z2)
        scale = scale * gain
    return states


def hamming_lowpass_fir(taps: int, cutoff: float) -> np.ndarray:
    """Linear-phase FIR low-pass, windowed sinc with a Hamming window, unit gain at DC; `cutoff` relative to the
    Nyquist frequency: ``scipy.signal.firwin(taps, cutoff, window="hamming")`` written out."""
    m = np.arange(taps) - 0.5 * (taps - 1)
    x = np.pi * cutoff * m
    sinc = np.where(m == 0.0, 1.0, sin(np.where(m == 0.0, 1.0, x)) / np.where(m == 0.0, 1.0, x))
    window = 0.54 + 0.46 * cos(np.linspace(-np.pi, np.pi, taps))
    h = cutoff * sinc * window
    return h / float(np.sum(h))


def fir_decimate(values: np.ndarray, fir: np.ndarray, factor: int, padtype: str = "constant") -> np.ndarray:
    """``scipy.signal.resample_poly(values, 1, factor, window=fir, padtype=padtype)`` written out, with its zero-phase
    delay, summed in upfirdn's order (oldest sample first, one rounding per product and per sum), so that it gives
    the same bits without importing scipy.signal (more than a second per process). `padtype` is what the filter
    reads beyond the ends: ``constant`` zeros (scipy's default), or ``antireflect`` the record reflected through
    its end sample, 2 x[0] - x[k] before it and 2 x[-1] - x[-1-k] after it (upfirdn's mode of that name,
    scipy.signal.filtfilt's odd padding): a straight line passes the filter unchanged up to the ends."""
    if padtype not in ("constant", "antireflect"):
        raise ValueError(f"fir_decimate: padtype {padtype!r} is not constant or antireflect")
    values = np.asarray(values, dtype=float)
    n_in = len(values)
    n_out = n_in // factor + bool(n_in % factor)
    half_len = (len(fir) - 1) // 2
    n_pre_pad = factor - half_len % factor
    n_pre_remove = (half_len + n_pre_pad) // factor
    h = np.concatenate([np.zeros(n_pre_pad), np.asarray(fir, dtype=float)])
    if padtype == "antireflect" and n_in <= len(h):
        raise ValueError(f"fir_decimate: {n_in} samples reflect no filter of {len(h)} taps")
    # output m of the full convolution taken every `factor` samples: sum over taps j of h[j] * values[m factor - j]
    outputs = np.arange(n_pre_remove, n_pre_remove + n_out) * factor
    out = np.zeros(n_out)
    for j in range(len(h) - 1, -1, -1):
        if h[j] == 0.0:
            continue
        index = outputs - j
        if padtype == "constant":
            inside = (index >= 0) & (index < n_in)
            out[inside] = out[inside] + values[index[inside]] * h[j]
            continue
        before, after = index < 0, index >= n_in
        taken = values[np.where(before, -index, np.where(after, 2 * (n_in - 1) - index, index))]
        taken = np.where(before, 2.0 * values[0] - taken, np.where(after, 2.0 * values[-1] - taken, taken))
        out = out + taken * h[j]
    return out


def running_median(values: np.ndarray, size: int) -> np.ndarray:
    """The median of `size` (odd) samples centred on each sample, the ends repeated:
    ``scipy.ndimage.median_filter(values, size, mode="nearest")`` (a selection: exact), without scipy.ndimage."""
    half = size // 2
    padded = np.concatenate([np.full(half, values[0]), values, np.full(half, values[-1])])
    windows = np.lib.stride_tricks.sliding_window_view(padded, size)
    out = np.empty(len(values))
    for start in range(0, len(values), 1 << 16):  # in blocks: a partitioned copy of every window at once is n * size
        out[start:start + (1 << 16)] = np.partition(windows[start:start + (1 << 16)], half, axis=1)[:, half]
    return out


def running_max3(values: np.ndarray) -> np.ndarray:
    """The largest of each sample and its two neighbours, the ends repeated:
    ``scipy.ndimage.maximum_filter1d(values, 3, mode="nearest")``, without scipy.ndimage."""
    padded = np.concatenate([values[:1], values, values[-1:]])
    return np.maximum(np.maximum(padded[:-2], padded[1:-1]), padded[2:])
