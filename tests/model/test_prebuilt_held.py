"""The models a diagnosis against a car's baseline builds: the baseline holds the form it learnt on the car's
model, and every later diagnosis replays the diagnosis models over it. `parksteer derive --prebuilt` given the
baseline benchmark's car results pre-derives them, so that a cold pipeline's baseline job compiles them instead of
deriving them."""

from __future__ import annotations

import json

from parksteer.commands.model import _held_form_sets
from parksteer.diagnose.candidates import default_diagnosis_models
from parksteer.diagnose.suggest import shape_forms
from parksteer.model.codegen import cache
from parksteer.model.symbolic.components import resolve_effects


def _car(tmp_path, kind, form):
    path = tmp_path / "car.json"
    path.write_text(json.dumps({"car": "bore", "kind": kind, "learnt": {"verdict": "unexplained", "form": form}}))
    return str(path)


def test_a_manual_cars_held_form_gives_the_default_diagnosis_models_with_it(tmp_path):
    """Each default diagnosis model (base, every candidate at once, brush_patch) with the learnt form added, once
    each; each spec resolves back to its model's key (as the shipped models' staleness check resolves it), and the
    base model with the form is the suggestion's form the package already ships."""
    form = next(f for f in shape_forms() if f.name == "shape_elastic_9")
    sets = _held_form_sets(_car(tmp_path, "manual", form.name))
    wanted = [sorted([e.name for e in model] + [form.name]) for model in default_diagnosis_models()]
    assert [sorted(e.name for e in effects) for _, effects in sets] == wanted
    for spec, effects in sets:
        again = sorted([*resolve_effects(spec.get("effects")), form], key=lambda e: e.name)
        assert spec["shape"] == form.name and cache.model_key(again) == cache.model_key(effects)
    base_key = cache.model_key(sets[0][1])
    assert cache.prebuilt_specs().get(base_key) == {"shape": form.name}


def test_what_is_not_a_manual_cars_result_gives_no_held_sets(tmp_path, capsys):
    """A pipeline model manifest is not a baseline result (None: it is read as a manifest); an assisted car's form
    is on the car's own assisted model, which this does not pre-derive, and is said on stderr (no sets)."""
    manifest = tmp_path / "full.json"
    manifest.write_text(json.dumps({"effects": ["rack_friction"], "key": "0" * 20, "spec": None}))
    assert _held_form_sets(str(manifest)) is None
    assert _held_form_sets(_car(tmp_path, "assisted", "shape_elastic_9")) == []
    assert "not pre-derived" in capsys.readouterr().err
