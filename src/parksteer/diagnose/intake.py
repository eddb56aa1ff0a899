"""The diagnosis's one front door: what a caller asks (records, how to read them, the car, the model's effects, the
diagnosis's options) in, what :func:`parksteer.diagnose.select.diagnose` takes (the prepared files, the parameters,
the effects, the settings, the worker count) out, with every decision of method and every precondition made here.

Made here and nowhere else: the vehicle file's ``[assist]`` added to the effects (``with_assist``) or, left out,
warned about; the run's one speed read from the records' speed channel, and the rolling tyre's turn slip added for
a creeping car (:func:`with_record_speed`); the refusal of a record whose rack never reverses (no reversal to
calibrate the friction on); the torque-lag search only on a measured rack; the handwheel angle fitted only where a
file has one beside a measured rack; the settings from the options. The command line (``parksteer compare``,
``diagnose``, ``baseline``), the workflow's rule scripts, the benchmarks of experiments/ and the case study call
:func:`intake` before they diagnose, so that one record gives one diagnosis whichever door it came in by.

Bad input raises :class:`parksteer.errors.UsageError` in one line naming the file, the column and where it can, the
row (the command line prints it and exits with status 2).
"""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import UsageError
from ..parameters import DEFAULT_PATH, Parameters
from ..progress import note
from .settings import DEFAULT_SETTINGS, DiagnosisSettings

# A record's speed channel gives the run's one constant speed (the model has no time-varying speed): its middle 90 %
# must lie within this band (km/h), every file's median within it of the others', and a median below the standstill
# limit is standstill (the model as it was, bit for bit).
SPEED_BAND_KMH = 1.0
STANDSTILL_KMH = 0.1

# What each command needs a reversal for, in its refusal of a record whose rack never reverses.
NEEDS_REVERSAL = {"diagnose": "diagnose needs a cycle that turns back",
                  "baseline": "a baseline needs a cycle that turns back"}


@dataclass(frozen=True)
class Request:
    """What a caller asks. `files`: the records' paths (any format :func:`parksteer.measure.importers.load_record`
    reads); `params`: the car (:func:`car_parameters`); `effects`: the model's effects as a spec
    (``"+column_friction"``, None for the paper's five) or as a list of effects; `vehicle`: the vehicle file
    `params` were read from (its ``[assist]`` for `with_assist`, and named in messages); `case`, `surface`,
    `channel_map`: how the files are read (:func:`parksteer.diagnose.problem.load_files`); `settings`: the method's,
    with `angle` (fit the handwheel angle beside the torque) and `torque_lag` (search the torque channel's lag
    behind the rack) turned on over them; `jobs`: worker processes (None: the CPUs available); `command`: what the
    request serves (``compare``, ``diagnose``, ``baseline``), which says what is checked and names the command in a
    warning."""

    files: Sequence[str | Path]
    params: Parameters
    effects: str | Sequence | None = None
    vehicle: str | Path | None = None
    with_assist: bool = False
    case: str | None = None
    surface: str | None = None
    channel_map: object = None
    settings: DiagnosisSettings = DEFAULT_SETTINGS
    angle: bool = False
    torque_lag: bool = False
    jobs: int | None = 1
    command: str = "diagnose"


@dataclass(frozen=True)
class Intake:
    """What :func:`intake` made of a :class:`Request`: the prepared files
    (:class:`parksteer.diagnose.problem.FileData`), the parameters at the records' speed, the effects, the settings
    and the worker count a diagnosis takes."""

    files: list = field(repr=False)
    params: Parameters = field(repr=False)
    effects: list
    settings: DiagnosisSettings
    workers: int

    def diagnose(self, **options):
        """:func:`parksteer.diagnose.select.diagnose` of this intake (`options`: its further keywords, e.g.
        ``quiet``, ``baseline``, ``registry``)."""
        from .select import diagnose

        return diagnose(self.files, self.params, self.effects, settings=self.settings, workers=self.workers,
                        **options)


def car_parameters(parameters: str | Path = DEFAULT_PATH, vehicle: str | Path | None = None) -> Parameters:
    """The car's parameters: the parameter file, with the vehicle file's car over it when given (its ``[assist]``
    checked), knowing the installed effects' quantities."""
    from ..model.symbolic.components import with_effect_quantities
    from ..parameters import load_parameters

    params = with_effect_quantities(load_parameters(parameters))
    if vehicle is None:
        return params
    from ..model.numeric.assist import check_assist
    from ..vehicle import load_vehicle

    params = load_vehicle(vehicle, params)
    check_assist(params)
    return params


