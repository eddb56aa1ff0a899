"""Raw CAN logs (parksteer.measure.readers.can_log, parksteer.measure.bus): checksums against frames of real cars,
the VW MQB sign conventions, and decoding that loses nothing beyond the DBC's resolution in every log format."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("can")
pytest.importorskip("cantools")

from parksteer.cli import main  # noqa: E402
from parksteer.measure.bus import WRITERS, bus_channel_map, encode_frames, write_log  # noqa: E402
from parksteer.measure.importers import load_record  # noqa: E402
from parksteer.measure.io import Measurement, format_measurement  # noqa: E402
from parksteer.measure.readers.bus_files import e2e_p2_checksum, load_bus, load_dbc  # noqa: E402
from parksteer.measure.readers.can_log import read_bus_log  # noqa: E402

# Frames logged on real MQB cars, published with opendbc 0.3.1 (opendbc/can/tests/test_checksums.py), byte 0 the
# checksum the car's own control unit computed.
LWI_01_FRAMES = [bytes.fromhex(h) for h in ("6b00bd0000000000", "ee010a0000000000", "d802a90000000000",
                                            "0303bea212000000", "7b04312003000000", "8b05e28509000000")]
ESP_21_FRAMES = [bytes.fromhex(h) for h in ("66d01f8045050000", "87d11f8052050000", "cdd21f8050060000",
                                            "fdd31f8035020000", "fad41f8022050000", "fdd51f8084040000")]


def test_checksum_matches_the_frames_of_real_cars():
    """AUTOSAR E2E profile 2 (CRC8H2F and the data ID of each counter value, parksteer/data/buses/vw_mqb.toml)
    reproduces the checksum byte of frames the cars' own steering-angle sensor (LWI_01) and ESP (ESP_21) sent,
    over six counter values each; one flipped data bit changes it."""
    ids = load_bus("vw_mqb").data_ids
    for frame_id, frames in ((134, LWI_01_FRAMES), (253, ESP_21_FRAMES)):
        for frame in frames:
            assert e2e_p2_checksum(frame, ids[frame_id]) == frame[0]
            flipped = frame[:3] + bytes([frame[3] ^ 0x01]) + frame[4:]
            assert e2e_p2_checksum(flipped, ids[frame_id]) != frame[0]


def _log_text(frames: list[tuple[float, int, bytes]]) -> str:
    return "".join(f"({t:.6f}) can0 {i:03X}#{d.hex().upper()}\n" for t, i, d in frames)


def test_a_real_frames_angle_and_the_sign_conventions(tmp_path):
    """The real LWI_01 frame 03 03 BE A2 12 .. holds 702 counts (70.2 deg) with LWI_VZ_Lenkradwinkel set: opendbc
    reads that as -70.2 deg in openpilot's left-positive frame, so here, positive to the right
    (data/measurements/README.md), it is +70.2 deg. A torque frame built with EPS_VZ_Lenkmoment set and 250 cN m
    likewise reads +2.50 N m, and one with the flag clear -2.50 N m."""
    bus = load_bus("vw_mqb")
    dbc = load_dbc(bus)
    lwi, eps = dbc.get_message_by_name("LWI_01"), dbc.get_message_by_name("LH_EPS_03")
    real = lwi.decode(LWI_01_FRAMES[3])
    assert (real["LWI_Lenkradwinkel"], real["LWI_VZ_Lenkradwinkel"]) == (70.2, 1)

    def frame(message, counter, **values):
        signals = {s.name: 0 for s in message.signals} | values | {"COUNTER": counter % 16}
        data = bytearray(message.encode(signals, scaling=False, strict=False))
        data[0] = e2e_p2_checksum(bytes(data), bus.data_ids[message.frame_id])
        return bytes(data)

    rows = []
    for k in range(60):
        rows.append((0.01 * k, 134, frame(lwi, k, LWI_Lenkradwinkel=702, LWI_VZ_Lenkradwinkel=1)))
        rows.append((0.01 * k + 0.002, 159, frame(eps, k, EPS_Lenkmoment=250, EPS_VZ_Lenkmoment=int(k < 30))))
    path = tmp_path / "real.log"
    path.write_text(_log_text(rows), encoding="utf-8")
    channels = bus_channel_map("vw_mqb", None, None, None)
    channels = type(channels)([c for c in channels if c.target != "vehicle_speed_mps"], channels.bus)
    assert all(c.negate for c in channels)  # openpilot's left-positive frame to the project's right-positive one
    record = read_bus_log(path.read_bytes(), path, channels)
    by_name = {s.name: s for s in record.sources}
    assert np.allclose(by_name["LWI_01.LWI_Lenkradwinkel"].values, -70.2)  # then negated by the map: +70.2 deg
    torque = by_name["LH_EPS_03.EPS_Lenkmoment"].values
    assert np.allclose(torque[:30], -250.0) and np.allclose(torque[30:], 250.0)  # then negated by the map
    assert "LWI_01 checksum autosar_e2e_p2 checked" in record.metadata["bus_checks"]
    assert "bus_findings" not in record.metadata  # every frame good: no counter jump, checksum or gap


def _record(torque_scale: float = 0.4) -> Measurement:
    """The shipped example record's torque (scaled into the 10.23 N m LH_EPS_03 carries) and angle at 100 Hz."""
    from parksteer.measure.io import read_measurement

    m = read_measurement(Path(__file__).resolve().parents[2] / "data" / "measurements" / "example_unladen.csv")
    t = np.arange(0.0, m.time_s[-1], 0.01)
    return Measurement(None, {"time_s": t,
                              "handwheel_torque_Nm": torque_scale * np.interp(t, m.time_s, m.handwheel_torque_Nm),
                              "handwheel_angle_rad": np.interp(t, m.time_s, m.columns["handwheel_angle_rad"])},
                       {"case": "unladen", "surface": "ground"})


