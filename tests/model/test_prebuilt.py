"""The package's pre-derived models (src/parksteer/model/prebuilt): the C a cold cache compiles instead of deriving
must be what the derivation gives today, byte for byte, for exactly the models a diagnosis with the default effects
builds. A change to the symbolic half without `parksteer derive --prebuilt` fails here, not silently slow."""

from __future__ import annotations

import json
import re

import pytest

from parksteer.diagnose.candidates import default_diagnosis_models
from parksteer.model.codegen import cache
from parksteer.model.symbolic.components import resolve_effects

REFRESH = "run `parksteer derive --prebuilt results/model/*.json` and commit src/parksteer/model/prebuilt"


def _effects(spec):
    """The effects of a shipped model's spec: an effects spec, a truth form of the signature benchmark, or a form
    a suggested effect is fitted on (with the default effects, or the effects the spec lists: a baseline's held
    form under a diagnosis model), or an example effect file with the effects the spec lists."""
    if isinstance(spec, dict) and "shape" in spec:
        from parksteer.diagnose.suggest import shape_forms

        form = next(f for f in shape_forms() if f.name == spec["shape"])
        return sorted([*resolve_effects(spec.get("effects")), form], key=lambda e: e.name)
    if isinstance(spec, dict) and "example" in spec:  # an effect file of the checkout's examples/
        from parksteer.model.codegen.cache import checkout_root

        return resolve_effects([*spec["effects"], str(checkout_root() / spec["example"])])
    if isinstance(spec, dict):
        from parksteer.experiments.outoflibrary import truth_effects
        from parksteer.synthetic.outoflibrary import form_by_name

        return truth_effects(form_by_name(spec["truth_form"]))
    return resolve_effects(spec)


def _shipped() -> set[str]:
    """The keys of the shipped models' C."""
    return {p.name.removesuffix(".c.gz") for p in cache.PREBUILT_DIR.glob("*.c.gz")}


def test_prebuilt_models_are_current_and_cover_the_default_diagnosis():
    """Every shipped model is the model of its spec in today's source (its key is the key of what the spec
    resolves to: no stale entry that nothing asks for any more), C and description in pairs, and the base,
    diagnosis and brush_patch models of a diagnosis with the default effects are among them. That they cover every
    set the pipeline derives is checked where the pipeline runs cold (.ci/run: every manifest says `prebuilt`)."""
    shipped = _shipped()
    specs = cache.prebuilt_specs()
    assert shipped == set(specs), f"pre-derived C and descriptions do not pair up: {REFRESH}"
    stale = sorted(key for key, spec in specs.items() if cache.model_key(_effects(spec)) != key)
    assert not stale, f"pre-derived models out of date ({len(stale)} of {len(specs)}): {REFRESH}"
    wanted = {cache.model_key(effects) for effects in default_diagnosis_models()}
    assert len(wanted) == 3 and wanted <= shipped, f"the default diagnosis's models are not all shipped: {REFRESH}"


def test_the_package_cars_first_diagnosis_needs_only_shipped_models(repo_root):
    """A car's values can change which models a diagnosis builds (a candidate already present in the car file
    needs a model of its own); the package's cars and the parameter file's leave every candidate absent, so their
    first diagnosis finds every model among the shipped ones."""
    from parksteer.diagnose.candidates import candidate_effects, models_to_build
    from parksteer.parameters import load_parameters
    from parksteer.vehicle import load_vehicle

    shipped = _shipped()
    base = resolve_effects(None)
    candidates = candidate_effects(base)[0]
    cars = sorted((repo_root / "data" / "vehicles").glob("*.toml"))
    assert cars
    for params in [load_parameters(), *(load_vehicle(car, load_parameters()) for car in cars)]:
        keys = {cache.model_key(effects) for effects in models_to_build(base, candidates, params)}
        assert keys <= shipped


