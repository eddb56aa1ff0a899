"""Big and fast records: a record sampled far faster than the method needs is anti-alias filtered and decimated
on reading, and one beyond the caps is refused in one line before it is parsed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.measure import importers, text_table
from parksteer.measure.importers import METHOD_RATE_HZ, load_record

from .corpus import base_record


def _fast_record(path, rate_hz: float, tone_hz: float, tone_Nm: float) -> tuple[np.ndarray, np.ndarray]:
    """The example cycle resampled to `rate_hz`, plus a torque tone at `tone_hz`; returns (time, clean torque)."""
    meta, header, data = base_record(1)
    meta = [m for m in meta if not m.startswith(("# bits", "# full_scale", "# sample_rate"))]
    t = np.arange(data[0, 0], data[-1, 0], 1.0 / rate_hz)
    cols = [t] + [np.interp(t, data[:, 0], data[:, j]) for j in range(1, data.shape[1])]
    clean = cols[2].copy()
    cols[2] = clean + tone_Nm * np.sin(2 * np.pi * tone_hz * t)
    body = "\n".join(",".join(f"{v:.9g}" for v in row) for row in zip(*cols))
    path.write_text("\n".join(meta + [",".join(header)]) + "\n" + body + "\n", encoding="utf-8")
    return t, clean


def test_fast_record_is_decimated_and_a_tone_above_the_new_nyquist_is_filtered_not_aliased(tmp_path, params):
    """A 5 kHz record decimates to METHOD_RATE_HZ or a little more. A 1 N m tone at 2.43 kHz (above the new Nyquist frequency)
    would alias to a slow wobble of full size if samples were only picked; the anti-alias filter removes it: the
    record with the tone reads within 0.02 N m of the same record without it."""
    t, clean = _fast_record(tmp_path / "fast.csv", 5000.0, 2430.0, 1.0)
    _fast_record(tmp_path / "plain.csv", 5000.0, 2430.0, 0.0)
    m = load_record(tmp_path / "fast.csv", params=params)
    plain = load_record(tmp_path / "plain.csv", params=params)
    rate = 1.0 / m.sample_interval_s
    assert METHOD_RATE_HZ <= rate < 2 * METHOD_RATE_HZ
    assert "decimated" in m.metadata
    inner = slice(20, -20)  # the filter's edge transients
    assert np.max(np.abs(m.handwheel_torque_Nm - plain.handwheel_torque_Nm)[inner]) < 0.02
    # The cycle itself passes: the filter changes the torque by less, in RMS, than the example's 8-bit torque
    # converter rounds it (step 2 x 25 N m / 255, rounding RMS step / sqrt(12) = 0.057 N m).
    change = (plain.handwheel_torque_Nm - np.interp(plain.time_s, t, clean))[inner]
    assert np.sqrt(np.mean(change**2)) < (2 * 25 / 255) / np.sqrt(12)
    # Plain picking of every step-th sample (no filter) leaves the tone aliased at full size, so the first check
    # can fail.
    step = int(round(5000.0 / rate))
    assert np.max(np.abs(np.sin(2 * np.pi * 2430.0 * t[::step]))) > 0.5


def test_a_record_cut_under_load_keeps_its_ends_through_the_decimation(tmp_path, params):
    """A fast record cut where the torque and the rack are far from 0 (the example cycle at 200 Hz, cut at its
    largest torque, 18.7 N m near the lock) ends where its logger left it: the zero-phase filter reads the record
    reflected through its end sample beyond it, and a straight line passes such a filter unchanged, so the last
    tenth of a second is within the example's 8-bit torque rounding (RMS 0.057 N m) and a tenth of a millimetre of
    the logged values. Zeros read there instead (scipy.signal.decimate's padding) pull the last samples toward 0
    and set them ringing, newton metres of torque and millimetres of rack off, which the last assertion shows."""
    from parksteer import portable as pm

    meta, header, data = base_record(1)
    meta = [m for m in meta if not m.startswith(("# bits", "# full_scale", "# sample_rate"))]
    t = np.arange(data[0, 0], data[-1, 0], 1.0 / 200.0)
    cols = [t] + [np.interp(t, data[:, 0], data[:, j]) for j in range(1, data.shape[1])]
    end = int(np.argmax(np.abs(cols[2][: len(t) // 2]))) + 1  # cut at the largest torque of the first stroke
    body = "\n".join(",".join(f"{v:.9g}" for v in row) for row in zip(*(c[:end] for c in cols)))
    path = tmp_path / "cut_under_load.csv"
    path.write_text("\n".join(meta + [",".join(header)]) + "\n" + body + "\n", encoding="utf-8")
    m = load_record(path, params=params)
    assert "decimated" in m.metadata and abs(m.handwheel_torque_Nm[-1]) > 10.0 and abs(m.rack_m[-1]) > 0.05
    last = slice(-10, None)  # half the filter's 41 taps at 200 Hz, in samples at 100 Hz
    logged_torque = np.interp(m.time_s, t, cols[2])
    logged_rack = np.interp(m.time_s, t, cols[1])
    assert np.max(np.abs(m.handwheel_torque_Nm - logged_torque)[last]) < (2 * 25 / 255) / np.sqrt(12)
    assert np.max(np.abs(m.rack_m - logged_rack)[last]) < 1e-4
    zeros = pm.fir_decimate(cols[2][:end], pm.hamming_lowpass_fir(41, 0.5), 2)
    assert np.max(np.abs(zeros - logged_torque)[last]) > 1.0


def test_slow_record_is_kept_sample_for_sample(tmp_path, params):
    """The 50 Hz example needs no decimation: every sample is kept and nothing is noted."""
    m = load_record(Path(__file__).resolve().parents[2] / "data/measurements/example_unladen.csv", params=params)
    assert m.n_samples == 901
    assert "decimated" not in m.metadata


def test_record_beyond_the_row_cap_is_refused_before_parsing(tmp_path, params, monkeypatch):
    """More data rows than MAX_SAMPLES: one line naming the file and the cap (the cap lowered to keep it small)."""
    path = tmp_path / "long.csv"
    _fast_record(path, 200.0, 1.0, 0.0)
    monkeypatch.setattr(text_table, "MAX_SAMPLES", 1000)
    with pytest.raises(UsageError, match=r"long\.csv: \d+ data rows, beyond the 1000"):
        load_record(path, params=params)


def test_record_beyond_the_size_cap_is_refused_before_reading(tmp_path, params, monkeypatch):
    """A file larger than MAX_RECORD_BYTES: refused by its size, naming the file."""
    path = tmp_path / "huge.csv"
    _fast_record(path, 200.0, 1.0, 0.0)
    monkeypatch.setattr(importers, "MAX_RECORD_BYTES", 1000)
    with pytest.raises(UsageError, match=r"huge\.csv: .* MiB"):
        load_record(path, params=params)


def test_a_decimated_record_keeps_the_step_its_converter_rounded_to(tmp_path, params):
    """Filtered samples are off the converter's levels, so a decimated record states no levels (full scale and bits
    are dropped), but where a channel moves by less than a step the filter averages no rounding away: each channel
    keeps the step it was rounded to (2 full_scale / 255 of the file's 8 bits), and an angle-only record's derived
    rack is rounded by the angle's step over the steering ratio (parksteer.measure.column.rack_rounding)."""
    from parksteer.measure.column import rack_rounding
    from parksteer.measure.converter import quantisation_step

    meta, header, data = base_record(1)
    meta = [m for m in meta if not m.startswith("# sample_rate")]
    t = np.arange(data[0, 0], data[-1, 0], 1.0 / 400.0)
    keep = [j for j, name in enumerate(header) if name != "rack_m"]
    cols = [t] + [np.interp(t, data[:, 0], data[:, j]) for j in keep[1:]]
    body = "\n".join(",".join(f"{v:.9g}" for v in row) for row in zip(*cols))
    path = tmp_path / "fast_angle_only.csv"
    path.write_text("\n".join(meta + [",".join(header[j] for j in keep)]) + "\n" + body + "\n", encoding="utf-8")
    m = load_record(path, params=params)
    assert "decimated" in m.metadata and "rack_derived" in m.metadata
    angle = "handwheel_angle_rad"
    assert m.quantisation_step(angle) == 0.0
    assert m.rounding_step(angle) == pytest.approx(quantisation_step(16.0, 8), rel=1e-12)
    assert m.rounding_step("handwheel_torque_Nm") == pytest.approx(quantisation_step(25.0, 8), rel=1e-12)
    ratio = params.sections["steering"]["handwheel_to_rack_ratio"]
    assert rack_rounding(m, params) == pytest.approx(quantisation_step(16.0, 8) / ratio, rel=1e-12)
