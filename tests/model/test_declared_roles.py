"""An effect's declared roles are what its class says: a contradiction between them is refused in one line, never
resolved silently (a rival is never a diagnosis candidate)."""

from __future__ import annotations

import pytest

from parksteer.errors import UsageError
from parksteer.model.symbolic.components import Effect, Rival, load_effect_module

RIVAL = Rival(closest="brush_patch", related=(), why="a probe of the check", probe_strength=1.0)


def test_a_rival_is_kept_out_of_the_candidates():
    """The fact checked: a class that declares a rival and says nothing of candidacy is no diagnosis candidate."""

    class Probe(Effect):
        name = "probe_rival"
        in_default_set = False
        rival = RIVAL

    assert Probe.diagnosis_candidate is False
    assert Effect.diagnosis_candidate is True  # the base's default is left as it was


@pytest.mark.parametrize("via_subclass", [False, True])
def test_a_rival_that_declares_itself_a_candidate_is_refused(via_subclass):
    """The fact checked: a class declaring both ``rival`` and ``diagnosis_candidate = True`` (itself, or a subclass
    of a rival) is refused with one line naming the effect, instead of having its candidacy switched off."""
    if via_subclass:
        class Base(Effect):
            name = "probe_base"
            rival = RIVAL

        with pytest.raises(UsageError, match=r"^effect probe_sub: declares both rival and diagnosis_candidate = True"):
            class Sub(Base):
                name = "probe_sub"
                diagnosis_candidate = True
    else:
        with pytest.raises(UsageError, match=r"^effect probe_both: declares both rival and diagnosis_candidate"):
            class Both(Effect):
                name = "probe_both"
                rival = RIVAL
                diagnosis_candidate = True


def test_an_effect_file_with_contradicting_roles_is_refused_in_one_line(tmp_path):
    """The fact checked: a user's effect file whose class declares both roles fails to load with one line that
    names the file and the contradiction."""
    path = tmp_path / "both_roles.py"
    path.write_text(
        "from parksteer.model.symbolic.components import Effect, Rival\n\n"
        "class BothRoles(Effect):\n"
        "    name = 'both_roles'\n"
        "    in_default_set = False\n"
        "    diagnosis_candidate = True\n"
        "    rival = Rival(closest=None, related=(), why='probe', probe_strength=1.0)\n\n"
        "EFFECT = BothRoles()\n", encoding="utf-8")
    with pytest.raises(UsageError) as raised:
        load_effect_module(str(path))
    message = str(raised.value)
    assert "\n" not in message and str(path) in message
    assert "declares both rival and diagnosis_candidate = True" in message
