"""Forward sensitivities of the prescribed-rack solve (parksteer.model.numeric.sensitivities): the handwheel torque's
derivatives with respect to the model's parameters, integrated by the compiled model beside its states.

The comparison with finite differences, made so that the difference quotient's own error is shown below the 1e-6
asked: both at the tightest integrator tolerances (rtol 3e-14, a hundred-thousandth of the replay's absolute
tolerances); the quotient is the Richardson extrapolation R(h) = (4 D(h/2) - D(h)) / 3 of central differences D
(error O(h^4)), on a ladder of steps h = 2e-2, 1e-2, ... 2.5e-3 of the parameter's value (of a radian or a unit
at zero). Too long a step leaves truncation (R falls 16-fold a halving: on the base model's surface grip 7.6e-5,
5.7e-6, 3.7e-7 of the largest derivative at h = 5e-3, 2.5e-3, 1.25e-3), too short a one the integrator's error over
the step (a brake fraction's quotient grows as 1/h: the solve's torque at these tolerances is reproducible to
about 2e-11 N m between neighbouring parameter values: TORQUE_PRECISION_NM). The first pair of
neighbours R(h), R(h/2) that agree to half the bar (plus that precision over the step) is taken, and the sensitivity
must agree with R(h/2) to the bar: 1e-6 of the derivative's largest value over the run (a pointwise ratio means
nothing where it crosses zero), plus 4 TORQUE_PRECISION_NM / h, which exceeds the 1e-6 only for parameters whose
derivative is below about 1e-4 N m per unit of a per-cent step. A parameter the torque does not depend on (the
lash, which only widens the column's twist) must have a zero sensitivity and quotients at the noise.
"""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.diagnose.candidates import default_diagnosis_models
from parksteer.errors import UsageError
from parksteer.measure.rack_spline import interpolate_rack
from parksteer.model.numeric.prescribed import solve
from parksteer.model.numeric.sensitivities import parameter_directions, solve_sensitivities
from parksteer.model.numeric.simulate import prepare

RTOL, ATOL_FACTOR = 3e-14, 1e-5
AGREEMENT = 1e-6
STEPS = (4e-2, 2e-2, 1e-2, 5e-3, 2.5e-3)  # of the parameter's value
TORQUE_PRECISION_NM = 2e-11
# The candidates' strengths where their derivatives are taken: inside each range, large enough to act.
STRENGTHS = {"ackermann.ackermann_fraction": 0.5, "braked_wheels.brake_fraction": 0.3,
             "column_friction.friction_torque": 2.0, "kingpin_friction.friction_radius": 0.01,
             "rack_damping.damping": 2000.0, "rack_lash.lash": 0.001, "rack_stiction.breakaway_excess": 300.0,
             "brush_patch.brush_fraction": 0.5}
# The calibrated values and the core's tyre and friction parameters, as the compiled vector holds them.
CORE_KEYS = ["tyre.carcass_torsional_stiffness", "steering.rack_friction_force", "derived.surface_grip",
             "steering.hooke_joint_angle", "steering.hooke_joint_phase", "tyre.radial_stiffness",
             "steering.friction_smoothing"]
MODELS = {"base": 0, "diagnosis": 1, "brush_patch": 2}
# The library's other manual effects, each added to the base model at a strength that acts (turn slip has none: it
# acts at its defaults; on this sweep its parameters leave the torque alone, zero sensitivities and quotients at the
# noise).
LIBRARY = {"carcass_hysteresis": {"carcass_hysteresis.stiffness_fraction": 0.5},
           "gear_efficiency": {"gear_efficiency.inefficiency": 0.1},
           "linkage_nonlinearity": {"linkage_nonlinearity.cubic_coefficient": 0.3},
           "rack_presliding": {"rack_presliding.force": 200.0},
           "rolling_resistance": {"rolling_resistance.coefficient": 0.015},
           "top_mount_windup": {"top_mount_windup.stiffness": 300.0},
           "turn_slip": {},
           "tyre_stribeck": {"tyre_stribeck.breakaway_excess": 0.2}}
# The gear's efficiency switches with the sign of its force, smoothed over 1 N of forces of kN: its solve is
# reproducible to about 1e-8 N m only (the surface grip's quotient error grows as 1/h below h = 3e-3 of the value,
# to 3e-4 of the derivative at 1e-5), so its quotients are trusted to that.
PRECISION_NM = {"gear_efficiency": 1e-8}


