"""Smoothing a logged rack (parksteer.measure.smoothing) and replaying it through the model (Replay)."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.diagnose.engine import ReplayEngine, effect_key
from parksteer.diagnose.ensemble import DrawnInAdvance, relogged_rack
from parksteer.diagnose.replay import Replay
from parksteer.measure.smoothing import rounding_draw, rounding_draw_size, smooth_rack
from parksteer.model.codegen.cache import entry_path as compiled_entry_path
from parksteer.model.numeric.prescribed import solve
from parksteer.model.numeric.simulate import prepare
from parksteer.model.symbolic.components import discover_effects, resolve_effects
from parksteer.measure.converter import add_noise, quantise, quantisation_step

FULL_SCALE_M = 0.1


def _logged_rack(seed: int, start_at_rest: bool):
    """A lock-to-lock rack motion, 8-bit logged at 50 Hz: (time, logged rack, true rack).

    The speed is a trapezoid per stroke (straight ahead to +67 mm in 4.5 s, to -67 mm in 9 s, back in 4.5 s),
    ramping linearly over 0.2 s at the start, through each reversal and at the end: the hand's motion.
    """
    t = np.arange(0.0, 18.0 + 1e-9, 0.02)
    fine = np.linspace(0.0, 18.0, 18001)
    ramp = 0.2
    corners = [0.0, 4.5, 13.5, 18.0]
    travel = [0.067, -0.134, 0.067]
    speed = np.zeros_like(fine)
    for (a, b), dx in zip(zip(corners[:-1], corners[1:]), travel):
        cruise = dx / (b - a - ramp)  # area of a trapezoid with ramps of `ramp` at both ends
        shape = np.clip(np.minimum(fine - a, b - fine) / ramp, 0.0, 1.0)
        speed += np.where((fine >= a) & (fine <= b), cruise * shape, 0.0)
    x_fine = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(fine))])
    x = np.interp(t, fine, x_fine)
    logged = quantise(add_noise(x, 0.0002, np.random.default_rng(seed)), FULL_SCALE_M)
    if not start_at_rest:
        keep = t >= 1.0
        return t[keep], logged[keep], x[keep]
    return t, logged, x


def test_spline_follows_the_motion_not_the_converter_steps():
    """The smoothed rack stays within a fraction of a converter step of the true motion, and its fit residual
    is the rack's noise (quantisation step / sqrt(12) with the analog noise), not less (it does not chase steps)."""
    t, logged, true = _logged_rack(1, True)
    rack = smooth_rack(t, logged)
    position, speed, _ = rack.evaluate(t)
    step = quantisation_step(FULL_SCALE_M)
    noise = np.hypot(step / np.sqrt(12.0), 0.0002)
    assert np.sqrt(np.mean((position - true) ** 2)) < 0.25 * step
    assert 0.8 * noise < rack.fit_rms_m <= rack.noise_rms_m * 1.0 + 1e-12
    assert 0.05 <= rack.knot_spacing_s <= 1.0


def test_a_record_that_starts_at_rest_is_held_at_rest_and_one_that_starts_moving_is_not():
    """The cycle starts from rest, so the spline's speed at the first sample is zero; a record cut in the middle
    of a stroke keeps its speed (about 15 mm/s)."""
    t, logged, _ = _logged_rack(2, True)
    rack = smooth_rack(t, logged)
    assert rack.held_at_rest[0]
    assert abs(rack.evaluate(t[:1])[1][0]) < 1e-12
    t2, logged2, _ = _logged_rack(2, False)
    moving = smooth_rack(t2, logged2)
    assert not moving.held_at_rest[0]
    assert abs(moving.evaluate(t2[:1])[1][0]) > 0.01


def test_drawn_racks_scatter_as_the_data_allow():
    """Racks drawn from the spline's least-squares distribution differ from it by about the spline's own
    uncertainty: a small fraction of the rack noise, never more than the noise itself."""
    t, logged, _ = _logged_rack(3, True)
    rack = smooth_rack(t, logged)
    rng = np.random.default_rng(0)
    spread = np.std([rack.perturbed(rng).evaluate(t)[0] - rack.evaluate(t)[0] for _ in range(20)], axis=0)
    assert 0.1 * rack.noise_rms_m < np.median(spread) < rack.noise_rms_m


def test_relogged_racks_scatter_about_the_smoothed_one():
    """A rack logged again through the same 8-bit logger and smoothed again stays within a converter step of the
    smoothed rack, keeps its knot spacing, and differs from it (the logger's noise is drawn again)."""
    t, logged, _ = _logged_rack(6, True)
    rack = smooth_rack(t, logged)
    again = relogged_rack(rack, t, FULL_SCALE_M, 8, 0.0002, np.random.default_rng(1))
    difference = again.evaluate(t)[0] - rack.evaluate(t)[0]
    assert again.knot_spacing_s == rack.knot_spacing_s
    assert 0.0 < np.sqrt(np.mean(difference**2)) < quantisation_step(FULL_SCALE_M)


