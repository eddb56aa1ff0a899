"""Diagnose: calibrate, rank the candidates, refit the best, choose, and say what would separate them.

:func:`diagnose` runs the stages of :data:`parksteer.diagnose.stages.STAGES` in order on a frozen
:class:`parksteer.diagnose.state.DiagnosisState`: the files replayed through the base model with each sample's
replay uncertainty (:mod:`parksteer.diagnose.problem`); the base model's uncertain parameters calibrated to the
optimum (:mod:`parksteer.diagnose.calibrate`, :func:`parksteer.diagnose.fitting.polish`); every candidate not in
the model scored at the calibrated model (:mod:`parksteer.diagnose.candidates`); the best-scored few refitted in the
full nonlinear model; the comparison by the BIC over the effective sample size, only a candidate whose fitted
strength is above 0 heading it (:func:`parksteer.diagnose.stages.select.may_headline`); the verdict ``missing``,
``adequate`` or ``unexplained``; for candidates within ``BIC_INDISTINGUISHABLE`` of the best, and for one
``confounded`` with the calibrated parameters, the uncovered condition that would separate them
(:func:`parksteer.diagnose.stages.confound.confound_tests`). With ``torque_lag_fitted``, each file's torque lag is
searched after the calibration and again with the named effect (:mod:`parksteer.diagnose.stages.torque_lag`). The
stages' table and the verdict's rules: docs/diagnosis.md.
"""

from __future__ import annotations

from dataclasses import replace

from ..errors import UsageError
from ..model.codegen.cache import finish_builds, start_builds
from ..model.symbolic.components import (Effect, discover_effects, power_assist_of, resolve_effects,
                                          with_effect_quantities)
from ..parameters import Parameters
from .candidates import candidate_effects, models_to_build, replay_models
from .compare import check_torque_sensors
from .parallel import Progress, signals_held
from .engine import ReplayEngine
from .problem import FileData, Problem
from .settings import DEFAULT_SETTINGS, DiagnosisSettings
from .stages import STAGES, run_table
from .stages.user_effect import with_user_effect_stage
from .state import Diagnosis, DiagnosisState, frozen_mapping

__all__ = ["Diagnosis", "diagnose"]


def diagnose(files: list[FileData], params: Parameters, effects=None, registry: dict[str, Effect] | None = None,
             strengths: dict[str, float] | None = None, start: dict[str, float] | None = None,
             settings: DiagnosisSettings = DEFAULT_SETTINGS, workers: int = 1, quiet: bool = True,
             stages=STAGES, baseline=None) -> Diagnosis:
    """Calibrate, rank every candidate outside the model, refit the best, give the verdict (module docstring).

    `settings` are the method's (:mod:`parksteer.diagnose.settings`; by default the documented ones).

    `strengths` ({"effect.param": finite-difference step}) are strengths of effects already
    added to the model, calibrated with the base parameters (from `start`, e.g. an earlier fit).

    `workers` > 1 replays independent runs side by side (:mod:`parksteer.diagnose.parallel`; the
    result is the same); unless `quiet`, each step says on stderr where it is. `stages` is the table run
    (:data:`parksteer.diagnose.stages.STAGES`).

    `baseline` (a :class:`parksteer.diagnose.baseline.Baseline`): the records are judged against the car's healthy
    ones (:mod:`parksteer.diagnose.baseline`): the model with the baseline's form, its strengths held, the calibration
    from the baseline's values, the thresholds of "as the baseline"; the result's ``outputs["relative_to"]`` names it.

    Nothing passed in is changed: the files are copied (whether each fits its angle: where it has one beside a
    measured rack, if the settings ask), and what the stages derive for them goes into further copies.
    """
    base = effects if isinstance(effects, list) and all(isinstance(e, Effect) for e in effects) \
        else resolve_effects(effects)
    params = with_effect_quantities(params, base)  # a value or an override of an effect's own quantity is known
    held = None
    if baseline is not None:
        baseline.check(params, base)
        params, base = baseline.parameters(params), baseline.model(base, registry)
        start, held = {**baseline.start, **(start or {})}, baseline.held
    # An assisted car's record: its motor channel fitted beside the torsion-bar torque (settings.use_motor_channel);
    # its handwheel angle is not replayed (parksteer.diagnose.replay).
    assisted = power_assist_of(base) is not None
    check_torque_sensors(files, assisted)
    if assisted and settings.use_handwheel_angle and any(f.angle_rad is not None for f in files):
        raise UsageError("--angle: the handwheel angle of an assisted car is not replayed; diagnose its torsion-bar "
                         "torque with the motor channel instead")
    copies = [replace(f, uses_angle=settings.use_handwheel_angle and f.angle_rad is not None,
                      replay_uncertainty_rad=None, replay_draws_rad=None,
                      uses_motor=assisted and settings.use_motor_channel and f.motor is not None,
                      replay_uncertainty_motor=None, replay_draws_motor=None) for f in files]
    problem = Problem(copies, params, angle_offset_fitted=settings.angle_offset_fitted)
    table = with_user_effect_stage(tuple(stages), base)
    if baseline is not None:  # each held calibrated value a candidate (before settings_for holds them)
        table = baseline.table(tuple(stages), settings)
        settings = baseline.threshold.settings_for(settings, problem.n)
    progress = Progress(quiet)
    registry = registry if registry is not None else discover_effects()
    # with a user's effect that declares free strengths, the error without it and with it (stages/user_effect.py)
    state = DiagnosisState(settings, problem, tuple(base), frozen_mapping(registry),
                           None if strengths is None else frozen_mapping(strengths),
                           None if start is None else frozen_mapping(start), progress,
                           table,
                           held=None if held is None else frozen_mapping(held))
    testable, _ = candidate_effects(base, registry)
    # The models the candidates replay in are built in the background while the base model's stages run (the base
    # model itself is built, if missing, when first replayed).
    builders = start_builds(models_to_build(base, testable, params)[1:], workers)
    # the workers hold every effect a stage may replay: one loaded from a file (the model's, or a candidate named in
    # the environment) among them
    engine = ReplayEngine(workers, hosts=replay_models(base, testable, params), effects=(*base, *registry.values()))
    try:
        state = run_table(state, engine)
        if baseline is not None:  # after the table: a stage that runs it again starts from nothing found
            state = state.with_output("relative_to", baseline.relative_to())
    except BaseException:  # an interrupt or an error: nothing still running is waited for
        engine.terminate()
        with signals_held():
            for builder in builders:
                builder.terminate()
            finish_builds(builders)
        raise
    finally:
        engine.close()
        finish_builds(builders)
    progress(f"verdict: {state.verdict}" + (f" {state.best}" if state.verdict == "missing" else "")
             + f" ({engine.evaluations} replays)")
    return state.result(engine.evaluations)
