"""The residual's signature and the suggested effect: closed-form residuals are decomposed onto the axis they were
made on, white noise at the floor shows no structure, and a suggested effect file loads, is the base model at
zero strengths, and takes the error of a record with a hidden out-of-library form down to the floor."""

from __future__ import annotations

from dataclasses import replace

import json
import math

import jsonschema
import numpy as np
import pytest

from parksteer import portable as pm
from parksteer.cli import main
from parksteer.experiments.benchmark import BENCHMARK_SETTINGS
from parksteer.experiments.outoflibrary import SignatureCase, SignatureDesign, make_record, summarise
from parksteer.diagnose.problem import load_files
from parksteer.reporting.report import diagnosis_dict, with_suggestion
from parksteer.reporting.pages import markdown_report
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.signature import signature_from_axes
from parksteer.diagnose.signature_axes import Axes, column_angle
from parksteer.diagnose.suggest import effect_source, suggest
from parksteer.errors import UsageError
from parksteer.measure.io import write_measurement
from parksteer.model.numeric.simulate import simulate
from parksteer.model.symbolic.components import load_effect_module, resolve_effects
from parksteer.parameters import load_parameters
from parksteer.resources import data_file

PARAMS = load_parameters()
G = 186.47  # rad/m, handwheel to rack
BETA = 1000.0  # s/m, friction smoothing
FLOOR = 0.1  # N m


def _cycle(n: int = 3000, seed: int = 0, noise: float = FLOOR):
    """A Section 4-like cycle: centre -> right lock -> left lock -> centre, x = 67 mm sin(t), t over one period;
    white noise of `noise` N m on a zero residual."""
    t = np.linspace(0.0, 2.0 * np.pi, n)
    x = 0.067 * pm.sin(t)
    v = 0.067 * pm.cos(t) * (2.0 * np.pi / 12.0)  # a 12 s cycle
    rng = np.random.default_rng(seed)
    return x, v, rng.normal(0.0, noise, n)


def _axes(x, v, residual, theta=None):
    phase = np.where(np.abs(v) < 0.1 * np.max(np.abs(v)), "reversal", "plateau")
    return Axes(x, v, column_angle(x, G, 0.0, 0.0) if theta is None else theta, phase, np.zeros(len(x), int),
                residual, np.full(len(x), FLOOR), (("unladen", "ground"),), BETA, G)


def _axis(signature, start: str):
    return next(a for a in signature.axes if a.axis.startswith(start))


def test_a_residual_odd_in_rack_speed_is_all_dissipative():
    """A constant extra rack friction of 50 N reverses with the speed: at the handwheel 50 / G N m times
    tanh(beta v). Its whole excess is on the odd-in-speed axis, the class is dissipative and uniform along the
    stroke, and the force read back is the 50 N put in (to 2 %)."""
    x, v, noise = _cycle()
    residual = 50.0 / G * pm.tanh(BETA * v) + noise
    sig = signature_from_axes(_axes(x, v, residual), calibrated_rack_friction_N=600.0)
    assert sig.effect_class == "dissipative"
    assert _axis(sig, "odd in rack speed").excess_share > 0.99
    assert _axis(sig, "odd in rack speed").significant
    assert sig.best.label == "uniform"
    assert sig.numbers["uniform_N"] == pytest.approx(50.0, rel=0.02)


def test_a_once_per_turn_column_torque_is_read_as_the_first_column_order():
    """0.3 N m cos(theta_c): a torque at the column, once per turn. The class is column, order 1 dominant with
    the amplitude put in (to 3 %), and the second-order axis holds next to nothing of it."""
    x, v, noise = _cycle(seed=1)
    theta = column_angle(x, G, 0.0, 0.0)
    sig = signature_from_axes(_axes(x, v, 0.3 * pm.cos(theta) + noise))
    assert sig.effect_class == "column"
    assert sig.numbers["dominant_order"] == 1
    assert sig.numbers["amplitudes_Nm"]["1"] == pytest.approx(0.3, rel=0.03)
    assert _axis(sig, "column angle, 1 per turn").excess_share > 0.95
    assert _axis(sig, "column angle, 2 per turn").excess_share < 0.05