def sweep_rack():
    """A rack swept sinusoidally to 30 mm and back: a reversal at t = 1 s, where every smoothed friction law
    turns."""
    t = np.linspace(0.0, 4.0, 401)
    return interpolate_rack(t, 0.03 * np.sin(np.pi * t / 2.0))


TIMES = np.linspace(0.5, 1.5, 51)


@pytest.fixture(scope="module", params=list(MODELS))
def model_run(request, params):
    """A run of each diagnosis model (the base, the one holding every candidate but the brush patch, and the brush
    patch's), its candidates at the strengths of STRENGTHS, and the keys whose sensitivities are checked: the core's
    and every effect's own parameters in the vector."""
    effects = default_diagnosis_models(params)[MODELS[request.param]]
    run = prepare("unladen", effects=effects, params=params)
    p = run.p.copy()
    names = run.model.info["parameters"]
    for key, value in STRENGTHS.items():
        if key in names:
            p[run.parameter_index(key)] = value
    own = [name for name in names if any(name.startswith(f"{e.name}.") for e in effects)]
    return run, p, CORE_KEYS + [k for k in own if k not in CORE_KEYS]


def step_of(p, i: int, step: float) -> float:
    """The absolute step: `step` of the value, or of a unit at zero."""
    return step * abs(p[i]) if p[i] != 0.0 else step


@pytest.fixture(scope="module", params=list(LIBRARY))
def library_run(request, params):
    """A run of the base model with one more of the library's manual effects at the strength of LIBRARY, and the
    keys checked: the effect's own parameters, the rack's friction and the surface grip."""
    run = prepare("unladen", effects=f"+{request.param}", params=params)
    p = run.p.copy()
    for key, value in LIBRARY[request.param].items():
        p[run.parameter_index(key)] = value
    own = [name for name in run.model.info["parameters"] if name.startswith(f"{request.param}.")]
    return (run, p, own + ["steering.rack_friction_force", "derived.surface_grip"],
            PRECISION_NM.get(request.param, TORQUE_PRECISION_NM))


def central_difference(run, p, key: str, rack, step: float) -> np.ndarray:
    """d torque / d key by the central difference at `step` of the key's value (of a unit at zero)."""
    i = run.parameter_index(key)
    h = step_of(p, i, step)
    up, down = p.copy(), p.copy()
    up[i] += h
    down[i] -= h
    return (solve(run, up, rack, TIMES, rtol=RTOL, atol_factor=ATOL_FACTOR).torque_Nm
            - solve(run, down, rack, TIMES, rtol=RTOL, atol_factor=ATOL_FACTOR).torque_Nm) / (2.0 * h)


def checked_derivative(run, p, key: str, rack, precision: float = TORQUE_PRECISION_NM
                       ) -> tuple[np.ndarray | None, float, float]:
    """(R(h/2), its largest value, the noise allowance 4 precision / (h/2)) of the first pair of neighbouring steps
    of STEPS whose extrapolations agree to half of AGREEMENT of their largest value plus the allowance; (None, the
    largest |R| seen, 0) if none do."""
    i = run.parameter_index(key)
    differences = [central_difference(run, p, key, rack, STEPS[0])]
    extrapolated = []
    largest = 0.0
    for step in STEPS[1:]:
        differences.append(central_difference(run, p, key, rack, step))
        extrapolated.append((4.0 * differences[-1] - differences[-2]) / 3.0)
        largest = max(largest, float(np.max(np.abs(extrapolated[-1]))))
        if len(extrapolated) >= 2:
            scale = float(np.max(np.abs(extrapolated[-1])))
            noise = 4.0 * precision / step_of(p, i, step)
            if scale > noise and np.max(np.abs(extrapolated[-1] - extrapolated[-2])) <= 0.5 * AGREEMENT * scale + noise:
                return extrapolated[-1], scale, noise
    return None, largest, 0.0


def disagreements(run, p, keys, precision: float = TORQUE_PRECISION_NM) -> list[str]:
    """The keys whose sensitivities disagree with their checked difference quotients (see the module docstring)."""
    rack = sweep_rack()
    solution = solve_sensitivities(run, p, rack, TIMES, parameter_directions(run, keys), rtol=RTOL,
                                   atol_factor=ATOL_FACTOR)
    failures = []
    for k, key in enumerate(keys):
        sensitivity = solution.torque_sensitivities[:, k]
        expected, scale, noise = checked_derivative(run, p, key, rack, precision)
        if expected is None:
            i = run.parameter_index(key)
            if np.any(sensitivity != 0.0) or scale > 4.0 * precision / step_of(p, i, STEPS[-1]):
                failures.append(f"{key}: no quotient agrees with its neighbour (largest {scale:.3g}), "
                                f"sensitivity up to {np.max(np.abs(sensitivity)):.3g}")
            continue
        error = np.max(np.abs(sensitivity - expected))
        if error > AGREEMENT * scale + noise:
            failures.append(f"{key}: error {error:.3g} of {scale:.3g}")
    return failures


