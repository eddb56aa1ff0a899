"""A model's tangent (eval_tangent, which only the forward sensitivities call) is compiled into a second library of
its cache entry on first use (parksteer.model.codegen.compiler.tangent_library); the model's own library, which every
replay loads, has a stub. The two libraries compute every function they share to the same bits; the second is built
once, under a lock, and again when damaged; a replay builds none."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import side_by_side

from parksteer.measure.rack_spline import interpolate_rack
from parksteer.model.codegen import cache
from parksteer.model.numeric.compiled import load_entry
from parksteer.model.numeric.prescribed import solve
from parksteer.model.numeric.sensitivities import parameter_directions, solve_sensitivities
from parksteer.model.numeric.simulate import integrate, prepare
from parksteer.model.symbolic.components import resolve_effects

pytestmark = pytest.mark.slow

TANGENT = "compiling the model's tangent"


def _rack():
    t = np.linspace(0.0, 2.0, 201)
    return interpolate_rack(t, 0.02 * np.sin(np.pi * t))


def test_a_replay_loads_no_tangent_and_the_sensitivities_give_its_bits(cache_dir, capfd):
    """The paper's car: a handwheel-driven run and a prescribed-rack replay build no tangent library, and the model's
    own library reports no sensitivities; the forward sensitivities then build the tangent library once, and its
    torque, states and outputs are the replay's, byte for byte (the same C, compiled with the same flags, but for
    the tangent); the torque's derivative by the rack's friction force is not zero (the tangent is there)."""
    run = prepare("unladen")
    entry = run.model.directory
    t = np.linspace(0.0, 1.0, 101)
    states = integrate(run, t)
    times = np.linspace(0.2, 1.8, 81)
    replay = solve(run, run.p, _rack(), times)
    assert run.model.lib.ps_sensitivities_available() == 0
    assert not (entry / "model_tangent.so").exists() and TANGENT not in capfd.readouterr().err

    keys = ["steering.rack_friction_force", "tyre.carcass_torsional_stiffness"]
    found = solve_sensitivities(run, run.p, _rack(), times, parameter_directions(run, keys))
    assert found.torque_Nm.tobytes() == replay.torque_Nm.tobytes()
    assert np.all(np.abs(found.torque_sensitivities).max(axis=0) > 0.0)
    tangent = run.model.with_tangent
    assert tangent.lib.ps_sensitivities_available() == 1 and tangent.lib is not run.model.lib
    assert (entry / "model_tangent.so").is_file() and (entry / "model_tangent.sha256").is_file()
    assert capfd.readouterr().err.count(TANGENT) == 1
    again = integrate(dataclasses.replace(run, model=tangent), t)
    assert again.tobytes() == states.tobytes()
    outputs, twin = run.model.evaluate_outputs(t, states, run.p), tangent.evaluate_outputs(t, states, run.p)
    assert all(outputs[k].tobytes() == twin[k].tobytes() for k in outputs)


def _tangent(entry: str) -> None:
    assert load_entry(entry).with_tangent.lib.ps_sensitivities_available() == 1


@pytest.mark.skipif(not side_by_side.FORKS, reason="forks its workers")
def test_the_tangent_library_is_built_once_side_by_side_and_a_damaged_one_again(cache_dir, capfd):
    """Three processes that need the tangent at once (a diagnosis's workers taking exact Jacobians): one compiles
    it under its lock, the others wait and load the same library; a later load finds it by its digest; bytes that
    are not the recorded ones (a truncated file) are compiled again; no scratch folder is left in the cache."""
    entry = cache.ensure_entry(resolve_effects(None))
    assert side_by_side.exit_codes(_tangent, str(entry)) == [0, 0, 0]
    assert capfd.readouterr().err.count(TANGENT) == 1
    info = load_entry(entry).info
    path = cache.ensure_tangent_library(entry, info)
    assert capfd.readouterr().err.count(TANGENT) == 0
    good = path.read_bytes()
    path.write_bytes(good[: len(good) // 2])
    assert load_entry(entry).with_tangent.lib.ps_sensitivities_available() == 1
    assert path.read_bytes()[:4] == b"\x7fELF" and capfd.readouterr().err.count(TANGENT) == 1
    assert sorted(p.name for p in cache_dir.iterdir() if p.name.startswith(".") and p.is_dir()) == []


def test_a_model_with_no_tangent_builds_no_second_library():
    """An assisted model's drive feeds the torsion bar's torque back (rack_drive false): its generated C has no
    tangent, so the model is its own tangent model and nothing more is compiled (in the checkout's cache, where
    the assisted tests build the same model)."""
    model = load_entry(cache.ensure_entry(resolve_effects("+hydraulic_assist")))
    assert model.info["rack_drive"] is False
    assert model.with_tangent is model and model.lib.ps_sensitivities_available() == 0
    assert not (model.directory / "model_tangent.so").exists()
