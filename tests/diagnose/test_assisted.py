"""The diagnosis of an assisted car: its torsion-bar torque replayed through the boost law, its motor current fitted
as a second signal, and the candidates of an assisted car.

The records are the Polo file's car with its column assist (data/vehicles/polo_vi.toml), a hand of the variation
benchmark, and a logger of the car's bus: a 10-bit torsion-bar torque on +-10 N m (0.02 N m steps), a 12-bit current
on +-100 A (0.05 A steps), a 12-bit rack. The truth is the assisted replay (parksteer.model.numeric.assisted), checked
against the handwheel-driven simulation in tests/model/test_assisted_replay.py. What each test checks is the
physics the diagnosis must recover.
"""

from __future__ import annotations

import json
from dataclasses import replace

import jsonschema
import numpy as np
import pytest

from pages_check import assert_same_sections

from parksteer.cli import main
from parksteer.experiments.benchmark import BENCHMARK_SETTINGS
from parksteer.diagnose.problem import prepare_file
from parksteer.reporting.report import SCHEMA_PATH, diagnosis_dict
from parksteer.diagnose.select import diagnose
from parksteer.measure.io import write_measurement
from parksteer.model.symbolic.components import discover_effects, resolve_effects
from parksteer.synthetic.assisted import AssistedLogger, assisted_clean, assisted_record
from parksteer.synthetic.variations import HandVariant

discover_effects()  # the assists' quantities, which the vehicle file's [assist] sets
POLO = "data/vehicles/polo_vi.toml"
ASSIST = "+electric_assist_column"
# Base parameters moved off the file's values, as a real car's would be: a diagnosis must calibrate them.
OFF_NOMINAL = {"tyre.friction_coefficient": 0.70, "steering.rack_friction_force": 650.0,
               "tyre.carcass_torsional_stiffness": 800.0}


@pytest.fixture(scope="module")
def polo():
    from parksteer.vehicle import load_vehicle

    return load_vehicle(POLO)


def record(params, hidden: str | None = None, strength: float = 0.0, current: bool = True, seed: int = 3,
           base: dict | None = None):
    overrides = dict(OFF_NOMINAL if base is None else base)
    effects = ASSIST
    if hidden is not None:
        key = next(q.key for q in discover_effects()[hidden].quantities)
        overrides[key], effects = strength, f"{ASSIST},+{hidden}"
    clean = assisted_clean(params, HandVariant(0.05, 0.2, seed=seed), effects, "kerb", overrides=overrides)
    return assisted_record(clean, AssistedLogger(seed=seed, log_current=current), "kerb")


def diagnosed(params, measurement):
    """The JSON of a user's diagnosis of `measurement` without the confound tests and the signature (the assist's
    assumed values replayed at their bands' ends, as a user's diagnosis does)."""
    settings = replace(BENCHMARK_SETTINGS, assumed_values_replayed=True)
    result = diagnose([prepare_file(measurement, "kerb", label="polo")], params, resolve_effects(ASSIST),
                      settings=settings)
    return diagnosis_dict(result)


@pytest.fixture(scope="module")
def motor_friction(polo):
    """The diagnosis (object and JSON) of a record whose motor drags 0.02 N m more than the file says."""
    result = diagnose([prepare_file(record(polo, "assist_motor_friction", 0.02), "kerb", label="polo")], polo,
                      resolve_effects(ASSIST), settings=BENCHMARK_SETTINGS)
    return result, diagnosis_dict(result)