def test_a_rack_drawn_from_numbers_drawn_in_advance_is_the_one_drawn_in_line():
    """DrawnInAdvance (the replay ensemble's random numbers drawn in order, its racks made in a worker): a rack
    logged again, smoothed and moved within a coarse rounding from numbers drawn in advance is, bit for bit, the
    rack drawn from the generator itself; a call for other numbers than those drawn, or numbers left unused, is
    refused."""
    t, logged, _ = _logged_rack(3, True)
    rack = smooth_rack(t, logged)
    rng = np.random.default_rng(5)
    in_line = rounding_draw(relogged_rack(rack, t, FULL_SCALE_M, 8, 0.0002, rng), t, 0.001, rng)
    rng, count = np.random.default_rng(5), rounding_draw_size(t)
    numbers = DrawnInAdvance([("normal", (0.0, 0.0002, t.shape), rng.normal(0.0, 0.0002, t.shape)),
                              ("standard_normal", (count,), rng.standard_normal(count))])
    ahead = rounding_draw(relogged_rack(rack, t, FULL_SCALE_M, 8, 0.0002, numbers), t, 0.001, numbers)
    numbers.check_used()
    assert np.array_equal(ahead.breaks, in_line.breaks) and np.array_equal(ahead.coefficients, in_line.coefficients)
    with pytest.raises(RuntimeError, match="asked for"):
        DrawnInAdvance([("standard_normal", (count,), np.zeros(count))]).standard_normal(count + 1)
    with pytest.raises(RuntimeError, match="not used"):
        DrawnInAdvance([("standard_normal", (count,), np.zeros(count))]).check_used()


def test_an_override_set_in_the_vector_replays_as_a_prepared_run(params):
    """Bookkeeping of Replay.parameter_vector: an override that only enters the equations is written into the
    vector, one that shapes the preparation (a case value) prepares the run again; either way the torque is the
    one of a run prepared with that override."""
    t, logged, _ = _logged_rack(7, True)
    rack = smooth_rack(t, logged)
    effects = resolve_effects(None)
    replay = Replay(effects, "unladen", "ground", params, rack, t)
    for key, value in (("steering.rack_friction_force", params["steering.rack_friction_force"] + 150.0),
                       ("case.load_left", params.case("unladen")["load_left"] + 100.0)):
        run = prepare("unladen", effects, {key: value}, "ground", params)
        expected = solve(run, run.p, rack, t).torque_Nm
        assert np.max(np.abs(replay.torque({key: value}) - expected)) < 1e-9, key
    model = replay.parameter_vector()[0].model.directory.name
    assert replay.direct[(model, "steering.rack_friction_force")] and not replay.direct[(model, "case.load_left")]


def test_a_rack_friction_override_changes_the_torque_by_its_physical_share(params):
    """Raising the rack friction force by 100 N raises the sliding torque by 100 N / 186.47 rad/m = 0.54 N m
    at the handwheel (times the Hooke joint's speed ratio, 0.90 to 1.11)."""
    t, logged, _ = _logged_rack(5, True)
    rack = smooth_rack(t, logged)
    replay = Replay(resolve_effects(None), "unladen", "ground", params, rack, t)
    base = replay.torque()
    more = replay.torque({"steering.rack_friction_force": params["steering.rack_friction_force"] + 100.0})
    speed = rack.evaluate(t)[1]
    sliding = np.abs(speed) > 0.008
    share = (more - base)[sliding] * np.sign(speed[sliding])
    expected = 100.0 / params["steering.handwheel_to_rack_ratio"]
    assert np.all(share > 0.85 * expected) and np.all(share < 1.16 * expected)
    assert np.mean(share) == pytest.approx(expected, rel=0.05)


def test_replays_on_one_host_model_share_its_prepared_runs_and_replay_as_alone(params):
    """ReplayEngine.new_replay: the replays of two effect sets on one host model (a candidate and the set without
    it, as a diagnosis replays them) prepare its base run once, and each gives exactly the torque of a replay made
    alone on that model, with an override set in the vector and one that prepares the run again (a case value):
    a prepared run does not depend on which replay made it."""
    t, logged, _ = _logged_rack(13, True)
    rack = smooth_rack(t, logged)
    base = resolve_effects(None)
    host = resolve_effects([*base, discover_effects()["column_friction"]])
    engine = ReplayEngine(hosts={effect_key(base): host, effect_key(host): host})
    first = engine.new_replay(base, "unladen", "ground", params, rack, t)
    second = engine.new_replay(host, "unladen", "ground", params, rack, t)
    assert first._base is second._base
    moves = ({}, {"steering.rack_friction_force": params["steering.rack_friction_force"] + 80.0},
             {"case.load_left": 1.05 * params["cases.unladen.load_left"]})
    for effects, shared in ((base, first), (host, second)):
        alone = Replay(effects, "unladen", "ground", params, rack, t, model_effects=host)
        for overrides in moves:
            assert np.array_equal(shared.torque(overrides), alone.torque(overrides))


