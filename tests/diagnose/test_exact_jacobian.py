"""The fits' exact Jacobian (parksteer.diagnose.fitting.exact_jacobian, DiagnosisSettings.exact_jacobian): the
replays' forward sensitivities in the fit's own units, and a calibration on it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from parksteer.diagnose.calibrate import calibrate, calibration_parameters
from parksteer.diagnose.engine import ReplayEngine
from parksteer.diagnose.fitting import _predict, exact_jacobian
from parksteer.diagnose.problem import load_files
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.diagnose.stages import STAGES

STEP = 3e-3  # in theta, for the central differences
MOVED = {"tyre.friction_coefficient": 0.70, "steering.rack_friction_force": 650.0,
         "tyre.carcass_torsional_stiffness": 800.0}


@pytest.fixture(scope="module")
def problem_and_effects(written, params):
    """A null record of a car whose calibrated values are moved off the parameter file's, its replay uncertainty
    estimated (the diagnosis's first stage), and the base model's effects."""
    paths, _ = written("exact_jacobian", kind="null", base_overrides=MOVED)
    diagnosis = diagnose(load_files(paths, params), params, stages=STAGES[:2])
    return diagnosis.problem, list(diagnosis.calibration.effects)


def test_exact_jacobian_is_the_central_difference_of_the_weighted_model(problem_and_effects):
    """The exact Jacobian is d(model / sigma)/d(theta) in the fit's variables: through the log transform of each
    calibrated value and, for the tyre's friction coefficient, through the run's preparation into the vector's surface
    grip. Central differences of the replayed, weighted model at a step of 3e-3 in theta agree with it to 2 % RMS of
    each column, and the column's least-squares ratio to it is 1 within 0.5 %. Measured: the RMS difference falls
    as the step squared from 3e-2 (5 % and 8.5 % for the friction coefficient and the carcass stiffness) to 3e-3
    (0.3 % and 0.5 %), below which the replay's own tolerance over the step takes over (1e-3: 0.8 % and 1.1 %, the
    rack friction's 4 %); a wrong transform or direction is a factor of the value or of a unit, far outside."""
    problem, effects = problem_and_effects
    engine = ReplayEngine(1)
    parameters = calibration_parameters(engine, problem, effects)
    theta = np.zeros(len(parameters))
    exact = exact_jacobian(engine, problem, effects, parameters, theta, {})
    assert exact is not None and exact.shape[1] == len(parameters) == 3
    for k, parameter in enumerate(parameters):
        step = STEP
        up, down = theta.copy(), theta.copy()
        up[k] += step
        down[k] -= step
        central = (problem.scale(_predict(engine, problem, effects, parameters, up, {})[0])
                   - problem.scale(_predict(engine, problem, effects, parameters, down, {})[0])) / (2.0 * step)
        scale = np.sqrt(np.mean(central ** 2))
        assert scale > 0.0
        assert np.sqrt(np.mean((exact[:, k] - central) ** 2)) <= 0.02 * scale, parameter.key
        assert abs(np.dot(exact[:, k], central) / np.dot(exact[:, k], exact[:, k]) - 1.0) <= 0.005, parameter.key


def test_calibration_on_exact_jacobians_finds_the_same_values(problem_and_effects):
    """Levenberg-Marquardt and the polish on exact Jacobians and on finite differences (Broyden's update between
    fresh ones in both) minimise the same weighted residual: their calibrated values agree within a tenth of each
    value's standard error, and the exact one recovers the moved car's values within their 95 % intervals."""
    problem, effects = problem_and_effects
    plain = calibrate(ReplayEngine(1), problem, effects)
    exact = calibrate(ReplayEngine(1), problem, effects, settings=replace(DEFAULT_SETTINGS, exact_jacobian=True))
    intervals = plain.intervals(problem)
    for key, value in exact.values.items():
        half = (intervals[key]["ci95"][1] - intervals[key]["ci95"][0]) / 2.0
        assert abs(value - plain.values[key]) <= 0.1 * intervals[key]["standard_error"], key
        assert abs(value - MOVED[key]) <= half, key
