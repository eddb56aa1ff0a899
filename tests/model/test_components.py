"""Effects as components: the registry, the effects spec and the overrides."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.model.symbolic.components import discover_effects, resolve_effects
from parksteer.model.numeric.simulate import simulate
from parksteer.model.numeric.values import parse_overrides

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
    """--set items must be OWNER.PARAM=number; unknown parameters and values out of bounds are refused."""
    assert parse_overrides(["rack_friction.friction_force=500"]) == {"rack_friction.friction_force": 500.0}
    for bad in (["rack_friction.friction_force"], ["friction_force=1"], ["rack_friction.friction_force=abc"]):
        with pytest.raises(UsageError):
            parse_overrides(bad)
    for bad in ({"rack_friction.friction_force": -1.0}, {"rack_friction.bogus": 1.0}, {"nobody.x": 1.0},
                {"steering.rack_mass": 0.0}):
        with pytest.raises(UsageError):
            simulate("unladen", overrides=bad, t_end_s=0.1)


def test_every_effect_declares_its_parameters(params):
    """Each effect has a description and parameters with SI unit, bounds containing the default, and a source."""
    for effect in discover_effects().values():
        described = effect.describe(params)
        assert described["description"]
        for p in described["parameters"]:
            assert p["unit"] and p["source"]
            assert p["min"] <= p["default"] <= p["max"]


NEW_EFFECT = '''
"""Viscous damping of the rack (an effect added as one file)."""
from parksteer.model.symbolic.components import Effect, EffectParameter


class RackViscous(Effect):
    name = "rack_viscous_test"
    description = "viscous force on the rack, -c * rack speed"
    in_default_set = False
    parameters = (EffectParameter("damping", "N s/m", 0.0, 1e6, "test", default=0.0),)

    def loads(self, model):
        force = model.p(self, "damping") * model.rack_u
        return [(model.rack_point, -force * model.B.y), (model.rack_housing_point, force * model.B.y)]


EFFECT = RackViscous()
'''


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
