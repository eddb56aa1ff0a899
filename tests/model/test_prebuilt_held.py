"""The models a diagnosis against a car's baseline builds: the baseline holds the form it learnt on the car's
model, and every later diagnosis replays the diagnosis models over it. `parksteer derive --prebuilt` pre-derives
them for every form a baseline can hold, so that the first diagnosis against a manual car's baseline (and a cold
pipeline's baseline job) compiles them instead of deriving them."""

from __future__ import annotations

import json

from parksteer.cli import main
from parksteer.commands.model import _held_form_sets
from parksteer.diagnose.candidates import default_diagnosis_models
from parksteer.diagnose.suggest import shape_forms
from parksteer.model.codegen import cache
from parksteer.model.symbolic.components import resolve_effects


def test_every_form_a_baseline_can_hold_ships_the_default_diagnosis_models_with_it():
    """For each form a suggestion can take (what a manual car's baseline holds), the default diagnosis models (base,
    every candidate at once, brush_patch) with the form added, once each; each spec resolves back to its model's
    key (as the shipped models' staleness check resolves it), and the package ships the C of every one of them."""
    sets = _held_form_sets()
    shipped = cache.prebuilt_specs()
    forms = shape_forms()
    assert len(sets) == len(forms) * len(default_diagnosis_models())
    for form in forms:
        held = [effects for spec, effects in sets if spec["shape"] == form.name]
        wanted = [sorted([e.name for e in model] + [form.name]) for model in default_diagnosis_models()]
        assert [sorted(e.name for e in effects) for effects in held] == wanted, form.name
    for spec, effects in sets:
        form = next(f for f in forms if f.name == spec["shape"])
        again = sorted([*resolve_effects(spec.get("effects")), form], key=lambda e: e.name)
        key = cache.model_key(effects)
        assert cache.model_key(again) == key
        assert key in shipped, f"{spec}: not pre-derived (run `parksteer derive --prebuilt results/model/*.json`)"


def test_a_baseline_result_is_not_a_model_manifest(tmp_path, capsys):
    """The baseline benchmark's car results are no longer needed to pre-derive the held forms' models: given as a
    manifest, one is refused in one line naming the file, before anything is derived."""
    path = tmp_path / "bore.json"
    path.write_text(json.dumps({"car": "bore", "kind": "manual", "learnt": {"verdict": "unexplained",
                                                                            "form": "shape_elastic_9"}}))
    assert main(["derive", "--prebuilt", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bore.json" in err[0] and "not a model manifest" in err[0]
