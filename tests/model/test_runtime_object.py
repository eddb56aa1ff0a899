"""The models' runtime is compiled once per cache and linked with each model (parksteer.model.codegen.compiler): the
numbers are those of the runtime compiled in one translation unit with the model, whose dimensions the compiler then
knows; one object serves every model; a damaged object is compiled again."""

from __future__ import annotations

import dataclasses
import json
import shutil

import numpy as np
import pytest

from parksteer.measure.rack_spline import interpolate_rack
from parksteer.model.codegen import cache, compiler
from parksteer.model.codegen.runtime import HERE, RUNTIME_FILES, WITH_TANGENT
from parksteer.model.numeric.compiled import load_entry
from parksteer.model.numeric.sensitivities import parameter_directions, solve_sensitivities
from parksteer.model.numeric.simulate import integrate, prepare
from parksteer.model.symbolic.components import resolve_effects

pytestmark = pytest.mark.slow


def _one_translation_unit(entry, folder):
    """The entry's model compiled with the runtime's text after it in one file, as every model was built before the
    runtime was compiled apart: NQ, NOUT, ... are the model's constants there, and the tangent is compiled in.
    Assembled here from the C files, not through runtime.runtime_source, so that the reference does not share the
    code it checks."""
    folder.mkdir()
    text = (entry / "model.c").read_text(encoding="utf-8")
    text += "".join("\n" + (HERE / name).read_text(encoding="utf-8") for name in RUNTIME_FILES)
    (folder / "model.c").write_text(text, encoding="utf-8")
    shutil.copy(entry / "model.json", folder / "model.json")
    cmd = [compiler.find_compiler(), *compiler.COMPILE_FLAGS, f"-D{WITH_TANGENT}", "-o", str(folder / "model.so"),
           str(folder / "model.c"), "-lm"]
    compiler.run_compiler(cmd, "the model in one translation unit")
    return load_entry(folder)


def test_the_runtime_compiled_apart_gives_the_bits_of_one_translation_unit(cache_dir, tmp_path):
    """The paper's cycle integrated handwheel-driven (mass matrix, Cholesky solves, the analytic Jacobian, the
    integrator), its outputs, and a prescribed-rack solve with its forward sensitivities (the drive, the LU solves,
    the tangent, from the model's second library) are the same bits whether the runtime knows the model's
    dimensions at compile time or reads them at run time: IEEE arithmetic in the same order, no fused multiply-add
    at any level."""
    run = prepare("unladen")
    alone = dataclasses.replace(run, model=_one_translation_unit(run.model.directory, tmp_path / "one"))
    t = np.round(np.arange(0.0, run.profile.end_time_s + 0.005, 0.01), 12)
    states = integrate(run, t)
    assert states.tobytes() == integrate(alone, t).tobytes()
    assert np.ptp(states[:, run.model.index("rack")]) > 0.05  # the rack swept the cycle's stroke
    outputs, again = run.model.evaluate_outputs(t, states, run.p), alone.model.evaluate_outputs(t, states, alone.p)
    assert outputs.keys() == again.keys() and all(outputs[k].tobytes() == again[k].tobytes() for k in outputs)
    t_rack = np.linspace(0.0, 4.0, 401)
    rack = interpolate_rack(t_rack, 0.03 * np.sin(np.pi * t_rack / 2.0))
    times = np.linspace(0.5, 1.5, 51)
    keys = ["steering.rack_friction_force", "tyre.carcass_torsional_stiffness"]
    apart = solve_sensitivities(run, run.p, rack, times, parameter_directions(run, keys))
    one = solve_sensitivities(alone, alone.p, rack, times, parameter_directions(alone, keys))
    assert apart.torque_sensitivities.tobytes() == one.torque_sensitivities.tobytes()
    assert np.all(np.abs(apart.torque_sensitivities).max(axis=0) > 0.0)


