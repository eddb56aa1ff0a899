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
above it. The handwheel angle, where a lash shows (the torque on a given rack does not see it), likewise to
BOUND_RAD: a thousand times below the smallest angle change a probe makes (a few floors of a 0.1 degree sensor
step, 0.0017 rad).
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
BOUND_RAD = 1e-6
TIGHT = {"rtol": 1e-10, "atol_factor": 0.01}


@pytest.fixture(scope="module")
def measured(repo_root):
    params = load_parameters()
    record = load_files([str(repo_root / "data" / "measurements" / "example_unladen.csv")], params, None, None,
                        None)[0]
    base = resolve_effects(None)
    testable, _ = candidate_effects(base)
    return params, record, base, testable, diagnosis_model(base, testable, params)


def _signals(measured, effects, overrides=None) -> np.ndarray:
    """The replayed handwheel torque (N m) and angle (rad) of the record, one after the other."""
    params, record, *_ = measured
    replay = Replay(list(effects), record.case, record.surface, params, record.rack, record.replay_time_s)
    run, p = replay.parameter_vector(overrides or {})
    solution = solve(run, p, record.rack, record.replay_time_s, outputs=True, **TIGHT)
    return solution.torque_Nm, solution.handwheel[:, 0]


def _differences(a, b) -> tuple[float, float]:
    return float(np.max(np.abs(a[0] - b[0]))), float(np.max(np.abs(a[1] - b[1])))


def test_the_diagnosis_model_holds_more_than_one_candidate(measured):
    """The point of it: several candidates are replayed in one model (else each would still need its own)."""
    _, _, base, _, host = measured
    assert len(host) - len(base) >= 2


def test_every_candidate_at_strength_zero_is_the_base_model(measured):
    _, _, base, _, host = measured
    torque, angle = _differences(_signals(measured, host), _signals(measured, base))
    assert torque < BOUND_NM and angle < BOUND_RAD, f"{torque:.3g} N m, {angle:.3g} rad"


def test_one_candidate_at_its_probe_strength_is_its_own_model(measured):
    """Each hosted candidate at a tenth of its range (a probe's order), the others at 0, against the base model
    with that candidate alone: the same torque and angle, and a change from the base model well above the bounds
    in one of them (so the strength reaches the equations)."""
    _, _, base, testable, host = measured
    names = {e.name for e in host}
    base_signals = _signals(measured, base)
    for candidate in (c for c in testable if c.name in names):
        spec = strength_parameter(candidate)
        overrides = {spec.key: 0.1 * spec.upper}
        own = _signals(measured, sorted([*base, candidate], key=lambda e: e.name), overrides)
        torque, angle = _differences(_signals(measured, host, overrides), own)
        assert torque < BOUND_NM and angle < BOUND_RAD, f"{candidate.name}: {torque:.3g} N m, {angle:.3g} rad"
        torque, angle = _differences(own, base_signals)
        assert torque > 1e3 * BOUND_NM or angle > 1e3 * BOUND_RAD, candidate.name