def test_sensitivities_agree_with_finite_differences(model_run):
    """The forward sensitivities (the sensitivity equations derived by sympy from the model's own expressions,
    integrated on the state's steps, from the statics' derivative by the implicit function theorem) are the
    derivatives of the solved torque: on each diagnosis model, for the calibrated values, the core's tyre and
    friction parameters and every effect's own parameters, they agree with difference quotients whose own error is
    shown below half of it (module docstring) to 1e-6 of each derivative's largest value (plus the replay's own
    precision over the step), at every sample including the first (the static start's). A parameter the torque does
    not depend on has a zero sensitivity and quotients at the noise."""
    failures = disagreements(*model_run)
    assert not failures, failures


def test_every_library_effect_has_sensitivities_that_agree(library_run):
    """The same agreement on each of the library's other manual effects added to the base model (pre-sliding with
    its bristle root's coordinate, hysteresis with its carcass state, the Stribeck tyre, turn slip, the top mount's
    windup, ...): its own parameters, the rack's friction and the surface grip, to 1e-6 as above (plus the gear
    efficiency's coarser precision over the step, PRECISION_NM)."""
    failures = disagreements(*library_run)
    assert not failures, failures


def test_sensitivities_leave_the_torque_unchanged(model_run):
    """The sensitivities stay out of the error control, so the state takes the same steps: the torque solved with
    them is the torque of the plain solve, byte for byte, at the replay's own tolerances."""
    run, p, keys = model_run
    rack = sweep_rack()
    with_sensitivities = solve_sensitivities(run, p, rack, TIMES, parameter_directions(run, keys[:3]))
    assert np.array_equal(with_sensitivities.torque_Nm, solve(run, p, rack, TIMES).torque_Nm)


@pytest.mark.parametrize("key", ["steering.rack_friction_force", "column_friction.friction_torque",
                                 "rack_damping.damping"])
def test_a_load_on_the_rack_or_column_alone_has_its_contribution_over_its_strength(params, key):
    """Closed form: a load that acts on the rack or the column alone and is linear in its strength (the rack's and
    the column's friction, the rack damper) moves no other coordinate when the rack is prescribed, so the torque's
    derivative by its strength is its contribution to the torque over the strength, at every instant (to 1e-12 of
    its largest value); and the column's stiffness, which carries the torque but does not set it, has none."""
    run = prepare("unladen", effects=default_diagnosis_models(params)[1], params=params)
    p = run.p.copy()
    for name, value in STRENGTHS.items():
        if name in run.model.info["parameters"]:
            p[run.parameter_index(name)] = value
    rack = sweep_rack()
    keys = [key, "steering.column_torsional_stiffness"]
    solution = solve_sensitivities(run, p, rack, TIMES, parameter_directions(run, keys))
    effect = key.split(".")[0] if not key.startswith("steering.") else "rack_friction"
    contribution = solve(run, p, rack, TIMES, outputs=True, handwheel=False).outputs[f"contrib_{effect}_Nm"]
    expected = contribution / p[run.parameter_index(key)]
    assert np.max(np.abs(expected)) > 0.0
    assert np.max(np.abs(solution.torque_sensitivities[:, 0] - expected)) <= 1e-12 * np.max(np.abs(expected))
    assert np.all(solution.torque_sensitivities[:, 1] == 0.0)


def test_bad_directions_are_refused(model_run):
    """A direction must name every parameter of the model's vector: a shorter one is refused, not read past."""
    run, p, _ = model_run
    with pytest.raises(ValueError, match="rows of"):
        solve_sensitivities(run, p, sweep_rack(), TIMES, np.ones((1, 3)))


def test_a_model_without_sensitivities_is_refused(model_run, monkeypatch):
    """An assisted model's drive depends on the torsion bar's torque, so it has no prescribed-rack sensitivities:
    a model that says so is refused with one line, before anything is integrated."""
    run, p, keys = model_run
    monkeypatch.setitem(run.model.info, "rack_drive", False)
    with pytest.raises(UsageError, match="no sensitivities"):
        solve_sensitivities(run, p, sweep_rack(), TIMES, parameter_directions(run, keys[:1]))