def test_a_tie_is_the_headline_and_no_test_is_offered_below_the_noise_floor(motor_friction, tmp_path):
    """Motor friction and column friction are one load at a column assist: the reports' headline says the data
    cannot tell them apart, naming both with their strengths, units and intervals; a load case or surface the
    data lack would move the two fitted models apart by far less than the noise floor, so no such measurement is
    offered as separating them; the motor current is shown beside the torque, as a table and as the figure's
    measured, fitted and residual panels."""
    from parksteer.reporting.pages import html_report, markdown_report
    from parksteer.figures.diagnose import diagnosis_figure

    diagnosis, result = motor_friction
    group = [result["effect"], *(s["effect"] for s in result["indistinguishable"])]
    assert sorted(group) == ["assist_motor_friction", "column_friction"]
    assert all(s["separating_measurement"]["over_noise_floor"] < 1.0 for s in result["indistinguishable"])
    text = markdown_report(result)
    headline = text.split("\n")[2]
    assert "these data cannot tell them apart" in headline.split("**")[1]
    assert "`assist_motor_friction`" in headline and "`column_friction`" in headline
    assert "No test of this kind separates" in headline and "measure the" not in text
    assert result["units"]["column_friction.friction_torque"] == "N m"
    assert " N m (95 %: " in headline and " to " in headline
    assert "| steering.rack_friction_force | N |" in text
    assert "## Motor channel" in text and "residual RMS (A)" in text
    page = html_report(result, [], [])
    assert "these data cannot tell them apart" in page.split('class="verdict">')[1].split("</p>")[0]
    assert "<h2>Motor channel</h2>" in page
    svg = tmp_path / "diagnosis.svg"
    diagnosis_figure(diagnosis, svg)
    assert "motor channel residual" in svg.read_text(encoding="utf-8")


def test_both_pages_show_the_same_sections_and_the_figure_the_table_s_numbers(motor_friction, monkeypatch, tmp_path):
    """The markdown report and the HTML page render one structure: each section of one is in the other, in order,
    the confounded candidates among them; neither advises the handwheel angle (--angle), which the diagnosis of an
    assisted car refuses. The figure's bar for each candidate is the weighted RMS the ranking table gives, to the
    last digit (the figure and the table read one number)."""
    import matplotlib.axes

    from parksteer.figures.diagnose import diagnosis_figure

    diagnosis, result = motor_friction
    text, page = assert_same_sections(result, phases=[])
    assert result["confounded"] and "<h2>Confounded with the calibrated parameters</h2>" in page
    assert "--angle" not in text and "--angle" not in page
    rows = {r["parameter"]: r for r in result["identification"]}
    assert rows["steering.column_torsional_stiffness"]["status"] == "not calibrated"
    assert rows["steering.column_torsional_stiffness"]["fixed_by"] is None
    drawn = []
    original = matplotlib.axes.Axes.barh
    monkeypatch.setattr(matplotlib.axes.Axes, "barh",
                        lambda self, y, width, *a, **k: drawn.append(list(width)) or original(self, y, width, *a, **k))
    diagnosis_figure(diagnosis, tmp_path / "diagnosis.svg")
    assert drawn == [[c["weighted_rms_after_Nm"] for c in result["ranking"]]]


def test_hidden_motor_friction_is_named_from_the_torsion_bar_torque_and_current(polo, motor_friction):
    """A motor dragging 0.02 N m more than the file says (N = 18: 0.36 N m at the column, 0.05 N m of torsion-bar
    torque after the boost's division by about 1 + G = 7) is named. At a column assist it is the same load as a
    column friction of N T_e (both act on the column above the intermediate shaft), so the two are reported
    indistinguishable; it is told from the calibrated rack friction by its lever, constant at the column where the
    rack friction's varies with the Hooke joint's speed ratio (cos 0.45 to 1 / cos 0.45). The current, which the
    boost curve makes about 8 A per N m of torsion-bar torque, reads the torsion bar more finely than its own 10-bit
    channel: without it the same record is still named, with a BIC gain less than half as large."""
    with_current = motor_friction[1]
    assert with_current["verdict"] == "missing"
    group = {with_current["effect"], *(s["effect"] for s in with_current["indistinguishable"])}
    assert "assist_motor_friction" in group and group <= {"assist_motor_friction", "column_friction"}
    assert "motor" in with_current["statistics"]["calibrated"]  # the current was fitted beside the torque
    jsonschema.validate(with_current, json.loads(SCHEMA_PATH.read_text(encoding="utf-8")))
    torque_only = diagnosed(polo, record(polo, "assist_motor_friction", 0.02, current=False))
    assert torque_only["verdict"] == "missing"
    gain = lambda r: max(c["delta_bic"] or 0.0 for c in r["ranking"])  # noqa: E731
    assert gain(with_current) > 2.0 * gain(torque_only) > 0.0