def _column_friction_residual(shape, seed: int):
    """A friction torque at the column, 0.25 N m times `shape` of the column angle, reversing with the column's
    rate through a breakaway of its own (tanh(omega / 0.5 rad/s), not the signature's tanh(beta v)), with the
    calibrated rack friction's direction (the smoothed sign) fitted beside every basis as the diagnosis fits the
    calibration's sensitivities: the axes, the residual and that nuisance column."""
    x, v, noise = _cycle(seed=seed)
    theta = column_angle(x, G, 0.0, 0.0)
    residual = 0.25 * shape(theta) * pm.tanh(G * v / 0.5) + noise
    axes = _axes(x, v, residual, theta)
    return axes, (pm.tanh(BETA * v) / FLOOR)[:, None]


def test_a_column_friction_pinched_once_per_turn_is_read_as_dissipative_and_periodic_in_the_column_angle():
    """A column bearing pinched at one place of its turn: its friction a narrow peak once per turn,
    exp((cos(theta - 0.9) - 1) / 0.25) (orders one to four and more, not a sinusoid). Its mean is a uniform
    friction the calibration takes; what is left is the product class dissipative x column angle, not a
    dissipative force along the stroke nor a torque that does not reverse, order 1 dominant, its peak found within
    20 degrees of the 52 degrees put in, and its suggestion at the column."""
    axes, nuisance = _column_friction_residual(lambda t: pm.exp((pm.cos(t - 0.9) - 1.0) / 0.25), seed=5)
    sig = signature_from_axes(axes, nuisance=nuisance)
    assert sig.effect_class == "dissipative_column", sig.sentence
    assert sig.numbers["dominant_order"] == 1
    assert abs(math.degrees(sig.numbers["peak_column_angle_rad"]) - math.degrees(0.9)) < 20.0
    assert sig.as_dict()["where"] == "column"
    assert "friction on the steering column" in sig.sentence


def test_a_joint_friction_growing_twice_per_turn_is_read_with_its_second_order():
    """A joint's friction growing with its angle twice per turn, sin(theta + 0.3)^4 (orders 2 and 4 about its
    mean): the product class, order 2 dominant."""
    axes, nuisance = _column_friction_residual(lambda t: pm.sin(t + 0.3) ** 4, seed=6)
    sig = signature_from_axes(axes, nuisance=nuisance)
    assert sig.effect_class == "dissipative_column", sig.sentence
    assert sig.numbers["dominant_order"] == 2


def test_the_suggested_effect_of_a_column_friction_is_a_torque_on_the_column_not_a_rack_force():
    """The file written for the product class puts a torque between the column shaft and the body that reverses
    with the motion (the smoothed sign of the rack speed times the periodic shape), strengths in N m, one sine and
    one cosine per order the signature found; it loads as a user's effect file does."""
    axes, nuisance = _column_friction_residual(lambda t: pm.exp((pm.cos(t - 0.9) - 1.0) / 0.25), seed=5)
    sig = signature_from_axes(axes, nuisance=nuisance)
    source = effect_source(sig)
    assert "torque_between(torque, k.B.y, k.column_frame, k.B)" in source
    assert "action_reaction" not in source.split("class Suggested", 1)[1]
    assert "sp.tanh(beta * model.rack_u)" in source
    namespace: dict = {}
    exec(compile(source, "suggested.py", "exec"), namespace)
    effect = namespace["EFFECT"]
    assert effect.name == "suggested_dissipative_column"
    assert {q.unit for q in effect.quantities} == {"N m"}
    assert [q.key.rsplit(".", 1)[1] for q in effect.quantities] == [f"{f}{m}" for m in sig.best.orders
                                                                      for f in ("sin", "cos")]


def test_a_localised_friction_bump_is_found_where_it_is_and_as_wide_as_it_is():
    """An extra friction 150 N exp(-((x - 20 mm) / 12 mm)^2): dissipative, peaking at +20 mm (within 3 mm), its
    half width at half height 12 mm sqrt(ln 2) = 10 mm (within 3 mm), its height 150 N (within 10 %)."""
    x, v, noise = _cycle(seed=2)
    residual = 150.0 / G * pm.exp(-(((x - 0.020) / 0.012) ** 2)) * pm.tanh(BETA * v) + noise
    sig = signature_from_axes(_axes(x, v, residual), calibrated_rack_friction_N=600.0)
    assert sig.effect_class == "dissipative"
    assert sig.numbers["peak_at_m"] == pytest.approx(0.020, abs=0.003)
    assert sig.numbers["half_width_m"] == pytest.approx(0.012 * math.sqrt(math.log(2.0)), abs=0.003)
    assert sig.numbers["departure_N"] == pytest.approx(150.0, rel=0.10)
    assert "within +-" in sig.sentence and "+20 mm" in sig.sentence