def test_the_engine_finds_an_effect_sets_model_once(monkeypatch):
    """LoadedModels (the replay engine's models): an effect set's cache key, a hash of its source, is computed once
    however many runs are prepared on it, and the model found is the cache entry of that key, the one a fresh
    CompiledModels loads."""
    import parksteer.model.numeric.compiled as compiled

    effects = resolve_effects(None)
    expected = compiled.CompiledModels().of(effects).directory
    keyed = []
    monkeypatch.setattr(compiled, "entry_path", lambda e: keyed.append(1) or compiled_entry_path(e))
    engine = ReplayEngine()
    found = [engine.models.of(effects) for _ in range(3)]
    assert len(keyed) == 1 and all(model is found[0] for model in found)
    assert found[0].directory == expected


def test_a_replay_on_another_rack_shares_the_preparation_not_the_result(params):
    """Replay.on_rack (the replay ensemble's racks): the prepared runs do not depend on the rack, so a replay made
    from another's on a second rack gives exactly the torque of a replay prepared afresh on that rack, overrides
    included, and a different torque from the first rack's."""
    t, logged, _ = _logged_rack(11, True)
    _, other_logged, _ = _logged_rack(12, True)
    first, second = smooth_rack(t, logged), smooth_rack(t, other_logged)
    effects = resolve_effects(None)
    replay = Replay(effects, "unladen", "ground", params, first, t)
    moved = {"steering.rack_friction_force": params["steering.rack_friction_force"] + 80.0}
    shared = replay.on_rack(second)
    fresh = Replay(effects, "unladen", "ground", params, second, t)
    for overrides in ({}, moved):
        assert np.array_equal(shared.torque(overrides), fresh.torque(overrides))
    assert not np.array_equal(shared.torque(), replay.torque())


def test_a_repeated_replay_is_answered_from_the_memo_bit_for_bit_and_counted(params):
    """SolutionMemo (ReplayEngine.solutions): a solve is a function of its inputs alone, so a replay asked again
    with the same compiled model, vector, rack and times (another effect set on the same host model at the same
    values, as each candidate's signature replays the calibrated model at strength 0) is not solved again, yet is
    counted as a replay, and gives bit for bit what a replay without the memo solves, its outputs too; what it hands
    out is a copy, so a caller changing it changes no later answer; another vector or rack is solved anew."""
    t, logged, _ = _logged_rack(17, True)
    _, other_logged, _ = _logged_rack(18, True)
    rack, other_rack = smooth_rack(t, logged), smooth_rack(t, other_logged)
    base = resolve_effects(None)
    host = resolve_effects([*base, discover_effects()["column_friction"]])
    engine = ReplayEngine(hosts={effect_key(base): host, effect_key(host): host})
    first = engine.new_replay(base, "unladen", "ground", params, rack, t)
    second = engine.new_replay(host, "unladen", "ground", params, rack, t)
    alone = Replay(base, "unladen", "ground", params, rack, t, model_effects=host)
    run, p = alone.parameter_vector()
    solved = solve(run, p, rack, t)

    torque = first.torque()
    assert engine.solutions.found == 0 and np.array_equal(torque, solved.torque_Nm)
    torque[:] = 0.0  # a caller's own copy
    again = second.torque()
    assert engine.solutions.found == 1 and engine.evaluations == 2
    assert np.array_equal(again, solved.torque_Nm) and again.tobytes() == solved.torque_Nm.tobytes()

    with_outputs = [first.solve(outputs=True), second.solve(outputs=True)]
    fresh = solve(run, p, rack, t, outputs=True)
    assert engine.solutions.found == 2
    for found in with_outputs:
        assert np.array_equal(found.states, fresh.states) and np.array_equal(found.handwheel, fresh.handwheel)
        assert all(np.array_equal(found.outputs[k], fresh.outputs[k]) for k in fresh.outputs)

    moved = {"steering.rack_friction_force": params["steering.rack_friction_force"] + 80.0}
    assert np.array_equal(second.torque(moved), alone.torque(moved))
    assert np.array_equal(first.on_rack(other_rack).torque(), alone.on_rack(other_rack).torque())
    assert engine.solutions.found == 2 and engine.evaluations == 6