def test_boost_gain_error_is_named_and_sized_by_the_current(polo):
    """A control unit whose gain is 20 % above the file's: in the linear range the current per torsion-bar torque
    rises by 20 % while the torque falls only by 1 - 7 / 8.2 (15 %); the diagnosis names it and the refitted size is
    within 0.03 of 0.20."""
    result = diagnosed(polo, record(polo, "boost_gain_error", 0.2))
    assert result["verdict"] == "missing" and result["effect"] == "boost_gain_error"
    entry = next(c for c in result["ranking"] if c["effect"] == "boost_gain_error")
    assert abs(entry["parameters"]["boost_gain_error.strength"]["value"] - 0.2) < 0.03


def test_a_record_of_the_assisted_car_with_nothing_hidden_is_adequate(polo):
    """A null: the calibrated model leaves the torque and the current at their noise floors (within 10 %).

    Its assumed values are each replayed at their band's ends (stage ``assumed``): every [assist] entry the Polo's
    file marks assumed is there, the boost line's are not (the file's table gives the curve); the torsion bar's
    stiffness moves the fit by less than 0.1 % (the column is massless: with the rack given, its compliance barely
    reaches the torque); a torque constant of 0.03 or 0.07 N m/A instead of the assumed 0.05 scales the current the
    replay predicts by 5/3 or 5/7, tens of the current's noise floors, and decides the verdict: each of its ends says
    it is not adequate because the calibrated model is above the adequate threshold of 1.15 floors."""
    result = diagnosed(polo, record(polo))
    assert result["verdict"] == "adequate"
    stats = result["statistics"]["calibrated"]
    assert stats["weighted_rms_Nm"] < 1.1 * stats["noise_floor_Nm"]
    assert stats["motor"]["weighted_rms"] < 1.1 * stats["motor"]["noise_floor"]
    jsonschema.validate(result, json.loads(SCHEMA_PATH.read_text(encoding="utf-8")))
    rows = {r["quantity"].split(".")[1]: r for r in result["assumed"]["quantities"]}
    assert {"motor_friction_torque", "motor_inertia", "efficiency", "torque_constant"} <= set(rows)
    assert not {"gain", "dead_band", "dead_band_smoothing"} & set(rows)
    nominal = result["assumed"]["nominal"]["calibrated_over_floor"]
    assert all(e["calibrated_over_floor"] == pytest.approx(nominal, rel=1e-3)
               for e in rows["torsion_bar_stiffness"]["ends"])
    assert rows["torque_constant"]["decides"] and not rows["torsion_bar_stiffness"]["decides"]
    assert min(e["calibrated_over_floor"] for e in rows["torque_constant"]["ends"]) > 5.0
    assert all(e["verdict"] == "unexplained" and "above the 1.15 of adequate" in e["why"]
               for e in rows["torque_constant"]["ends"])
    # the assumed values' section is on both pages (one structure renders both)
    text, page = assert_same_sections(result)
    assert "<h2>What the verdict owes to the assist&#x27;s assumed values</h2>" in page


def test_moving_a_factor_of_an_identified_product_holds_the_product(polo):
    """Where `assist identify` fixed the product k_t eta N (the torque constant's entry declares it identified), the
    assumed-values stage moves the efficiency with the torque constant taking up the product, and the reduction with
    the product, the reflected inertia N^2 J and the reflected friction N T_f held; a file's own torque constant
    moves alone."""
    from dataclasses import replace as copy

    from parksteer.diagnose.stages.assumed import moved

    name = "electric_assist_column"
    assert moved(polo, name, "efficiency", 0.75) == {f"{name}.efficiency": 0.75}
    sources = {**polo.sources, **{f"{name}.{k}.provenance": "identified"
                                  for k in ("torque_constant", "motor_inertia", "motor_friction_torque")}}
    identified = copy(polo, sources=sources)
    v = lambda k: polo[f"{name}.{k}"]  # noqa: E731
    out = moved(identified, name, "efficiency", 0.75)
    assert out[f"{name}.torque_constant"] * 0.75 == pytest.approx(v("torque_constant") * v("efficiency"))
    out = moved(identified, name, "reduction_ratio", 22.0)
    assert out[f"{name}.torque_constant"] * 22.0 == pytest.approx(v("torque_constant") * v("reduction_ratio"))
    assert out[f"{name}.motor_inertia"] * 22.0 ** 2 == pytest.approx(v("motor_inertia") * v("reduction_ratio") ** 2)
    assert out[f"{name}.motor_friction_torque"] * 22.0 == pytest.approx(v("motor_friction_torque")
                                                                         * v("reduction_ratio"))