def test_a_position_force_the_same_both_ways_is_elastic():
    """A centring force 200 N x / 67 mm, the same whichever way the rack moves: elastic, with all of the excess
    on the position axis."""
    x, v, noise = _cycle(seed=3)
    sig = signature_from_axes(_axes(x, v, 200.0 / G * x / 0.067 + noise))
    assert sig.effect_class == "elastic"
    assert _axis(sig, "rack position").excess_share > 0.99


def test_a_force_growing_with_the_speed_is_read_as_viscous():
    """A rack drag c v |v| (quadratic in the speed, 0 at rest): the speed class, growing with the speed, its
    force near the 90th-percentile speed larger than at low speed."""
    x, v, noise = _cycle(seed=4)
    scale = float(np.quantile(np.abs(v), 0.9))
    residual = 80.0 / G * (v / scale) * np.abs(v / scale) + noise
    sig = signature_from_axes(_axes(x, v, residual))
    assert sig.effect_class == "speed"
    assert "viscous-like" in sig.numbers["kind"]
    assert sig.numbers["high_speed_force_N"] > 3.0 * sig.numbers["low_speed_force_N"] > 0.0


def test_white_noise_at_the_floor_has_no_signature():
    """A perfect model leaves white noise at the floor: no class on any of five seeds, and the axes significant at
    p < 1e-3 no more often than chance allows: ten axes on five records expect 0.05 false alarms, so two or more
    (probability about 0.1 %) would say the significance is miscalibrated."""
    alarms = []
    for seed in range(5):
        x, v, noise = _cycle(seed=10 + seed)
        sig = signature_from_axes(_axes(x, v, noise))
        assert sig.effect_class is None
        alarms += [a for a in sig.axes if a.significant]
    assert len(alarms) <= 1, alarms


def test_the_axes_refuse_mismatched_lengths():
    x, v, noise = _cycle(n=100)
    with pytest.raises(UsageError, match="axis speed_m_s has 99 samples"):
        _axes(x, v[:-1], noise)


@pytest.fixture(scope="module")
def bump_record(tmp_path_factory):
    """A record with a friction bump (an out-of-library form) of 5 converter steps, made as the signature
    benchmark makes its records, written and read back, and diagnosed."""
    folder = tmp_path_factory.mktemp("signature")
    design = SignatureDesign()
    case = SignatureCase("bump", "oolib_friction_bump", 5.0, "rest_after_stop", 2411)
    measurement, truth = make_record(PARAMS, case, design)
    path = folder / "bump.csv"
    write_measurement(path, measurement, PARAMS)
    settings = replace(BENCHMARK_SETTINGS, residual_signature=True)  # the benchmarks leave the stage off
    diagnosis = diagnose(load_files([path], PARAMS), PARAMS, settings=settings)
    return folder, path, diagnosis, truth


@pytest.mark.slow
def test_the_suggested_effect_loads_is_the_base_model_at_zero_and_takes_the_error_to_the_floor(bump_record):
    """The bump is unexplained by the library; its signature is dissipative; the suggested effect file loads as
    a user's would, replays exactly the base model with its strengths at 0 and, as it stands, the fitted effect (its
    defaults are the fitted strengths), which fitted with the calibrated parameters brings the weighted error from
    several floors to within 1.3."""
    folder, _, diagnosis, truth = bump_record
    assert diagnosis.verdict == "unexplained"
    cal = diagnosis.calibration
    sig = diagnosis.outputs["signature"]  # the diagnosis's own stage
    assert sig.effect_class == truth["class"] == "dissipative"
    out = folder / "suggested.py"
    suggestion = suggest(diagnosis.problem, cal, sig, out, BENCHMARK_SETTINGS)
    assert suggestion.before_over_floor > 3.0
    assert suggestion.after_over_floor < 1.3
    effect = load_effect_module(str(out))
    f = diagnosis.problem.files[0]
    base = simulate(f.case, overrides=cal.overrides, rack_drive=f.rack, params=PARAMS, t_end_s=4.0)
    zero = simulate(f.case, effects=[*resolve_effects(None), effect], rack_drive=f.rack, params=PARAMS,
                    t_end_s=4.0, overrides={**cal.overrides, **{key: 0.0 for key in suggestion.strengths}})
    assert np.array_equal(base.columns["handwheel_torque_Nm"], zero.columns["handwheel_torque_Nm"])
    fitted = simulate(f.case, effects=[*resolve_effects(None), effect], rack_drive=f.rack, params=PARAMS,
                      t_end_s=4.0, overrides={**cal.overrides, **suggestion.strengths})
    assert not np.array_equal(base.columns["handwheel_torque_Nm"], fitted.columns["handwheel_torque_Nm"])
    as_written = simulate(f.case, effects=[*resolve_effects(None), effect], overrides=cal.overrides,
                          rack_drive=f.rack, params=PARAMS, t_end_s=4.0)
    assert np.array_equal(fitted.columns["handwheel_torque_Nm"], as_written.columns["handwheel_torque_Nm"])
    schema = json.loads(data_file("diagnosis.schema.json").read_text(encoding="utf-8"))
    result = json.loads(json.dumps(with_suggestion(diagnosis_dict(diagnosis), suggestion)))
    jsonschema.validate(result, schema)
    assert "The residual's signature" in markdown_report(result)


