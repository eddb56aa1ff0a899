"""The diagnosis model (parksteer.diagnose.candidates.diagnosis_model): one compiled model with every candidate that
shares it, where strength 0 means absent.

Physical fact checked: a candidate's loads are its strength times something finite, so at strength 0 the diagnosis
model's equations of motion are the base model's, and at one candidate's strength (the others 0) they are that
candidate's own model's. The compiled models sum their terms in different orders, so their right-hand sides agree
to rounding, and the adaptive solver turns a rounding difference into a different step sequence: at the replay's
own tolerance (PRESCRIBED_RTOL) two such models differ by the solver's error, about 0.001 N m on the measured cycle
(parksteer.model.numeric.tolerances: 0.0005 N m against a tight solve, each). Solved tightly (rtol 1e-10, a
hundredth of the absolute tolerances) each is within about 1e-8 N m of the exact torque (the 0.0005 N m scaled with
the tolerance), so they must agree to BOUND_NM: forty times that for the two step sequences, and still a thousand
times below the smallest change a probe makes (a few noise floors, at least 0.002 N m). A load that did not vanish
at strength 0, or a candidate that changed the base model's equations (a slot's law, a coordinate), would show far
above it.
"""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.diagnose.candidates import candidate_effects, diagnosis_model, strength_parameter
from parksteer.diagnose.problem import load_files
from parksteer.diagnose.replay import Replay
from parksteer.model.numeric.prescribed import solve
from parksteer.model.symbolic.components import resolve_effects
from parksteer.parameters import load_parameters

BOUND_NM = 1e-6
TIGHT = {"rtol": 1e-10, "atol_factor": 0.01}


@pytest.fixture(scope="module")
def measured(repo_root):
    params = load_parameters()
    record = load_files([str(repo_root / "data" / "measurements" / "example_unladen.csv")], params, None, None,
                        None)[0]
    base = resolve_effects(None)
    testable, _ = candidate_effects(base)
    return params, record, base, testable, diagnosis_model(base, testable, params)


def _torque(measured, effects, overrides=None) -> np.ndarray:
    params, record, *_ = measured
    replay = Replay(list(effects), record.case, record.surface, params, record.rack, record.replay_time_s)
    run, p = replay.parameter_vector(overrides or {})
    return solve(run, p, record.rack, record.replay_time_s, **TIGHT).torque_Nm


def test_the_diagnosis_model_holds_more_than_one_candidate(measured):
    """The point of it: several candidates are replayed in one model (else each would still need its own)."""
    _, _, base, _, host = measured
    assert len(host) - len(base) >= 2


def test_every_candidate_at_strength_zero_is_the_base_model(measured):
    _, _, base, _, host = measured
    difference = np.max(np.abs(_torque(measured, host) - _torque(measured, base)))
    assert difference < BOUND_NM, f"{difference:.3g} N m"


def test_one_candidate_at_its_probe_strength_is_its_own_model(measured):
    """Each hosted candidate at a tenth of its range (a probe's order), the others at 0, against the base model
    with that candidate alone: the same torque, and a change from the base model well above the bound (so the
    strength reaches the equations)."""
    _, _, base, testable, host = measured
    names = {e.name for e in host}
    base_torque = _torque(measured, base)
    for candidate in (c for c in testable if c.name in names):
        spec = strength_parameter(candidate)
        overrides = {spec.key: 0.1 * spec.upper}
        own = _torque(measured, sorted([*base, candidate], key=lambda e: e.name), overrides)
        shared = _torque(measured, host, overrides)
        difference = np.max(np.abs(shared - own))
        assert difference < BOUND_NM, f"{candidate.name}: {difference:.3g} N m"
        assert np.max(np.abs(own - base_torque)) > 1e3 * BOUND_NM, candidate.name
