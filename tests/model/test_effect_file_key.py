"""An effect loaded from a file is keyed by its text: an edited file (or another file of the same name) builds its
own compiled model instead of replaying the one built for the old text."""

from __future__ import annotations

from parksteer.model.codegen.cache import model_key
from parksteer.model.symbolic.components import load_effect_module

from model_helpers import rack_effect_text

TEXT = rack_effect_text("Push", "file_key_push", "a constant push on the rack", "force", "N", "100.0",
                        '-SCALE * model.p("file_key_push.force") * k.B.y')


def test_two_files_of_one_name_and_class_but_different_text_have_different_model_keys(tmp_path):
    """The same stem, class and effect name, a force scaled by 1 in one file and by 2 in the other: different
    physics, so different keys; the same text in another folder: the same key."""
    paths = []
    for folder, scale in (("a", 1.0), ("b", 2.0), ("c", 1.0)):
        (tmp_path / folder).mkdir()
        path = tmp_path / folder / "push.py"
        path.write_text(f"SCALE = {scale}\n" + TEXT, encoding="utf-8")
        paths.append(path)
    keys = [model_key([load_effect_module(str(p))]) for p in paths]
    assert keys[0] != keys[1]
    assert keys[0] == keys[2]