def test_one_runtime_object_serves_every_model_and_a_damaged_one_is_compiled_again(cache_dir):
    """Two models built into an empty cache link one runtime object; an object damaged afterwards (here: its bytes
    replaced) fails the next link, is compiled again and the model built and run."""
    first = cache.ensure(resolve_effects(None))
    second = cache.ensure(resolve_effects("+rack_lash"))
    objects = list((cache_dir / compiler.RUNTIME_FOLDER).glob("*.o"))
    assert [p.name for p in objects] == [f"{compiler.shared_key(compiler.find_compiler(), 'runtime')}.o"]
    assert first["built_now"] and second["built_now"]
    objects[0].write_bytes(b"not an object file")
    third = cache.ensure(resolve_effects("+ackermann"))
    assert third["built_now"] and objects[0].read_bytes()[:4] == b"\x7fELF"
    run = prepare("unladen", effects="+ackermann")
    assert json.loads((cache_dir / third["key"] / "model.json").read_text())["prebuilt"] is True
    assert np.all(np.isfinite(integrate(run, np.linspace(0.0, 1.0, 11))))


def test_models_built_side_by_side_on_an_empty_cache_compile_the_runtime_once(cache_dir, capfd):
    """A first diagnosis builds its three models in background processes side by side (start_builds); each needs
    the runtime: the first compiles it under its lock, the others wait and link the same object."""
    sets = [resolve_effects(None), resolve_effects("+rack_lash"), resolve_effects("+ackermann")]
    builders = cache.start_builds(sets, jobs=3)
    assert len(builders) == 3
    cache.finish_builds(builders)
    assert [b.exitcode for b in builders] == [0, 0, 0]
    assert all(cache.entry_is_sound(cache.entry_path(effects)) for effects in sets)
    assert capfd.readouterr().err.count("compiling the models' runtime") == 1


def test_the_runtime_compiles_beside_the_first_models_object_not_after_it(cache_dir, tmp_path, monkeypatch):
    """On an empty cache a model's build starts its own object's compile and meanwhile compiles the missing runtime:
    the two run side by side. The compiler here is a wrapper that logs each compile and holds the model's until the
    runtime's has ended (giving up after 30 s): built one after the other, the log would read model, then runtime."""
    log, wrapper = tmp_path / "compiles.log", tmp_path / "cc"
    wrapper.write_text(f"""#!/bin/sh
case "$*" in
*" -c "*model.c*)
  echo start model >> {log}
  i=0; while ! grep -q "end runtime" {log} && [ $i -lt 300 ]; do sleep 0.1; i=$((i + 1)); done
  "{compiler.find_compiler()}" "$@"; status=$?; echo end model >> {log}; exit $status;;
*" -c "*runtime.c*)
  echo start runtime >> {log}; "{compiler.find_compiler()}" "$@"; status=$?; echo end runtime >> {log}; exit $status;;
esac
exec "{compiler.find_compiler()}" "$@"
""", encoding="utf-8")
    wrapper.chmod(0o755)
    monkeypatch.setenv("CC", str(wrapper))
    assert cache.ensure(resolve_effects(None))["built_now"]
    assert log.read_text(encoding="utf-8").split("\n") == ["start model", "start runtime", "end runtime", "end model",
                                                            ""]


def test_the_shipped_boost_table_is_the_law_as_printed():
    """boost_table.c, which every model with a boost table links, is the C that generate prints from the law in
    sympy (assist_common.table_law): a model derived here and one compiled from shipped C call the same law."""
    from parksteer.model.codegen.generate import table_functions_source
    from parksteer.model.codegen.runtime import boost_table_source

    assert boost_table_source() == table_functions_source()


def test_models_with_a_boost_table_link_one_compiled_law(cache_dir):
    """Two assisted models built into an empty cache compile the boost table's law once, beside the runtime, and
    each links it: the law's functions are hidden symbols, so a library without the object would not link (the
    assisted replays' tests run the law through these libraries against its Python evaluation)."""
    sets = [resolve_effects("+electric_assist_column"), resolve_effects("+electric_assist_column,+assist_motor_friction")]
    manifests = [cache.ensure(effects) for effects in sets]
    compiled = compiler.find_compiler()
    names = sorted(p.name for p in (cache_dir / compiler.RUNTIME_FOLDER).glob("*.o"))
    assert names == sorted(f"{compiler.shared_key(compiled, name)}.o" for name in ("runtime", "boost_table"))
    for manifest in manifests:
        info = json.loads((cache_dir / manifest["key"] / "model.json").read_text())
        assert info["shared_objects"] == ["boost_table"] and info["prebuilt"] is True
        assert load_entry(cache_dir / manifest["key"]) is not None