@pytest.mark.parametrize("fmt", sorted(WRITERS))
def test_decoding_loses_nothing_but_the_dbc_resolution(tmp_path, fmt):
    """A record sent as the frames of a VW MQB car (torque 0.01 N m, angle 0.1 deg a count, counters and
    checksums) and written as candump, ASC, BLF, TRC or MDF4 bus logging reads back, on the torque message's
    clock, within half a count of the DBC of the original: nothing is lost but the bus's own resolution. The
    resolution is stated as the torque's quantisation step (full scale 10.23 N m, 11 bits: sign and 10)."""
    if fmt == "mf4":
        pytest.importorskip("asammdf")
    record = _record()
    channels = bus_channel_map("vw_mqb", None, None, None)
    path = write_log(encode_frames(record, channels), tmp_path / f"run{WRITERS[fmt]}", fmt, channels.bus.dbc)
    decoded = load_record(path, channels, case="unladen", surface="ground")
    t = decoded.time_s
    assert np.allclose(t, record.time_s[: len(t)], atol=2e-6)
    for column, half_count in (("handwheel_torque_Nm", 0.005), ("handwheel_angle_rad", np.radians(0.05))):
        original = record.columns[column][: len(t)]
        # the formats store time stamps to a microsecond or so: the angle, interpolated onto the torque frames'
        # time stamps, may move by its rate times that
        stamp = 2e-6 * np.abs(np.gradient(original, record.time_s[: len(t)])).max()
        error = np.abs(decoded.columns[column] - original)
        assert error.max() <= half_count * (1 + 1e-9) + stamp, (column, error.max())
    assert np.all(decoded.columns["vehicle_speed_mps"] == 0.0)
    assert decoded.metadata["full_scale_handwheel_torque_Nm"] == "10.23"
    assert decoded.metadata["bits_handwheel_torque_Nm"] == "11"
    assert "LWI_01 (100 Hz) interpolated linearly" in decoded.metadata["bus_time_base"]