def intake(request: Request) -> Intake:
    """The files, parameters, effects, settings and worker count of `request` (module docstring), or a one-line
    :class:`parksteer.errors.UsageError`."""
    params = request.params
    effects = model_effects(request)
    files = load_records(request, params, effects)
    params, effects = with_record_speed(params, effects, files)
    if request.command in NEEDS_REVERSAL:
        check_reversals(files, NEEDS_REVERSAL[request.command])
    if request.jobs is not None and request.jobs < 1:
        raise UsageError(f"--jobs {request.jobs}: give at least 1")
    from .parallel import available_workers

    workers = request.jobs if request.jobs is not None else available_workers()
    settings = request.settings
    if request.torque_lag:
        settings = dataclasses.replace(settings, torque_lag_fitted=True)
    if request.angle:
        settings = dataclasses.replace(settings, use_handwheel_angle=True)
    check_torque_lag(files, settings)
    check_angle(files, settings)
    return Intake(files, params, effects, settings, workers)


def vehicle_study(items, parameters: str | Path, vehicle: str | Path, options: dict, **request) -> Intake:
    """The vehicle study's records taken in as ``parksteer compare/diagnose --vehicle`` takes them: `items` files, or
    a folder whose .csv files are the records (the synthetic set), read with the workflow's import options
    (``case``, ``surface``, ``map_file``); `request` the rest of the :class:`Request`."""
    from ..measure.channel_map import channel_map_from_options

    files = []
    for item in [items] if isinstance(items, str | Path) else list(items):
        path = Path(item)
        files += sorted(str(p) for p in path.iterdir() if p.suffix == ".csv") if path.is_dir() else [str(item)]
    return intake(Request(files, car_parameters(parameters, vehicle), vehicle=vehicle, case=options["case"],
                          surface=options["surface"], channel_map=channel_map_from_options(None, options["map_file"]),
                          **request))


def load_records(request: Request, params: Parameters, effects) -> list:
    """The request's files read and prepared for the model of `effects` (its torsion bar, if assisted)."""
    from .problem import load_files

    return load_files(list(request.files), params, request.case, request.surface, request.channel_map,
                      assist_of_effects(effects))


def model_effects(request: Request) -> list:
    """The model's effects: the request's, with the vehicle file's ``[assist]`` added when `with_assist`."""
    from ..model.symbolic.components import resolve_effects

    given = request.effects
    if not request.with_assist:
        effects = given if _effect_list(given) else resolve_effects(given)
        _warn_unused_assist(request, effects)
        return effects
    if request.vehicle is None:
        raise UsageError("--with-assist needs --vehicle FILE (the assist is the vehicle file's [assist])")
    from ..model.numeric.assist import check_assist, effects_with_assist

    if check_assist(request.params) is None:
        raise UsageError(f"--with-assist: {request.vehicle} has no [assist] section")
    return resolve_effects(effects_with_assist(given, request.params))


def _effect_list(effects) -> bool:
    from ..model.symbolic.components import Effect

    return isinstance(effects, (list, tuple)) and all(isinstance(e, Effect) for e in effects)


def _warn_unused_assist(request: Request, effects) -> None:
    """One line on stderr when the vehicle file has an [assist] the run leaves out: the record is then fitted as
    the car without assistance, its torque as the whole steering torque, which a record of the car with its
    assist working (a bus log's torsion-bar torque, say) is not."""
    if request.vehicle is None or assist_of_effects(effects) is not None:
        return
    from ..vehicle import assist_of

    if assist_of(request.params) is not None:
        print(f"parksteer {request.command}: warning: {request.vehicle} has an [assist] section, left out: the "
              "records are fitted as the car without assistance; if they were logged with the assist working, add "
              "--with-assist", file=sys.stderr)


def assist_of_effects(effects) -> str | None:
    """The name of the power assist among `effects`, if any."""
    from ..model.symbolic.components import power_assist_of

    assist = power_assist_of(effects)
    return None if assist is None else assist.name


def _where(f) -> str:
    return str(f.measurement.path or f.label)


