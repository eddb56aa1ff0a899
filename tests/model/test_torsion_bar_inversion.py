"""The assisted replay's torsion-bar inversion in compiled C (parksteer.model.numeric.torsion_bar, torsion_bar.c):
the bits of the numpy inversion it replaced, the balance it solves, and the library's build once per cache."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import side_by_side

from parksteer.boost_table import entries, table_keys
from parksteer.model.codegen import compiler
from parksteer.model.numeric import torsion_bar
from parksteer.model.numeric.assisted import INVERSION_TOLERANCE_NM, BoostLaw
from parksteer.model.symbolic.effects import assist_common

INVERSION = "the assisted replay's torsion-bar inversion"


class _ReferenceExcess:
    """x + factor A(x) - y at the samples `rows`, as the numpy inversion evaluated it (its _Excess, as it stood
    before the inversion was compiled), the law's pieces taken from assist_common on numbers (the law's one
    definition), in the same order: the line through the dead band (times G_hr at a rack motor), plus the table
    (times its scale unless 1), clamped; a valve's area over G_hr, a motor's gear factor in the direction of the
    power, its reduction, over G_hr at the rack; times the factor unless it is 1."""

    def __init__(self, law: BoostLaw, y: np.ndarray, factor, rotor_speed) -> None:
        self.law, self.y = law, y
        factor = np.asarray(factor, dtype=float)
        self.factor = None if factor.ndim == 0 and float(factor) == 1.0 else np.broadcast_to(factor, y.shape)
        self.points = None
        if any(law.table):
            values = dict(zip(table_keys(), law.table))
            self.points = assist_common.table_points(values.__getitem__, law.speed)
        self.speed = np.array(np.broadcast_to(np.asarray(rotor_speed, dtype=float), y.shape))
        self.line_scale = law.ratio if law.location == "rack" and not law.hydraulic else 1.0
        self.assist_scale = law.ratio if law.location == "rack" else 1.0

    def __call__(self, x: np.ndarray, rows) -> np.ndarray:
        law = self.law
        demand = law.gain * assist_common.deadband(x, law.dead_band, law.band_width)
        if self.line_scale != 1.0:
            demand = demand * self.line_scale
        if self.points is not None:
            table = assist_common.table_law(x, None, law.speed, self.points)
            demand = demand + (table if law.table_scale == 1.0 else law.table_scale * table)
        if law.hydraulic:
            assist = law.area * assist_common.clamp(demand, law.limit, law.limit_width) / law.ratio
        else:
            motor = assist_common.clamp(demand / (law.efficiency * law.reduction), law.limit, law.limit_width)
            delivered = assist_common.directional_efficiency(motor, self.speed[rows], law.efficiency,
                                                             law.back_efficiency, law.direction_width,
                                                             1.0 / law.friction_speed)
            assist = delivered * law.reduction * motor
            if self.assist_scale != 1.0:
                assist = assist / self.assist_scale
        if self.factor is not None:
            assist = self.factor[rows] * assist
        return x + assist - self.y[rows]


def _reference_torsion_bar(law: BoostLaw, y, factor=1.0, rotor_speed=0.0):
    """BoostLaw.torsion_bar as numpy stepped it before it was compiled (the figures' bits were made with it): the
    open samples' brackets packed and stepped together. Returns the root and how many samples took each rare
    branch: the wide bracket, an end that is the root, a step onto the root, a NaN secant point, the step cap."""
    y = np.asarray(y, dtype=float)
    excess = _ReferenceExcess(law, y, factor, rotor_speed)
    taken = dict.fromkeys(("wide", "end_is_root", "exact", "nan_secant", "capped"), 0)
    with np.errstate(all="ignore"):
        low, high = np.minimum(y, 0.0), np.maximum(y, 0.0)
        f_low, f_high = excess(low, slice(None)), excess(high, slice(None))
        wide = np.flatnonzero((f_low > 0.0) | (f_high < 0.0))
        taken["wide"] = wide.size
        if wide.size:
            width = law.bound() * float(np.max(factor)) + 1.0
            low[wide], high[wide] = y[wide] - width, y[wide] + width
            f_low[wide], f_high[wide] = excess(low[wide], wide), excess(high[wide], wide)
        taken["end_is_root"] = int(np.sum((f_low == 0.0) | (f_high == 0.0)))
        low = np.where(f_high == 0.0, high, low)
        high = np.where(f_low == 0.0, low, high)
        rows = np.flatnonzero(high - low > INVERSION_TOLERANCE_NM)
        lo, hi, flo, fhi = low[rows], high[rows], f_low[rows], f_high[rows]
        side = np.zeros(rows.shape, dtype=np.int8)
        for _ in range(200):
            if rows.size == 0:
                break
            x = lo - flo * (hi - lo) / (fhi - flo)
            taken["nan_secant"] += int(np.sum(np.isnan(x)))
            x = np.where((x > lo) & (x < hi), x, 0.5 * (lo + hi))
            fx = excess(x, rows)
            above = fx > 0.0
            flo = np.where(above & (side == 1), 0.5 * flo, flo)
            fhi = np.where(~above & (side == -1), 0.5 * fhi, fhi)
            lo, flo, hi, fhi = (np.where(above, lo, x), np.where(above, flo, fx), np.where(above, x, hi),
                                np.where(above, fx, fhi))
            side = np.where(above, 1, -1).astype(np.int8)
            exact = fx == 0.0
            taken["exact"] += int(exact.sum())
            if exact.any():
                lo[exact] = hi[exact] = x[exact]
            still = hi - lo > INVERSION_TOLERANCE_NM
            if not still.all():
                done = ~still
                low[rows[done]], high[rows[done]] = lo[done], hi[done]
                rows, lo, hi, flo, fhi, side = (a[still] for a in (rows, lo, hi, flo, fhi, side))
        taken["capped"] = rows.size
        low[rows], high[rows] = lo, hi
    return 0.5 * (low + high), taken


def _table(scale: float = 1.0) -> tuple:
    """A two-row boost table (0 and 2 m/s; the second row 0.8 of the first), in table_keys order."""
    torques = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.5, 3.0, 4.0]
    row = [0.0, 0.0, 0.9, 2.73, 5.22, 8.27, 12.78, 18.0, 30.3]
    values = entries(torques, [0.0, 2.0], [[scale * a for a in row], [0.8 * scale * a for a in row]])
    return tuple(float(values.get(k, 0.0)) for k in table_keys())


def _laws() -> dict[str, BoostLaw]:
    """Every kind of law the replay builds: a motor at the column, the pinion and the rack (whose demand is times
    G_hr and assist over it), a valve, each with and without a boost table, tables read below, between and beyond
    their speed rows and scaled (a gain error), a motor in saturation, a sharp (unsmoothed) dead band, a dead band
    widened (its table's points moved out)."""
    table = _table()
    column = BoostLaw("electric_assist_column", "column", 6.0, 0.5, 0.05, 4.0, 0.05, 125.0, 18.0, 0.85, 0.05,
                      back_efficiency=0.6, direction_width=0.05, friction_speed=0.5)
    return {
        "column": column,
        "column_table": dataclasses.replace(column, table=table, speed=1.3, table_scale=0.75),
        "column_saturated": dataclasses.replace(column, limit=0.5, back_efficiency=0.8),
        "column_sharp": dataclasses.replace(column, band_width=0.0, dead_band=0.0),
        "column_wider": dataclasses.replace(column, table=table).with_wider_dead_band(0.3),
        "pinion": BoostLaw("electric_assist_pinion", "pinion", 5.0, 0.4, 0.05, 3.0, 0.02, 125.0, 20.0, 0.8, 0.05,
                           back_efficiency=0.75, direction_width=0.05, friction_speed=1.5),
        "pinion_table": BoostLaw("electric_assist_pinion", "pinion", 0.0, 0.0, 0.05, 3.0, 0.02, 125.0, 20.0, 0.8, 0.05,
                                 table=table, speed=0.7, table_scale=1.1, back_efficiency=0.75, direction_width=0.05,
                                 friction_speed=1.5),
        "rack": BoostLaw("electric_assist_rack", "rack", 5.0, 0.8, 0.01, 5.0, 0.05, 150.0, 2500.0, 0.9, 0.05,
                         back_efficiency=0.85, direction_width=0.05, friction_speed=0.3),
        "rack_table": BoostLaw("electric_assist_rack", "rack", 5.0, 0.8, 0.01, 5.0, 0.05, 150.0, 2500.0, 0.9, 0.05,
                               table=table, speed=-1.0, back_efficiency=0.85, direction_width=0.05,
                               friction_speed=0.3),
        "hydraulic": BoostLaw("hydraulic_assist", "rack", 4e5, 0.3, 0.05, 7e6, 1e5, 150.0, area=8e-4),
        "hydraulic_table": BoostLaw("hydraulic_assist", "rack", 0.0, 0.3, 0.05, 7e6, 1e5, 150.0, area=8e-4,
                                    table=_table(scale=1e5), speed=3.0, table_scale=1.25),
        "hydraulic_both": BoostLaw("hydraulic_assist", "rack", 2e5, 0.3, 0.05, 7e6, 1e5, 150.0, area=8e-4,
                                   table=_table(scale=1e5), speed=1.0),
    }


def _bits_equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def _cases(name: str, law: BoostLaw) -> list[tuple[np.ndarray, object, object]]:
    """The bit comparison's samples of one law, (y, factor, rotor speed): torques across the law and at its edges,
    0 and -0.0, subnormals, 1e-15 N m (where a dead band's smoothing rounds to the wrong sign and the bracket is
    widened), torques beyond 8192 N m (whose bracket cannot close below 1e-12 N m, so the step cap ends it) and
    1e200-1e300 N m (the law overflows to NaN and every comparison is false); motors delivering 1 (no product), a
    half, none, 0-2 times (a factor per sample) and exactly 1 per sample (the product taken) of the law; rotor
    speeds of either sign and none."""
    rng = np.random.default_rng(sum(map(ord, name)))
    edges = [0.0, -0.0, 5e-324, -5e-324, 1e-310, -2.2e-308, 1e-13, -1e-13, 0.5, -0.5, 0.8, -0.8, 4.0, -4.0, 1e4,
             -1e4, 3e5, -1e6, 1e12, -1e15, 1e200, -1e300]
    y = np.concatenate([rng.uniform(-40.0, 40.0, 400), law.dead_band + rng.uniform(-0.2, 0.2, 100),
                        -law.dead_band + rng.uniform(-0.2, 0.2, 100), rng.uniform(-1.0, 1.0, 100),
                        rng.uniform(-1e-15, 1e-15, 100), edges])
    speeds = rng.choice([-3.0, -0.02, -1e-4, -0.0, 0.0, 1e-4, 0.02, 3.0], size=y.size)
    factors = rng.choice([0.0, 0.5, 1.0, 2.0], size=y.size)
    return [(y, factor, speed) for factor, speed in ((1.0, 0.0), (0.5, speeds), (factors, 0.7),
                                                     (np.ones(y.size), speeds), (0.0, speeds))]


@pytest.mark.parametrize("name", list(_laws()))
def test_the_compiled_inversion_gives_the_numpy_inversions_bits(name):
    """Bit for bit, the compiled inversion returns what the numpy inversion it replaced returned (a copy of it
    above, the law from assist_common), for every kind of law (:func:`_laws`) at every sample of :func:`_cases`;
    a 2-d array of samples is solved sample by sample, its shape kept; no samples give no torques."""
    law = _laws()[name]
    cases = _cases(name, law)
    for y, factor, speed in cases:
        assert _bits_equal(law.torsion_bar(y, factor, speed), _reference_torsion_bar(law, y, factor, speed)[0])
    y, _, speeds = cases[1]
    assert _bits_equal(law.torsion_bar(y[:600].reshape(20, 30), 1.0, speeds[:600].reshape(20, 30)),
                       _reference_torsion_bar(law, y[:600], 1.0, speeds[:600])[0].reshape(20, 30))
    assert law.torsion_bar(np.empty(0), 1.0, 0.0).shape == (0,)


def test_the_bit_comparison_takes_every_rare_branch():
    """The bit comparison's samples (:func:`_cases`) take every rare branch of the inversion somewhere (counted on
    the reference): the wide fallback bracket, an end of the first bracket that is the root, a step onto the
    root, a NaN secant point (the law's values NaN, or 0/0: the midpoint taken), and the 200-step cap. A NaN
    torque gives NaN, as numpy's did."""
    taken = dict.fromkeys(("wide", "end_is_root", "exact", "nan_secant", "capped"), 0)
    for name, law in _laws().items():
        for y, factor, speed in _cases(name, law):
            counts = _reference_torsion_bar(law, y, factor, speed)[1]
            taken = {key: taken[key] + counts[key] for key in taken}
    assert all(count > 0 for count in taken.values()), taken
    law = _laws()["column"]
    y = np.array([np.nan, 1.0, -np.nan])
    assert np.array_equal(np.isnan(law.torsion_bar(y, 1.0, 0.0)), np.isnan(_reference_torsion_bar(law, y)[0]))


@pytest.mark.parametrize("name", list(_laws()))
def test_the_torsion_bar_torque_and_the_assist_balance_the_column_torque(name):
    """The physics the inversion solves: the torsion bar carries what the assist does not, T + f A(T) = y (the
    column torque at the bar), at every sample, to within what the 1e-12 N m bracket leaves: the root is within
    half of it of the midpoint returned, so the balance is off by at most the law's local slope d(T + f A)/dT
    times that, plus the rounding of evaluating the balance itself (a few units in the last place of y and f A);
    and the balance changes sign across T -+ 1e-12 N m. The law evaluated by assist_common, not by the C."""
    law = _laws()[name]
    rng = np.random.default_rng(17)
    y = np.concatenate([rng.uniform(-40.0, 40.0, 500), law.dead_band + rng.uniform(-0.1, 0.1, 100), [0.0, 3.0]])
    speed = rng.choice([-0.02, -1e-4, 0.0, 1e-4, 0.02], size=y.size)
    factor = rng.choice([0.0, 0.5, 1.0, 2.0], size=y.size)
    t = law.torsion_bar(y, factor, speed)
    balance = _ReferenceExcess(law, y, factor, speed)
    rows = np.arange(y.size)
    residual = balance(t, rows)
    h = 1e-6
    slope = (balance(t + h, rows) - balance(t - h, rows)) / (2 * h)
    assist = balance(t, rows) - t + y  # f A(T)
    rounding = 8 * np.finfo(float).eps * (np.abs(y) + np.abs(t) + np.abs(assist))
    assert np.all(slope >= 0.99)  # the balance rises with T: one root
    assert np.all(np.abs(residual) <= slope * INVERSION_TOLERANCE_NM + rounding)  # twice the half: margin
    assert np.all(balance(t - INVERSION_TOLERANCE_NM, rows) <= rounding)
    assert np.all(balance(t + INVERSION_TOLERANCE_NM, rows) >= -rounding)
    assert np.max(np.abs(t - y)) > 1.0  # the assist carries a real share


def test_the_c_asks_for_the_wide_bracket_only_where_a_sample_needs_it():
    """The fallback bracket's width is the law's bound, which some laws cannot give (1 / 0: the numpy inversion
    raised its ZeroDivisionError only where a sample needed that bracket): the C, given no width, inverts samples
    that do not need it and stops (no torque) at one that does; given the width, it gives the reference's bits."""
    law = _laws()["hydraulic"]
    values, y = law._inversion_values, np.array([3.0, -0.5])
    assert _bits_equal(torsion_bar.invert(values, True, None, y, None, None, None, INVERSION_TOLERANCE_NM, 200),
                       _reference_torsion_bar(law, y)[0])
    tiny = np.array([3.0, 9.91873753e-17])  # the valve's smoothed dead band rounds to the wrong sign: widened
    assert _reference_torsion_bar(law, tiny)[1]["wide"] == 1
    assert torsion_bar.invert(values, True, None, tiny, None, None, None, INVERSION_TOLERANCE_NM, 200) is None
    width = law.bound() + 1.0
    assert _bits_equal(torsion_bar.invert(values, True, None, tiny, None, None, width, INVERSION_TOLERANCE_NM, 200),
                       _reference_torsion_bar(law, tiny)[0])


def test_a_table_whose_torques_do_not_rise_is_refused():
    """The C finds a sample's table segment by bisection, which is numpy's search only in rising torques (a table's
    file has them rising): a table whose torques past the first fall is refused in one line, not inverted."""
    from parksteer.errors import UsageError

    table = list(_table())
    table[3], table[4] = table[4], table[3]  # boost_torque_3 and _4 swapped
    law = dataclasses.replace(_laws()["column"], table=tuple(table))
    with pytest.raises(UsageError, match="torques do not rise"):
        law.torsion_bar(np.array([1.0, 2.0]))


def test_the_inversion_is_built_once_per_cache_and_a_damaged_one_again(tmp_path, capfd):
    """The library is compiled once into the cache's runtime folder, named by its source, flags and compiler, with
    its bytes' digest beside it; a second look finds it; bytes that are not the recorded ones (a damaged or
    truncated file) are compiled again; another source is another library; no scratch folder is left behind."""
    compiled = compiler.find_compiler()
    source = torsion_bar.SOURCE.read_text(encoding="utf-8")
    path = compiler.standalone_library(compiled, "torsion_bar", source, INVERSION, tmp_path)
    assert path.parent == tmp_path / compiler.RUNTIME_FOLDER
    assert path.name == f"torsion_bar-{compiler.library_key(compiled, source)}.so"
    assert path.with_suffix(".sha256").is_file()
    assert compiler.standalone_library(compiled, "torsion_bar", source, INVERSION, tmp_path) == path
    assert capfd.readouterr().err.count(f"compiling {INVERSION}") == 1
    good = path.read_bytes()
    path.write_bytes(good[: len(good) // 2])
    assert compiler.standalone_library(compiled, "torsion_bar", source, INVERSION, tmp_path) == path
    assert path.read_bytes()[:4] == b"\x7fELF" and capfd.readouterr().err.count(f"compiling {INVERSION}") == 1
    other = compiler.standalone_library(compiled, "torsion_bar", source + "\n/* another */\n", INVERSION, tmp_path)
    assert other != path and other.is_file()
    assert [p.name for p in tmp_path.iterdir()] == [compiler.RUNTIME_FOLDER]


def _build(root: str) -> None:
    compiled = compiler.find_compiler()
    compiler.standalone_library(compiled, "torsion_bar", torsion_bar.SOURCE.read_text(encoding="utf-8"), INVERSION,
                                Path(root))


@pytest.mark.skipif(not side_by_side.FORKS, reason="forks its builders")
def test_builders_side_by_side_compile_the_inversion_once(tmp_path, capfd):
    """Three processes that need the library at once on an empty cache (a first diagnosis's workers): one
    compiles it under its lock, the others wait and find it built."""
    assert side_by_side.exit_codes(_build, str(tmp_path)) == [0, 0, 0]
    assert capfd.readouterr().err.count(f"compiling {INVERSION}") == 1
    assert len(list((tmp_path / compiler.RUNTIME_FOLDER).glob("*.so"))) == 1


def test_the_inversion_is_compiled_on_the_first_replay_not_at_import(tmp_path):
    """Importing the replay compiles and loads nothing (an empty cache stays empty); the first inversion builds
    the library into the cache the process is given."""
    cache = tmp_path / "cache"
    code = ("import numpy as np\n"
            "from parksteer.model.numeric import assisted, torsion_bar\n"
            "import pathlib, sys\n"
            "print(pathlib.Path(sys.argv[1]).exists(), torsion_bar.entry_point.cache_info().currsize)\n"
            "law = assisted.BoostLaw('hydraulic_assist', 'rack', 4e5, 0.3, 0.05, 7e6, 1e5, 150.0, area=8e-4)\n"
            "law.torsion_bar(np.array([1.0, -2.0]))\n"
            "print(sorted(p.suffix for p in (pathlib.Path(sys.argv[1]) / 'runtime').iterdir()))\n")
    env = {**os.environ, "PARKSTEER_MODEL_CACHE": str(cache)}
    out = subprocess.run([sys.executable, "-c", code, str(cache)], capture_output=True, text=True, check=True, env=env)
    assert out.stdout.splitlines() == ["False 0", "['.lock', '.sha256', '.so']"]