def test_lost_duplicated_and_corrupt_frames_are_named_and_dropped(tmp_path, capsys):
    """Three frames lost, one sent twice and one with a flipped checksum: the record still reads, each finding is
    a note with its time, and the frames kept are the good ones (no counter repeats in what is decoded)."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from hardening.corpus import _bus_log

    path = _bus_log(tmp_path, "dropped", "candump")
    channels = bus_channel_map("vw_mqb", None, None, None)
    decoded = load_record(path, channels, case="unladen", surface="ground")
    findings = decoded.metadata["bus_findings"]
    assert "duplicated frames dropped" in findings or "repeating their counter dropped" in findings
    assert "failing their checksum dropped" in findings
    assert "counter COUNTER jumps" in findings
    assert "note:" in capsys.readouterr().err


def _diagnose(path: Path, *extra: str) -> dict:
    import contextlib
    import io

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert main(["diagnose", str(path), *extra, "--jobs", "1", "--quiet", "--json"]) == 0
    return json.loads(buffer.getvalue())


def _quantised(record: Measurement) -> Measurement:
    """`record` as the bus carries it, made without the bus: torque to the nearest 0.01 N m and angle to the
    nearest 0.1 deg in magnitude (sign and magnitude, as LH_EPS_03 and LWI_01 send them), with the resolution as
    the bus reader states it."""
    torque, angle = record.columns["handwheel_torque_Nm"], record.columns["handwheel_angle_rad"]
    metadata = {k: v for k, v in record.metadata.items() if not k.startswith(("bits", "full_scale_"))}
    metadata.update({"full_scale_handwheel_torque_Nm": "10.23", "bits_handwheel_torque_Nm": "11",
                     "full_scale_handwheel_angle_rad": f"{np.radians(819.1):.10g}", "bits_handwheel_angle_rad": "14"})
    return Measurement(None, {"time_s": record.time_s,
                              "handwheel_torque_Nm": np.sign(torque) * np.round(np.abs(torque) * 100.0) / 100.0,
                              "handwheel_angle_rad": np.sign(angle) * np.radians(np.round(np.abs(np.degrees(angle)) * 10.0) / 10.0)},
                       metadata)


@pytest.mark.slow
@pytest.mark.parametrize("hidden", [None, ("+column_friction", {"column_friction.friction_torque": 1.0})],
                         ids=["null", "column_friction"])
def test_diagnosis_of_the_bus_log_is_the_diagnosis_of_the_record(tmp_path, hidden):
    """A record of the variation benchmark's angle logger (16-bit torque and angle at 100 Hz, the rate of
    LH_EPS_03; on air bearings, where the torque stays inside the 10.23 N m the signal carries), with nothing or
    a column friction of 1 N m hidden, diagnosed as its CSV and as a candump log of a VW MQB car: the same
    verdict and effect, and the same noise floor within 1 %. What the bus changes is its resolution alone: the log
    is diagnosed as the CSV rounded to 0.01 N m and 0.1 deg (made with numpy, not through the bus), calibrated
    error within 0.1 % (the CSV's nine digits and the log's microsecond time stamps)."""
    import dataclasses

    from parksteer.parameters import load_parameters
    from parksteer.synthetic.variations import VARIATIONS, variation_record

    variation = next(v for v in VARIATIONS if v.uses_angle)
    logger = dataclasses.replace(variation.logger, torque_bits=16, angle_bits=16, sample_rate_hz=100.0)
    effects, overrides = hidden or (None, None)
    m = variation_record(load_parameters(), variation.hand, logger, surface="air_bearing", effects=effects,
                         overrides=overrides)
    record = Measurement(None, {k: m.columns[k] for k in ("time_s", "handwheel_torque_Nm", "handwheel_angle_rad")},
                         m.metadata)
    csv, rounded = tmp_path / "record.csv", tmp_path / "rounded.csv"
    csv.write_text(format_measurement(record), encoding="utf-8")
    rounded.write_text(format_measurement(_quantised(record)), encoding="utf-8")
    channels = bus_channel_map("vw_mqb", None, None, None)
    log = write_log(encode_frames(record, channels), tmp_path / "run.log", "candump")
    a, q = _diagnose(csv), _diagnose(rounded)
    b = _diagnose(log, "--bus", "vw_mqb", "--case", "unladen", "--surface", "air_bearing")
    assert (a["verdict"], a["effect"]) == (b["verdict"], b["effect"]) == (q["verdict"], q["effect"])
    assert b["noise_floor_Nm"] == pytest.approx(a["noise_floor_Nm"], rel=0.01)
    assert b["noise_floor_Nm"] == pytest.approx(q["noise_floor_Nm"], rel=1e-3)
    cq, cb = q["statistics"]["calibrated"], b["statistics"]["calibrated"]
    assert cb["weighted_rms_Nm"] == pytest.approx(cq["weighted_rms_Nm"], rel=1e-3)


def test_map_options_parse_and_print_back():
    """';sign=' and ';scale=' after a bus signal's target: parsed, printed back by spec() as given, and a wrong
    option or a zero scale refused in one line naming the entry."""
    from parksteer.errors import UsageError
    from parksteer.measure.channel_map import parse_channel_map

    (ch,) = parse_channel_map("LH_EPS_03.EPS_Lenkmoment[cN*m]=-handwheel_torque_Nm;sign=LH_EPS_03.EPS_VZ_Lenkmoment")
    assert (ch.source, ch.unit, ch.negate, ch.sign, ch.scale) == (
        "LH_EPS_03.EPS_Lenkmoment", "cN*m", True, "LH_EPS_03.EPS_VZ_Lenkmoment", None)
    assert ch.spec() == "LH_EPS_03.EPS_Lenkmoment[cN*m]=-handwheel_torque_Nm;sign=LH_EPS_03.EPS_VZ_Lenkmoment"
    (ch,) = parse_channel_map("S.T[N*m]=handwheel_torque_Nm;scale=0.0125")
    assert ch.scale == 0.0125 and ch.spec().endswith(";scale=0.0125")
    with pytest.raises(UsageError, match="scale=0 is not a finite non-zero number"):
        parse_channel_map("S.T=handwheel_torque_Nm;scale=0")
    with pytest.raises(UsageError, match="option 'sing=S.V' is neither"):
        parse_channel_map("S.T=handwheel_torque_Nm;sing=S.V")


TOYOTA_LIKE_DBC = '''VERSION ""

NS_ :

BS_:

BU_: XXX

BO_ 608 STEER_TORQUE_SENSOR: 8 XXX
 SG_ STEER_TORQUE_EPS : 47|16@0- (1,0) [-32768|32767] "" XXX
 SG_ STEER_TORQUE_DRIVER : 15|16@0- (1,0) [-32768|32767] "" XXX
 SG_ STEER_ANGLE : 31|16@0- (0.0573,0) [-500|500] "" XXX
 SG_ STEER_OVERRIDE : 0|1@0+ (1,0) [0|1] "" XXX
 SG_ CHECKSUM : 63|8@0+ (1,0) [0|255] "" XXX
'''


def test_a_raw_count_with_a_scale_from_a_dbc_given_alone(tmp_path):
    """Toyota's STEER_TORQUE_SENSOR layout (big-endian signed 16-bit raw counts, opendbc's toyota DBC): with
    --dbc and 'scale=' a count of -321 at scale 0.01 N m reads -3.21 N m, the angle's 0.0573 deg factor is the
    DBC's; with no algorithm known the checksum is said to be unchecked; the resolution is one count times the
    scale."""
    import cantools

    dbc_path = tmp_path / "toyota_like.dbc"
    dbc_path.write_text(TOYOTA_LIKE_DBC, encoding="utf-8")
    message = cantools.database.load_file(str(dbc_path)).get_message_by_name("STEER_TORQUE_SENSOR")
    rows = [(0.01 * k, 608, message.encode({"STEER_TORQUE_EPS": 0, "STEER_TORQUE_DRIVER": -321, "STEER_ANGLE": 1000,
                                              "STEER_OVERRIDE": 0, "CHECKSUM": 0}, scaling=False)) for k in range(20)]
    path = tmp_path / "toyota.log"
    path.write_text(_log_text(rows), encoding="utf-8")
    channels = bus_channel_map(None, str(dbc_path), "STEER_TORQUE_SENSOR.STEER_TORQUE_DRIVER[N*m]="
                               "handwheel_torque_Nm;scale=0.01,STEER_TORQUE_SENSOR.STEER_ANGLE[deg]=handwheel_angle_rad",
                               None)
    record = read_bus_log(path.read_bytes(), path, channels)
    torque, angle = record.sources
    assert np.allclose(torque.values, -3.21) and torque.step == pytest.approx(0.01)
    assert np.allclose(angle.values, 57.3) and angle.step == pytest.approx(0.0573)
    assert "STEER_TORQUE_SENSOR checksum not checked" in record.metadata["bus_checks"]
    assert any("checksum CHECKSUM not checked (no algorithm known for toyota_like.dbc" in n for n in record.notes)


def test_a_bus_log_drives_the_rack_of_a_simulation(tmp_path):
    """`simulate --rack-from` takes a bus log as compare does: the rack derived from the decoded angle and
    torque drives the model (an entry point beside compare and diagnose)."""
    record = _record()
    channels = bus_channel_map("vw_mqb", None, None, None)
    log = write_log(encode_frames(record, channels), tmp_path / "run.log", "candump")
    out = tmp_path / "sim.csv"
    assert main(["simulate", "--rack-from", str(log), "--bus", "vw_mqb", "--case", "unladen", "--surface", "ground",
                 "--out", str(out)]) == 0
    assert out.is_file()


def test_a_log_of_two_buses_is_read_from_the_channel_with_the_message(tmp_path):
    """candump -l any writes every bus into one file; a gateway forwards LH_EPS_03 to the second bus with its own
    delay. The message is read from the channel with most of its frames, and a note says so (two interleaved
    copies would read as counters going back and forth)."""
    record = _record()
    channels = bus_channel_map("vw_mqb", None, None, None)
    frames = encode_frames(record, channels)
    import can

    forwarded = [can.Message(timestamp=f.timestamp + 0.0004, arbitration_id=f.arbitration_id, data=f.data,
                             is_extended_id=False, channel="can1") for f in frames[::2] if f.arbitration_id == 159]
    for f in frames:
        f.channel = "can0"
    both = sorted(frames + forwarded, key=lambda f: f.timestamp)
    log = write_log(both, tmp_path / "any.log", "candump")
    decoded = load_record(log, channels, case="unladen", surface="ground")
    assert "LH_EPS_03 is on channels can0" in decoded.metadata["bus_findings"]
    assert "read from can0" in decoded.metadata["bus_findings"]
    assert "jumps" not in decoded.metadata["bus_findings"]
    assert np.abs(decoded.columns["handwheel_torque_Nm"] - record.columns["handwheel_torque_Nm"][: decoded.n_samples]
                  ).max() <= 0.005 + 1e-9
