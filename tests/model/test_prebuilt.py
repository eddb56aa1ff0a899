"""The package's pre-derived models (src/parksteer/model/prebuilt): the C a cold cache compiles instead of deriving
must be what the derivation gives today, byte for byte, for exactly the models a diagnosis with the default effects
builds. A change to the symbolic half without `parksteer derive --prebuilt` fails here, not silently slow."""

from __future__ import annotations

import json

import pytest

from parksteer.diagnose.candidates import default_diagnosis_models
from parksteer.model.codegen import cache
from parksteer.model.symbolic.components import resolve_effects

REFRESH = "run `parksteer derive --prebuilt` and commit src/parksteer/model/prebuilt"


def test_prebuilt_models_are_the_default_diagnosis_models():
    """The shipped keys are the keys of the base, diagnosis and brush_patch models of today's source: no stale
    entry (a key nothing asks for any more) and none missing."""
    wanted = {cache.model_key(effects) for effects in default_diagnosis_models()}
    shipped = {p.name.removesuffix(".c.gz") for p in cache.PREBUILT_DIR.glob("*.c.gz")}
    described = {p.stem for p in cache.PREBUILT_DIR.glob("*.json")}
    assert len(wanted) == 3
    assert shipped == wanted == described, f"pre-derived models out of date: {REFRESH}"


def test_the_package_cars_first_diagnosis_needs_only_shipped_models(repo_root):
    """A car's values can change which models a diagnosis builds (a candidate already present in the car file
    needs a model of its own); the package's cars and the parameter file's leave every candidate absent, so their
    first diagnosis finds every model among the shipped ones."""
    from parksteer.diagnose.candidates import candidate_effects, models_to_build
    from parksteer.parameters import load_parameters
    from parksteer.vehicle import load_vehicle

    shipped = {p.name.removesuffix(".c.gz") for p in cache.PREBUILT_DIR.glob("*.c.gz")}
    base = resolve_effects(None)
    candidates = candidate_effects(base)[0]
    cars = sorted((repo_root / "data" / "vehicles").glob("*.toml"))
    assert cars
    for params in [load_parameters(), *(load_vehicle(car, load_parameters()) for car in cars)]:
        keys = {cache.model_key(effects) for effects in models_to_build(base, candidates, params)}
        assert keys <= shipped


def test_a_damaged_prebuilt_model_is_said_and_derived(tmp_path, monkeypatch, capsys):
    """A truncated shipped file is not trusted: the build says so and derives (here: reading gives None)."""
    key = cache.model_key(resolve_effects(None))
    (tmp_path / f"{key}.c.gz").write_bytes(b"\x1f\x8b\x08 truncated")
    (tmp_path / f"{key}.json").write_text("{}")
    monkeypatch.setattr(cache, "PREBUILT_DIR", tmp_path)
    assert cache.prebuilt_source(key) is None
    assert "damaged" in capsys.readouterr().err
    assert cache.prebuilt_source("0" * 20) is None and capsys.readouterr().err == ""


@pytest.mark.slow
def test_prebuilt_source_is_the_derivation():
    """Derived and generated again here, each model's C and description equal the shipped ones exactly: compiling
    the shipped C is deriving the model (the same bytes, so the same library and the same numbers)."""
    for effects in default_diagnosis_models():
        shipped = cache.prebuilt_source(cache.model_key(effects))
        assert shipped is not None, f"no pre-derived model of {[e.name for e in effects]}: {REFRESH}"
        source, info, _ = cache.derive_source(effects)
        assert source == shipped[0], f"pre-derived C differs from the derivation: {REFRESH}"
        assert cache.prebuilt_info(info) == shipped[1]


@pytest.mark.slow
def test_cold_cache_compiles_the_prebuilt_model(tmp_path, monkeypatch):
    """A cold cache builds the default model from the shipped C: no derivation time, the entry's C the shipped C,
    and a key that is not shipped is still derived (the cache entry says which)."""
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path))
    base = resolve_effects(None)
    manifest = cache.ensure(base)
    assert manifest["built_now"] and manifest["timings_s"]["derive"] == 0.0
    entry = json.loads((tmp_path / manifest["key"] / "model.json").read_text())
    assert entry["prebuilt"] is True
    assert (tmp_path / manifest["key"] / "model.c").read_text() == cache.prebuilt_source(manifest["key"])[0]
    other = resolve_effects("-rack_friction")
    manifest = cache.ensure(other)
    assert manifest["timings_s"]["derive"] > 0.0
    assert json.loads((tmp_path / manifest["key"] / "model.json").read_text())["prebuilt"] is False
