"""An assisted car's bus record, angle only: where the rack is slow, the replay uncertainty covers what the rack
derived from a rounded handwheel angle cannot show.

The records are the independent assisted truth's nulls (:mod:`parksteer.experiments.assisted_truth`, angle tier):
a 14-bit angle on +-16 rad (1.95e-3 rad a step, 15.6 um of rack on the Polo's 125.5 rad/m) whose noise, 2e-4 rad,
is a tenth of a step, so the rounding is not dithered: through a reversal or at the edge of a pause the rack stays
within one level for tens of milliseconds, and the smoothed rack's speed there follows its knots. Relogging that
spline to the same levels gives every draw of the replay ensemble the same rack; the draws within the rounding
(:func:`parksteer.measure.smoothing.rounding_draw`) are what spread them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from parksteer.diagnose.engine import ReplayEngine
from parksteer.diagnose.ensemble import with_replay_uncertainty
from parksteer.diagnose.problem import Problem, load_files
from parksteer.diagnose.replay import Replay
from parksteer.experiments.assisted_truth import case_truth_and_record
from parksteer.experiments.assisted_truth_owner import owner_file
from parksteer.experiments.assisted_truth_design import TruthDesign, cases
from parksteer.measure.io import format_measurement
from parksteer.measure.smoothing import rounding_draw, smooth_rack
from parksteer.measure.rack_spline import RackSpline, interpolate_rack
from parksteer.synthetic.variations import variation_by_name, variation_rack
from parksteer.vehicle import load_vehicle

# three hands: pauses (edges of a pause), uneven strokes (reversals at differing rates), a 200 Hz logger the import
# decimates to 100 Hz (its rounding kept through the filter)
HANDS = ("pauses", "uneven_strokes", "rate_3pc_200Hz")
SLOW_MPS = 2e-3  # where the rack friction and the motor's friction and direction turn over


def _errors(params_path, tmp_path, hand_name: str) -> dict[str, tuple[float, float]]:
    """{with, without the rounding draws: (RMS of the chosen rack's replay error in attainable errors at the slow
    samples, the attainable error's RMS over the noise floor where the rack moves faster than 10 mm/s)}."""
    params = load_vehicle(params_path)
    design = TruthDesign(tiers=("angle",), null_variations=(hand_name,), hidden_variations=(),
                         out_of_class_variations=())
    case = cases(design)[0]
    _, record = case_truth_and_record(params, design, case)
    owner = owner_file(params_path, design, tmp_path)
    path = tmp_path / f"{hand_name}.csv"
    path.write_text(format_measurement(record), encoding="utf-8")
    (f,) = load_files([path], owner.params, assist=owner.assist)
    hand, _ = variation_by_name(case.variation).settings(case.seed)
    driven = variation_rack(owner.params, hand)  # the rack the hand drove
    out = {}
    for label, file in (("with", f), ("without", replace(f, rack=replace(f.rack, rest_resolution_m=0.0)))):
        engine = ReplayEngine()
        problem = with_replay_uncertainty(engine, Problem([file], owner.params), owner.effects, {})
        g = problem.files[0]
        t = g.time_s
        chosen = engine.signals(problem, owner.effects, 0)[: g.n]
        true = Replay(owner.effects, g.case, g.surface, owner.params, driven, t).torque({})
        speed = np.abs(driven.evaluate(t)[1])
        slow = (speed < SLOW_MPS) & (t > t[0] + 0.5) & (t < t[-1] - 0.5)
        fast = speed > 10e-3
        weighted = (chosen - true) / g.sigma_Nm
        out[label] = (float(np.sqrt(np.mean(weighted[slow] ** 2))),
                      float(np.sqrt(np.mean(g.sigma_Nm[fast] ** 2)) / g.noise.total_rms))
    return out


@pytest.fixture(scope="module")
def errors(repo_root, tmp_path_factory):
    return {h: _errors(repo_root / "data" / "vehicles" / "polo_vi.toml", tmp_path_factory.mktemp(h), h)
            for h in HANDS}


def test_the_replay_uncertainty_covers_an_angle_derived_racks_error_where_it_is_slow(errors):
    """The model replayed on the rack derived from the angle against the same model replayed on the rack the hand
    drove (so only the rack differs), at the samples where the rack is slower than 2 mm/s: the error is within each
    sample's attainable error, RMS (0.62, 0.89, 0.25 measured). Relogging alone leaves it at 1.1 to 2.3 attainable
    errors RMS: the test fails without the draws within the rounding. Where the rack moves faster than 10 mm/s the
    attainable error stays the noise floor (the draws do not blunt the strokes)."""
    for hand, found in errors.items():
        assert found["with"][0] < 1.0, hand
        assert found["with"][1] < 1.01, hand
    assert max(found["without"][0] for found in errors.values()) > 1.5


def test_a_rounding_draw_moves_the_rack_by_the_rounding_where_it_is_slow_and_not_where_it_moves():
    """A rack at rest, then moving at 50 mm/s (128 levels of 15.6 um over a knot interval of 4 samples at 100 Hz):
    over many draws the added motion's RMS is the rounding's, step / sqrt(12), times the cubic B-spline basis's own
    spread at rest, and 1 / sqrt(128) of that where the rack moves; over a stretch the draw holds at rest nothing is
    added beyond the four knot intervals at its ends."""
    t = np.arange(0.0, 4.0, 0.01)
    x = np.where(t < 2.0, 0.0, 0.05 * (t - 2.0))
    rack = interpolate_rack(t, x)
    step = 15.6e-6
    rng = np.random.default_rng(7)
    added = np.array([rounding_draw(rack, t, step, rng).evaluate(t)[0] - rack.evaluate(t)[0] for _ in range(400)])
    rest = (t > 0.3) & (t < 1.7)
    moving = (t > 2.3) & (t < 3.7)
    ratio = np.sqrt(np.mean(added[:, moving] ** 2)) / np.sqrt(np.mean(added[:, rest] ** 2))
    assert ratio == pytest.approx(1 / np.sqrt(0.05 * 0.04 / step), rel=0.15)
    # uniform cubic B-splines' sum of squares at a point is 0.46 (mid-interval) to 0.5 (at a knot): RMS 0.68-0.71 sigma
    assert 0.64 < np.sqrt(np.mean(added[:, rest] ** 2)) / (step / np.sqrt(12.0)) < 0.75
    held = rounding_draw(rack, t, step, rng, held=((0.5, 1.5),))
    inside = (t > 0.66) & (t < 1.34)  # four knot intervals (0.16 s) in from the stretch's ends
    assert np.max(np.abs(held.evaluate(t[inside])[0] - rack.evaluate(t[inside])[0])) < 1e-15


def test_a_sum_of_rack_motions_is_the_sum_at_every_instant():
    """RackSpline.plus: position, speed and acceleration of the sum are the sums, on the union of the breaks."""
    t = np.linspace(0.0, 3.0, 121)
    a = smooth_rack(t, 0.02 * np.sin(2.0 * t))
    b = interpolate_rack(np.linspace(0.0, 3.0, 17), 1e-4 * np.cos(5.0 * np.linspace(0.0, 3.0, 17)))
    total = a.plus(b)
    assert isinstance(total, RackSpline)
    probe = np.linspace(0.0, 3.0, 997)
    for got, x, y in zip(total.evaluate(probe), a.evaluate(probe), b.evaluate(probe)):
        np.testing.assert_allclose(got, x + y, rtol=0, atol=1e-12 * max(1.0, float(np.max(np.abs(x + y)))))