def with_record_speed(params: Parameters, effects, files):
    """(params, effects) of a run at the records' vehicle speed, from their speed channel (``vehicle_speed_mps``):
    unchanged at standstill or without the channel, else the rolling tyre's turn slip added at the median speed
    (as ``simulate --speed-kmh``); a speed that varies, or differs between files, is refused in one line."""
    import numpy as np

    from ..measure.channel_map import SPEED
    from ..model.symbolic.components import discover_effects
    from ..vehicle import MAX_CREEPING_SPEED_KMH, creeping_overrides

    logged = [f for f in files if SPEED in f.measurement.columns]
    if not logged:
        return params, effects
    if len(logged) != len(files):
        missing = next(f for f in files if SPEED not in f.measurement.columns)
        raise UsageError(f"{_where(missing)}: no column {SPEED!r} while {_where(logged[0])} has one; a run has one "
                         "speed, give it in every file or in none")
    medians = []
    for f in logged:
        kmh = np.abs(np.asarray(f.measurement.columns[SPEED], dtype=float)) * 3.6
        low, middle, high = np.percentile(kmh, [5.0, 50.0, 95.0])
        where = f"{_where(f)}: column {SPEED!r}"
        if high - low > SPEED_BAND_KMH:
            raise UsageError(f"{where}: the speed varies from {low:.2f} to {high:.2f} km/h (middle 90 %); the model "
                             f"takes one constant speed a run (within {SPEED_BAND_KMH:g} km/h): cut the record where "
                             "the car creeps steadily")
        if middle > MAX_CREEPING_SPEED_KMH:
            raise UsageError(f"{where}: {middle:.1f} km/h is beyond parking and creeping (0-"
                             f"{MAX_CREEPING_SPEED_KMH:g} km/h)")
        medians.append((middle, f))
    (slow, f_slow), (fast, f_fast) = min(medians, key=lambda m: m[0]), max(medians, key=lambda m: m[0])
    if fast - slow > SPEED_BAND_KMH:
        raise UsageError(f"{_where(f_fast)}: column {SPEED!r}: {fast:.2f} km/h against {slow:.2f} km/h in "
                         f"{_where(f_slow)}; diagnose files of one speed together")
    speed_kmh = float(np.median([m for m, _ in medians]))
    if speed_kmh < STANDSTILL_KMH:
        return params, effects
    if all(e.name != "turn_slip" for e in effects):
        effects = sorted([*effects, discover_effects()["turn_slip"]], key=lambda e: e.name)
    note(f"vehicle speed from the records' {SPEED}: {speed_kmh:.2f} km/h, constant over the run (the rolling tyre's "
         "turn slip added)")
    return params.with_overrides(creeping_overrides(speed_kmh)), effects


def check_reversals(files, needs: str) -> None:
    """Refuse a record whose rack never reverses: the friction is calibrated on the reversals (`needs`: what for)."""
    for f in files:
        if len(f.phases.reversal_times_s) == 0:
            raise UsageError(f"{f.measurement.path}: column 'rack_m': the rack never reverses, so the record holds "
                             f"no reversal to calibrate the friction on; {needs}")


def check_torque_lag(files, settings: DiagnosisSettings) -> None:
    """A torque lag is searched behind a measured rack only: a rack derived from the angle and the torque has none."""
    if not settings.torque_lag_fitted:
        return
    derived = next((f for f in files if "rack_derived" in f.measurement.metadata), None)
    if derived is not None:
        raise UsageError(f"{_where(derived)}: --torque-lag needs a measured rack channel (this file's rack is "
                         "derived from the angle and the torque itself, so it has no lag behind the torque to find)")


def check_angle(files, settings: DiagnosisSettings) -> None:
    """The handwheel angle is fitted where a file has one beside a measured rack: refuse a run where none has, say
    which files fit it."""
    if not settings.use_handwheel_angle:
        return
    from ..measure.channel_map import ANGLE

    with_angle = [f.label for f in files if f.angle_rad is not None]
    if not with_angle:
        f = files[0]
        why = "its rack is derived from the angle" if ANGLE in f.measurement.columns else f"no column {ANGLE!r}"
        raise UsageError(f"{_where(f)}: --angle needs a handwheel angle beside a measured rack ({why})")
    note(f"handwheel angle fitted beside the torque in {len(with_angle)} of {len(files)} file(s): "
         + ", ".join(with_angle))