def test_compare_an_assisted_record_from_the_command_line(polo, tmp_path, capsys):
    """`parksteer compare --vehicle FILE --with-assist`: the torque compared is the torsion bar's and the current
    has its own residual beside its own floor (a record of the file's own car: each weighted RMS, which counts a
    sample by its attainable error, at its floor within 10 %); the same
    record without the assist is refused in one line (its torque is not a handwheel's)."""
    path = tmp_path / "polo_null.csv"
    write_measurement(path, record(polo, base={}), polo)
    assert main(["compare", str(path), "--vehicle", POLO, "--with-assist", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    torque, motor = out["files"][0], out["files"][0]["motor"]
    assert torque["over_floor"] < 1.1
    assert motor["column"] == "motor_current_A" and motor["weighted_rms"] < 1.1 * motor["noise_floor"]["total_rms"]
    assert main(["compare", str(path), "--vehicle", POLO]) == 2
    assert "torsion-bar torque; replay it with the car's assist" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["electric_assist_column", "electric_assist_pinion"])
def test_an_angle_only_record_gives_the_rack_through_the_torsion_bar(params, name):
    """The inverse of the free run's own column: a handwheel-driven assisted run's handwheel angle and torsion-bar
    torque give back its rack through the column shaft and the torsion bar in series (damper included) within
    1 um over a 0.07 m stroke (2e-7 m found, column and pinion assist); taken through the shaft alone (the car
    without its assist's bar, k_c = 1000 N m/rad against the series 103 N m/rad) the rack is off by 1.5e-4 m, the
    bar's twist T / k_t through the ratio."""
    from parksteer.diagnose.problem import torsion_bar
    from parksteer.measure.column import rack_from_angle
    from parksteer.measure.io import Measurement
    from parksteer.model.numeric.simulate import simulate
    from parksteer.model.symbolic.components import with_effect_quantities

    params = with_effect_quantities(params)  # the assist's torsion bar at its declared stiffness
    run = simulate("unladen", effects=f"+{name}", params=params, output_dt_s=0.005, rtol=1e-8).columns
    measurement = Measurement(None, {"time_s": run["time_s"], "handwheel_angle_rad": run["handwheel_angle_rad"],
                                     "handwheel_torque_Nm": run["torsion_bar_torque_Nm"]},
                              {"case": "unladen", "surface": "ground", "torque_sensor": "torsion_bar"})
    through_bar = rack_from_angle(measurement, params, torsion_bar(name)).rack_m
    through_shaft = rack_from_angle(measurement, params).rack_m
    error, naive = (float(np.max(np.abs(r - run["rack_m"]))) for r in (through_bar, through_shaft))
    assert error < 1e-6 and naive > 100 * error


def test_the_assisted_benchmark_rows_come_back_in_the_design_order(tmp_path):
    """Bookkeeping, not physics: the rows the benchmark's jobs write (one file per case, in any job's folder) are
    read back in the order of the design's cases, whatever job ran each, so that the summary and the figure do not
    depend on how the cases were dealt; a case without a row, or with a row in two folders, is refused in one line
    naming it."""
    from parksteer.experiments.assisted_benchmark import ROW_SUFFIX, case_names, read_rows
    from parksteer.errors import UsageError

    names = case_names()
    assert len(names) == len(set(names)) == 62  # 20 nulls, 4 candidates x 2 sizes x 4 hands, 10 out of class
    folders = [tmp_path / "a", tmp_path / "b"]
    for folder in folders:
        folder.mkdir()
    for i, name in enumerate(reversed(names)):
        (folders[i % 2] / f"{name}{ROW_SUFFIX}").write_text(json.dumps({"name": name, "value": 0.1 * i}))
    assert [row["name"] for row in read_rows(folders, names)] == names
    for folder in folders:
        (folder / f"{names[0]}{ROW_SUFFIX}").unlink(missing_ok=True)
    with pytest.raises(UsageError, match=f"no rows of case {names[0]}"):
        read_rows(folders, names)
    for folder in folders:  # names[1] in both folders
        (folder / f"{names[1]}{ROW_SUFFIX}").write_text("{}")
    (folders[0] / f"{names[0]}{ROW_SUFFIX}").write_text("{}")
    with pytest.raises(UsageError, match=f"case {names[1]} has rows"):
        read_rows(folders, names)