@pytest.mark.slow
def test_a_pinched_column_bearing_is_read_at_the_column_and_its_suggestion_takes_the_error_to_the_floor(tmp_path):
    """A column bearing pinched once per turn (an out-of-library truth form with its own breakaway smoothing), on a
    record with an 8-bit rack beside a 12-bit torque (0.012 N m steps, the friction 20 of them RMS) and a hand of
    its own, written and read back: the signature reads the product class dissipative x column angle, and the
    suggested effect, a friction torque at the column, fitted with the calibrated parameters brings the weighted
    error from twice the floor (the 8-bit rack's replay uncertainty weighs much of the record down) to within
    1.3 floors."""
    case = SignatureCase("pinched", "oolib_pinched_bearing", 20.0, "rack_8bit_torque_12bit", 977)
    measurement, truth = make_record(PARAMS, case, SignatureDesign())
    path = tmp_path / "pinched.csv"
    write_measurement(path, measurement, PARAMS)
    settings = replace(BENCHMARK_SETTINGS, residual_signature=True)
    diagnosis = diagnose(load_files([path], PARAMS), PARAMS, settings=settings)
    sig = diagnosis.outputs["signature"]
    assert sig.effect_class == truth["class"] == "dissipative_column", sig.sentence
    suggestion = suggest(diagnosis.problem, diagnosis.calibration, sig, tmp_path / "missing.py", BENCHMARK_SETTINGS)
    assert suggestion.before_over_floor > 1.8
    assert suggestion.after_over_floor < 1.3
    assert "k.column_frame" in (tmp_path / "missing.py").read_text(encoding="utf-8")


@pytest.mark.slow
def test_a_null_gets_no_suggested_effect_file(tmp_path, capsys):
    """A record with nothing hidden is adequate: diagnose --suggest-effect writes no file, says why, and the JSON
    still carries the signature (with no class)."""
    design = SignatureDesign()
    measurement, _ = make_record(PARAMS, SignatureCase("null", None, 0.0, "rate_3pc_200Hz", 2421), design)
    path = tmp_path / "null.csv"
    write_measurement(path, measurement, PARAMS)
    out = tmp_path / "suggested.py"
    assert main(["diagnose", str(path), "--json", "--quiet", "--suggest-effect", str(out)]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["verdict"] == "adequate"
    assert not out.exists()
    assert "suggestion" not in result and result["signature"]["sentence"]


def test_the_benchmark_summary_counts_per_class_and_flags_a_suggestion_on_a_null():
    """On hand-made rows: the per-class counts, the rates against the targets, and a null with a written
    suggestion failing the null target."""
    def row(cls, said, within, form="f", written=False):
        return {"name": f"{form}_{cls}_{said}", "form": form, "class": cls, "said_class": said,
                "class_right": cls == said, "within": within, "verdict": "unexplained", "named": None,
                "suggestion_written": written, "diagnosis_s": 1.0, "signature_s": 0.1, "suggestion_s": 2.0}
    rows = [row("column", "column", True), row("column", "elastic", True), row("speed", "speed", False),
            row(None, None, False, form=None, written=True)]
    summary = summarise(rows)
    assert summary["table"]["column"] == {"records": 2, "class_right": 1, "class_in_group": 1, "within": 2,
                                          "said": ["column", "elastic"],
                                          "verdicts": ["unexplained", "unexplained"]}
    assert summary["class_right_rate"] == pytest.approx(2 / 3)
    assert summary["within_rate"] == pytest.approx(2 / 3)
    assert summary["targets_met"] == {"class": False, "suggestion": False, "nulls": False}
