"""Effects as components: the registry, the effects spec and the overrides."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.model.symbolic.components import Effect, discover_effects, resolve_effects, strength_parameter
from parksteer.model.symbolic.derive import build_space
from parksteer.model.numeric.simulate import simulate
from parksteer.model.numeric.values import parse_overrides

from model_helpers import rack_effect_text

PAPER_EFFECTS = ["carcass_compliance", "hooke_joint", "lifting", "rack_friction", "tyre_friction"]


def test_default_set_is_the_papers_five():
    """Without a spec the model has the five mechanisms of the paper's section 5."""
    assert [e.name for e in resolve_effects(None)] == PAPER_EFFECTS


def test_spec_adds_and_removes_from_the_default_set():
    """'-name' removes an effect from the default set, '+name' adds one; a bare list names the set exactly."""
    assert [e.name for e in resolve_effects("-rack_friction,-tyre_friction")] == [
        "carcass_compliance", "hooke_joint", "lifting"]
    assert [e.name for e in resolve_effects("lifting,rack_friction")] == ["lifting", "rack_friction"]
    assert resolve_effects("none") == []
    with pytest.raises(UsageError):
        resolve_effects("-no_such_effect")
    with pytest.raises(UsageError):
        resolve_effects("lifting,-rack_friction")


def test_overrides_are_checked():
    """--set items must be SECTION.NAME=number; unknown keys, keys of an effect not in the model and values
    outside the quantity's physical bounds are refused."""
    assert parse_overrides(["steering.rack_friction_force=500"]) == {"steering.rack_friction_force": 500.0}
    for bad in (["steering.rack_friction_force"], ["friction_force=1"], ["steering.rack_friction_force=abc"]):
        with pytest.raises(UsageError):
            parse_overrides(bad)
    for bad in ({"steering.rack_friction_force": -1.0}, {"steering.bogus": 1.0}, {"nobody.x": 1.0},
                {"steering.rack_mass": 0.0}, {"tyre.tyre_pressure": 1.225}, {"rack_lash.lash": 1e-4},
                {"rack_friction.friction_force": 500.0}):
        with pytest.raises(UsageError):
            simulate("unladen", overrides=bad, t_end_s=0.1)


def test_every_effect_declares_its_parameters(params):
    """Each effect has a description and uses quantities of the registry, each with SI unit, bounds containing
    the file's value, and a source; an effect's own quantities are declared on the effect (none of them is in the
    parameter file, which holds the car's), and every rival names diagnosis candidates as its closest and related
    mechanisms and a probe strength within its strength quantity's bounds."""
    effects = discover_effects()
    for effect in effects.values():
        described = effect.describe(params)
        assert described["description"]
        for p in described["parameters"]:
            assert p["unit"] and p["source"]
            assert p["min"] <= p["default"] <= p["max"]
        declared = {q.key for q in effect.quantities}
        for key in effect.own_keys():
            assert key in declared and key not in params.sources, key
        if effect.rival is not None:
            assert not effect.diagnosis_candidate and effect.rival.why
            for name in filter(None, (effect.rival.closest, *effect.rival.related)):
                assert effects[name].diagnosis_candidate, (effect.name, name)
            assert strength_parameter(effect, params).within(effect.rival.probe_strength), effect.name
    assert discover_effects()["rack_lash"].own_keys() == ("rack_lash.lash", "rack_lash.smoothing_width")


class _Linkage(Effect):
    name = "linkage_test"
    description = "a second steer function"
    in_default_set = False
    replaces = "steer_function"


def test_two_effects_filling_one_slot_are_refused_in_one_line():
    """Ackermann's linkage and a second linkage both fill the steer_function slot: resolving the set is refused in
    one line naming both and the slot, instead of the later one silently replacing the earlier."""
    with pytest.raises(UsageError) as info:
        resolve_effects([*resolve_effects("+ackermann"), _Linkage()])
    message = str(info.value)
    assert "\n" not in message
    assert "ackermann" in message and "linkage_test" in message and "steer_function" in message


def test_a_missing_dependency_is_refused_in_one_line():
    """brush_patch requires carcass_compliance and tyre_friction: without one, resolving the set is refused in one
    line naming it (the effect once silently added nothing)."""
    with pytest.raises(UsageError) as info:
        resolve_effects("-carcass_compliance,+brush_patch")
    message = str(info.value)
    assert "\n" not in message and "brush_patch requires carcass_compliance" in message
    with pytest.raises(UsageError, match="braked_wheels requires tyre_friction"):
        resolve_effects("-tyre_friction,+braked_wheels")


def test_building_two_models_leaves_no_state_on_the_effects():
    """Two models built in one process with different effect sets: the coordinates each effect adds live on its
    model (model.state(effect)), so the effect singletons keep no per-build attributes and each model keeps
    its own annuli and twists."""
    effects = discover_effects()
    before = {name: dict(vars(e)) for name, e in effects.items()}
    with_brush = build_space(resolve_effects("+brush_patch"))
    plain = build_space(resolve_effects(None))
    assert {name: dict(vars(e)) for name, e in effects.items()} == before == {name: {} for name in effects}
    brush, carcass = effects["brush_patch"], effects["carcass_compliance"]
    assert len(with_brush.state(brush).annulus["left"]) == 2
    assert not vars(plain.state(brush))
    twist_a, twist_b = with_brush.state(carcass).twist["left"][0], plain.state(carcass).twist["left"][0]
    assert twist_a in with_brush.q and twist_b in plain.q
    assert [c.name for c in plain.coordinates] == ["rack", "bounce", "roll", "twist_left", "twist_right"]


NEW_EFFECT = rack_effect_text(
    "RackViscous", "rack_viscous_test", "viscous force on the rack, -c * rack speed", "damping", "N s/m", "1e6",
    'force = model.p("rack_viscous_test.damping") * model.rack_u\n-force * k.B.y',
    docstring="Viscous damping of the rack (an effect added as one file).")


@pytest.mark.slow  # builds a model of its own: started early, so that the workers end together
def test_a_new_effect_is_one_file(tmp_path, params, nominal):
    """A mechanism added as one file (given by path in the spec) joins the model without editing the core; at
    strength 0 (its default) the torque is the nominal one, and at damping c its share of the handwheel torque is
    c * rack speed mapped through the column, i.e. c v / (d theta_c / d rack)."""
    path = tmp_path / "rack_viscous_test.py"
    path.write_text(textwrap.dedent(NEW_EFFECT), encoding="utf-8")
    spec = f"+{path}"
    absent = simulate("unladen", effects=spec, params=params)
    assert "contrib_rack_viscous_test_Nm" in absent.columns
    np.testing.assert_allclose(absent.columns["handwheel_torque_Nm"], nominal.columns["handwheel_torque_Nm"],
                               atol=2e-3)
    damping = 2000.0
    present = simulate("unladen", effects=spec, overrides={"rack_viscous_test.damping": damping}, params=params)
    c = present.columns
    column_per_rack = np.gradient(c["column_angle_rad"], c["rack_m"])
    moving = np.abs(c["rack_speed_m_s"]) > 0.005
    expected = damping * c["rack_speed_m_s"] / column_per_rack
    assert np.max(np.abs(c["contrib_rack_viscous_test_Nm"] - expected)[moving]) < 0.01 * np.max(np.abs(expected))