def test_the_example_effect_files_first_diagnosis_needs_only_shipped_models(repo_root):
    """The documents' worked examples add an effect file to the model (`parksteer diagnose --effects=+FILE`:
    docs/signature.md's examples/user_effect, docs/measurement.md's src/parksteer/examples): every model such a
    diagnosis builds (the base with the file's effect, the diagnosis models over it) is shipped, so a reader's first
    run of those commands compiles and never derives."""
    from parksteer.commands.model import example_effect_files
    from parksteer.diagnose.candidates import candidate_effects, models_to_build

    shipped = _shipped()
    files = example_effect_files(repo_root)
    assert {path.name for path in files} >= {"centre_friction.py", "column_imbalance.py"}
    for path in files:
        base = resolve_effects(f"+{path}")
        missing = [[e.name for e in effects] for effects in models_to_build(base, candidate_effects(base)[0])
                   if cache.model_key(effects) not in shipped]
        assert not missing, f"{path.name}: models not shipped {missing}: {REFRESH}"


def test_the_paper_car_with_each_power_assist_is_shipped():
    """`--effects=+NAME` for each power assist the library has (a vehicle file's `[assist] type`): the paper's car
    with it is shipped, so the first run of any assist type compiles and never derives."""
    from parksteer.model.numeric.assist import ASSIST_EFFECTS

    shipped = _shipped()
    assert len(ASSIST_EFFECTS) == 4
    missing = [name for name in ASSIST_EFFECTS.values() if cache.model_key(resolve_effects(f"+{name}")) not in shipped]
    assert not missing, f"not shipped: {missing}: {REFRESH}"


def test_the_paper_model_without_each_of_its_effects_is_shipped():
    """`--effects=-NAME` for each of the paper's effects (the ablation a reader runs first, and the reference the
    physical checks switch lifting or the Hooke joint off for) is shipped: it compiles and never derives."""
    shipped = _shipped()
    names = [e.name for e in resolve_effects(None)]
    assert len(names) == 5
    missing = [name for name in names if cache.model_key(resolve_effects(f"-{name}")) not in shipped]
    assert not missing, f"not shipped: {missing}: {REFRESH}"


# An effects option in a document's command: `--effects SPEC` or `--effects=SPEC`, up to a space or a backquote.
_EFFECTS_OPTION = re.compile(r"--effects[ =]([^\s`]+)")


def _documented_plain_specs() -> set[str]:
    """The effects specs the documents' shell blocks run (as tests/test_docs.py reads them) that name library
    effects only (no effect file, no placeholder such as EFFECTS or +NAME)."""
    from test_docs import documents, parse

    specs = set()
    for name, text in documents().items():
        for block in parse(name, text):
            specs |= {spec for spec in _EFFECTS_OPTION.findall(block.text)
                      if not any(mark in spec for mark in ("/", ".py", "$")) and spec == spec.lower()}
    return specs


def test_every_plain_effects_spec_the_documents_run_is_shipped():
    """A reader running a document's `--effects` example on the paper's car compiles its model and never derives
    it: every spec of library effects in the documents' commands resolves to a shipped model
    (parksteer.commands.model.DOCUMENTED_SPECS ships those no other category does)."""
    specs = _documented_plain_specs()
    assert "-rack_friction,+kingpin_friction" in specs  # docs/model.md's example is found
    shipped = _shipped()
    missing = sorted(spec for spec in specs if cache.model_key(resolve_effects(spec)) not in shipped)
    assert not missing, f"not shipped: {missing} (add to DOCUMENTED_SPECS): {REFRESH}"


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
    other = resolve_effects("-carcass_compliance,-hooke_joint,-lifting,-tyre_friction")  # rack friction alone
    assert cache.model_key(other) not in cache.prebuilt_specs()
    manifest = cache.ensure(other)
    assert manifest["timings_s"]["derive"] > 0.0
    assert json.loads((tmp_path / manifest["key"] / "model.json").read_text())["prebuilt"] is False


def test_prebuilt_refuses_a_file_that_is_not_a_pipeline_manifest(tmp_path, capsys):
    """`parksteer derive --prebuilt results/model/*.json` reads the effects spec the derive rule keeps in each
    manifest: a file without one (an old manifest, another JSON) is refused in one line naming it, before
    anything is derived or written."""
    from parksteer.cli import main

    before = sorted(p.name for p in cache.PREBUILT_DIR.iterdir())
    manifest = tmp_path / "full.json"
    manifest.write_text(json.dumps({"effects": ["rack_friction"], "key": "0" * 20}), encoding="utf-8")
    assert main(["derive", "--prebuilt", str(manifest)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(manifest) in err[0] and "no 'spec'" in err[0]
    assert sorted(p.name for p in cache.PREBUILT_DIR.iterdir()) == before
