"""``parksteer compare`` and ``parksteer diagnose``: the model against measurement files."""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

from ..names import SURFACES
from ..errors import UsageError
from ..parameters import DEFAULT_PATH
from ..progress import note
from . import add_quiet_option, check_writable
from .baseline import RecordOptions, baseline_of, register_baseline
from .vehicle import add_vehicle_option, parameters_of


def _common(p, outputs: bool = True) -> None:
    p.add_argument("files", nargs="+", metavar="FILE",
                   help="measurement files: native CSV (data/measurements/README.md), a logger's CSV, ASAM MDF or a raw CAN "
                        "log with --bus/--dbc")
    p.add_argument("--case", default=None, help="Table B1 case for every file (default: each file's own)")
    p.add_argument("--surface", choices=tuple(SURFACES), default=None,
                   help="the surface of files that do not state one")
    add_import_options(p)
    p.add_argument("--effects", default=None,
                   help="effects spec of the model, e.g. --effects=+column_friction or --effects=+path/to/effect.py "
                        "(a leading - needs no =; default: the paper's five)")
    p.add_argument("--parameters", default=str(DEFAULT_PATH), help="parameter file (default: the packaged parksteer/data/parameters.toml)")
    add_vehicle_option(p)
    p.add_argument("--with-assist", action="store_true",
                   help="with --vehicle: the car with its [assist]: the record's torque is the torsion bar's, replayed "
                        "through the boost law, and a motor current or torque channel is fitted beside it")
    if outputs:
        p.add_argument("--json", action="store_true", help="print the result as JSON on stdout")
        p.add_argument("--plot", default=None, metavar="OUT.svg", help="write a figure")


def add_import_options(p) -> None:
    """--map and --map-file: how a logger's channels become the native columns (parksteer.measure.importers)."""
    p.add_argument("--map", default=None, metavar="'SRC[unit]=COLUMN,...'",
                   help="channel map, e.g. --map 'RackPos[mm]=rack_m,SteerTorque[N*m]=handwheel_torque_Nm,"
                        "SWA[deg]=handwheel_angle_rad' (units converted with pint; '=-column' negates a channel)")
    p.add_argument("--map-file", default=None, metavar="MAP.txt",
                   help="the same channel map in a file, one 'SRC[unit]=COLUMN' per line, '#' comments")
    # A raw CAN log (candump, ASC, BLF, TRC, MDF4 bus logging): the DBC and its signals (docs/bus.md)
    p.add_argument("--bus", default=None, metavar="NAME",
                   help="a car's bus: its DBC and ready channel map (parksteer/data/buses/NAME.toml, e.g. vw_mqb); "
                        "--map entries replace the ready map's for their column")
    p.add_argument("--dbc", default=None, metavar="CAR.dbc",
                   help="decode a raw CAN log with this DBC; --map names the signals, e.g. "
                        "'LH_EPS_03.EPS_Lenkmoment[cN*m]=-handwheel_torque_Nm;sign=LH_EPS_03.EPS_VZ_Lenkmoment'")


def channel_map_of(args):
    """The channel map of --map and --map-file (None when neither is given); with --bus or --dbc, one that carries
    the bus its signals are decoded with."""
    from ..measure.importers import channel_map_from_options

    if getattr(args, "bus", None) is not None or getattr(args, "dbc", None) is not None:
        from ..measure.bus import bus_channel_map

        return bus_channel_map(args.bus, args.dbc, args.map, args.map_file)
    return channel_map_from_options(args.map, args.map_file)


def register(sub) -> None:
    p = sub.add_parser("compare", help="replay measured rack motion through the model; error by phase and noise floor")
    _common(p)
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a quantity by its key, e.g. tyre.tyre_pressure=180000 or rack_lash.lash=0.0002 (keys: `parksteer effects`, the parameter file; case.<name> for the case; repeatable)")
    add_quiet_option(p)
    p.set_defaults(func=_compare)

    p = sub.add_parser("diagnose", help="calibrate the model, rank the candidate effects it lacks, give a verdict")
    _common(p)
    p.add_argument("--report", default=None, metavar="OUT.md", help="write a readable report (markdown)")
    p.add_argument("--html", default=None, metavar="OUT.html",
                   help="write one self-contained HTML page: overlay, residual by phase, fitted values, ranking")
    p.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="replays run side by side on N processes (default: the CPUs available; same result)")
    add_quiet_option(p)
    p.add_argument("--angle", action="store_true",
                   help="fit the measured handwheel angle beside the torque, in files that have one beside a measured "
                        "rack (the column stiffness and Hooke joint phase are then calibrated, a rack lash observable)")
    p.add_argument("--torque-lag", action="store_true",
                   help="search each file for a lag of the torque channel behind the rack channel (up to 40 ms) and "
                        "replay the model at the instants the torque was sampled (for a logger known to delay it)")
    p.add_argument("--suggest-effect", default=None, metavar="OUT.py",
                   help="when the verdict is unexplained, write the effect the residual's signature points to as a "
                        "user-effect file (its strengths fitted with the calibrated parameters; pass it back with "
                        "--effects=+OUT.py); no file when the verdict is adequate or names a candidate")
    p.set_defaults(func=_diagnose)
    register_baseline(sub, RECORDS, diagnose=p)


def _check_outputs(args) -> None:
    if getattr(args, "suggest_effect", None) is not None and not args.suggest_effect.endswith(".py"):
        raise UsageError(f"--suggest-effect {args.suggest_effect}: the effect is a Python module; name it .py")
    for option in ("plot", "report", "html", "suggest_effect"):
        value = getattr(args, option, None)
        option = option.replace("_", "-")
        if value is not None:
            if Path(value).is_dir():
                raise UsageError(f"--{option} {value}: is a directory; name a file to write")
            parent = Path(value).resolve().parent
            if parent.exists() and not parent.is_dir():
                raise UsageError(f"--{option} {value}: {parent} is a file, not a folder")
            if not parent.is_dir():
                raise UsageError(f"--{option} {value}: folder {parent} does not exist")
            _check_writable(option, value, parent)
    if getattr(args, "plot", None) is not None and not args.plot.endswith(".svg"):
        raise UsageError(f"--plot {args.plot}: the figure is written as SVG; name it .svg")


def _check_writable(option: str, value: str, folder: Path) -> None:
    """:func:`parksteer.commands.check_writable` of the option named without its dashes (``out``)."""
    check_writable(f"--{option}", value, folder)


def _print_json(result: dict) -> None:
    json.dump(result, sys.stdout, indent=1, allow_nan=False)
    sys.stdout.write("\n")


def effects_of(args, params) -> list:
    """The model's effects: --effects, with the vehicle file's [assist] added under --with-assist."""
    from ..model.symbolic.components import resolve_effects

    if not getattr(args, "with_assist", False):
        effects = resolve_effects(args.effects)
        _warn_unused_assist(args, params, effects)
        return _by_reference(effects)
    if args.vehicle is None:
        raise UsageError("--with-assist needs --vehicle FILE (the assist is the vehicle file's [assist])")
    from ..model.numeric.assist import check_assist, effects_with_assist

    if check_assist(params) is None:
        raise UsageError(f"--with-assist: {args.vehicle} has no [assist] section")
    return _by_reference(resolve_effects(effects_with_assist(args.effects, params)))


def _by_reference(effects: list) -> list:
    """`effects`, each one's class findable by its module's name before any worker process forks
    (:func:`parksteer.diagnose.parallel.by_reference`)."""
    from ..diagnose.parallel import by_reference

    return by_reference(effects)


def _warn_unused_assist(args, params, effects) -> None:
    """One line on stderr when the vehicle file has an [assist] the run leaves out: the record is then fitted as
    the car without assistance, its torque as the whole steering torque, which a record of the car with its
    assist working (a bus log's torsion-bar torque, say) is not."""
    if getattr(args, "vehicle", None) is None or assist_of_effects(effects) is not None:
        return
    from ..vehicle import assist_of

    if assist_of(params) is not None:
        print(f"parksteer {args.command}: warning: {args.vehicle} has an [assist] section, left out: the records "
              "are fitted as the car without assistance; if they were logged with the assist working, add "
              "--with-assist", file=sys.stderr)


# A record's speed channel gives the run's one constant speed (the model has no time-varying speed): its middle 90 %
# must lie within this band (km/h), every file's median within it of the others', and a median below the standstill
# limit is standstill (the model as it was, bit for bit).
SPEED_BAND_KMH = 1.0
STANDSTILL_KMH = 0.1


def with_record_speed(params, effects, files):
    """(params, effects) of a run at the records' vehicle speed, from their speed channel (``vehicle_speed_mps``):
    unchanged at standstill or without the channel, else the rolling tyre's turn slip added at the median speed
    (as ``simulate --speed-kmh``); a speed that varies, or differs between files, is refused in one line."""
    import numpy as np

    from ..measure.importers import SPEED
    from ..model.symbolic.components import discover_effects
    from ..vehicle import MAX_CREEPING_SPEED_KMH, creeping_overrides

    logged = [f for f in files if SPEED in f.measurement.columns]
    if not logged:
        return params, effects
    if len(logged) != len(files):
        missing = next(f for f in files if SPEED not in f.measurement.columns)
        raise UsageError(f"{missing.measurement.path or missing.label}: no column {SPEED!r} while "
                         f"{logged[0].measurement.path or logged[0].label} has one; a run has one speed, give it in "
                         "every file or in none")
    medians = []
    for f in logged:
        kmh = np.abs(np.asarray(f.measurement.columns[SPEED], dtype=float)) * 3.6
        low, middle, high = np.percentile(kmh, [5.0, 50.0, 95.0])
        where = f"{f.measurement.path or f.label}: column {SPEED!r}"
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
        raise UsageError(f"{f_fast.measurement.path or f_fast.label}: column {SPEED!r}: {fast:.2f} km/h against "
                         f"{slow:.2f} km/h in {f_slow.measurement.path or f_slow.label}; diagnose files of one speed "
                         "together")
    speed_kmh = float(np.median([m for m, _ in medians]))
    if speed_kmh < STANDSTILL_KMH:
        return params, effects
    if all(e.name != "turn_slip" for e in effects):
        effects = sorted([*effects, discover_effects()["turn_slip"]], key=lambda e: e.name)
    note(f"vehicle speed from the records' {SPEED}: {speed_kmh:.2f} km/h, constant over the run (the rolling tyre's "
         "turn slip added)")
    return params.with_overrides(creeping_overrides(speed_kmh)), effects


def assist_of_effects(effects) -> str | None:
    """The name of the power assist among `effects`, if any."""
    from ..model.symbolic.components import power_assist_of

    assist = power_assist_of(effects)
    return None if assist is None else assist.name


def _compare(args) -> int:
    from ..diagnose.compare import compare_files
    from ..diagnose.problem import load_files
    from ..model.numeric.values import parse_overrides

    _check_outputs(args)
    overrides = parse_overrides(args.overrides)
    params = parameters_of(args)
    effects = effects_of(args, params)
    files = load_files(args.files, params, args.case, args.surface, channel_map_of(args), assist_of_effects(effects))
    params, effects = with_record_speed(params, effects, files)
    result = compare_files(files, params, effects, overrides)
    summary = result.as_dict()
    if args.plot:
        from ..figures.diagnose import compare_figure

        compare_figure(result, args.plot)
    if args.json:
        _print_json(summary)
    else:
        for key, e in summary.get("fitted", {}).items():  # a user's free strengths, fitted with the calibration
            ci = e["ci95"]
            print(f"fitted {key} = {e['value']:.4g} {e['unit']}"
                  + (f" (95 %: {ci[0]:.4g} to {ci[1]:.4g})" if ci else ""))
        for f in summary["files"]:
            print(f"{f['file']} ({f['case']}, {f['surface']}): RMS {f['overall']['rms']:.3f} N m, "
                  f"peak {f['overall']['peak']:.3f} N m, weighted RMS {f['weighted_rms_Nm']:.3f} N m, "
                  f"noise floor {f['noise_floor']['total_rms']:.3f} N m")
            for phase, stats in f["by_phase"].items():
                print(f"  {phase:<13} RMS {stats['rms']:.3f} N m over {stats['samples']} samples")
            if "motor" in f:
                unit = "A" if f["motor"]["column"] == "motor_current_A" else "N m"
                print(f"  motor channel {f['motor']['column']}: RMS {f['motor']['rms']:.3f} {unit}, noise floor "
                      f"{f['motor']['noise_floor']['total_rms']:.3f} {unit}")
    return 0


def _diagnose(args) -> int:
    from ..diagnose.problem import load_files
    from ..reporting.report import diagnosis_dict
    from ..reporting.pages import markdown_report, write_markdown
    from ..measure.importers import ANGLE
    from ..diagnose.select import diagnose
    from ..diagnose.settings import DEFAULT_SETTINGS

    _check_outputs(args)
    if not (args.json or args.report or args.plot or args.html or args.suggest_effect):
        raise UsageError("say where the result goes: --json, --report OUT.md, --html OUT.html, --plot OUT.svg and/or "
                         "--suggest-effect OUT.py")
    params = parameters_of(args)
    effects = effects_of(args, params)
    files = load_files(args.files, params, args.case, args.surface, channel_map_of(args), assist_of_effects(effects))
    params, effects = with_record_speed(params, effects, files)
    for f in files:
        if len(f.phases.reversal_times_s) == 0:
            raise UsageError(f"{f.measurement.path}: column 'rack_m': the rack never reverses, so the record holds "
                             "no reversal to calibrate the friction on; diagnose needs a cycle that turns back")
    from ..diagnose.parallel import available_workers

    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: give at least 1")
    workers = args.jobs if args.jobs is not None else available_workers()
    settings = DEFAULT_SETTINGS
    if args.torque_lag:
        derived = next((f for f in files if "rack_derived" in f.measurement.metadata), None)
        if derived is not None:
            raise UsageError(f"{derived.measurement.path or derived.label}: --torque-lag needs a measured rack channel "
                             "(this file's rack is derived from the angle and the torque itself, so it has no lag "
                             "behind the torque to find)")
        settings = dataclasses.replace(settings, torque_lag_fitted=True)
    if args.angle:
        settings = dataclasses.replace(settings, use_handwheel_angle=True)
        with_angle = [f.label for f in files if f.angle_rad is not None]
        if not with_angle:
            f = files[0]
            why = "its rack is derived from the angle" if ANGLE in f.measurement.columns else f"no column {ANGLE!r}"
            raise UsageError(f"{f.measurement.path or f.label}: --angle needs a handwheel angle beside a measured rack "
                             f"({why})")
        note(f"handwheel angle fitted beside the torque in {len(with_angle)} of {len(files)} file(s): "
             + ", ".join(with_angle))
    diagnosis = diagnose(files, params, effects, workers=workers, quiet=args.quiet, settings=settings,
                         baseline=baseline_of(args, params, effects, settings, workers, RECORDS))
    result = _with_suggestion(args, diagnosis_dict(diagnosis), diagnosis, settings)
    user_plot = None
    if args.plot:
        from ..figures.diagnose import diagnosis_figure

        diagnosis_figure(diagnosis, args.plot)
        if "user_effect" in diagnosis.outputs:  # a user's effect in the model: its own figure beside
            from ..figures.user_effect import user_effect_figure, user_effect_path

            user_plot = user_effect_path(args.plot)
            user_effect_figure(diagnosis, user_plot)
            note(f"the figure of {', '.join(diagnosis.outputs['user_effect'].effects)}: {user_plot}")
    # both pages render the same sections: the residual by phase for both, the error ladder (a diagnosis more for
    # each effect it names) where the HTML page asks for it, and then in both
    phases = ladder = None
    if args.report or args.html:
        from ..reporting.report import phase_residuals

        phases = phase_residuals(diagnosis)
    if args.html:
        from ..reporting.ladder import error_ladder

        ladder = error_ladder(files, params, list(diagnosis.base_effects), first=diagnosis, workers=workers)
    if args.report:
        figure = _linked(args.plot, args.report) if args.plot else None
        write_markdown(args.report, markdown_report(result, figure,
                                                    _linked(user_plot, args.report) if user_plot else None,
                                                    phases, ladder.as_dict() if ladder is not None else None))
    if args.html:
        _write_html(args.html, diagnosis, result, phases, ladder)
    if args.json:
        _print_json(result)
    return 0


def _linked(figure, report) -> str:
    """`figure` as the markdown `report` links it: relative to the report's folder when it lies under it."""
    resolved, folder = Path(figure).resolve(), Path(report).resolve().parent
    return str(resolved.relative_to(folder)) if resolved.is_relative_to(folder) else str(figure)


def _with_suggestion(args, result: dict, diagnosis, settings) -> dict:
    """With --suggest-effect and an unexplained verdict, the effect the residual's signature points to, written
    and fitted (parksteer.diagnose.suggest)."""
    if not args.suggest_effect:
        return result
    signature = diagnosis.outputs.get("signature")
    if diagnosis.verdict != "unexplained" or signature is None or signature.effect_class is None:
        note(f"no effect suggested (verdict {diagnosis.verdict}"
             + (", no structure in the residual" if signature is not None and signature.effect_class is None
                else "") + ")")
        return result
    from ..reporting.report import with_suggestion
    from ..diagnose.suggest import suggest

    suggestion = suggest(diagnosis.problem, diagnosis.calibration, signature, args.suggest_effect, settings)
    note(f"suggested effect {suggestion.effect_name} written to {args.suggest_effect}: weighted RMS "
         f"{suggestion.before_over_floor:.2f} -> {suggestion.after_over_floor:.2f} noise floors")
    return with_suggestion(result, suggestion)


def _write_html(path: str, diagnosis, result: dict, phases: list[dict], ladder) -> None:
    """The diagnosis and its error ladder as one self-contained HTML page (parksteer.reporting.pages.html_report)."""
    import tempfile

    from ..reporting.pages import html_report, write_markdown
    from ..figures.diagnose import diagnosis_figure, ladder_figure, phase_residual_figure

    captions = {
        "diagnosis": "Measured handwheel torque and the calibrated model (with the best candidate) against rack, "
                     "their residual, and the weighted RMS error with each candidate (first file).",
        "phases": "RMS residual by phase of the cycle over all files, against the noise floor.",
        "ladder": "The error ladder: the paper's model, calibrated, then with each effect the diagnoses name, down "
                  "to the noise floor.",
    }
    if "user_effect" in diagnosis.outputs:
        captions["user_effect"] = ("Your effect: the error ladder without it and with it, the record (first file) "
                                   "with both models and their residuals over the phases of the cycle, the residual "
                                   "by phase, and the error as its strengths grow from 0 to their fitted values.")
    with tempfile.TemporaryDirectory() as tmp:
        if "user_effect" in diagnosis.outputs:
            from ..figures.user_effect import user_effect_figure

            user_effect_figure(diagnosis, Path(tmp) / "user_effect.svg")
        diagnosis_figure(diagnosis, Path(tmp) / "diagnosis.svg")
        phase_residual_figure(phases, Path(tmp) / "phases.svg")
        ladder_figure(ladder.rungs, ladder.noise_floor_Nm, ladder.attainable_floor_Nm, Path(tmp) / "ladder.svg")
        figures = [(name, caption, (Path(tmp) / f"{name}.svg").read_text(encoding="utf-8"))
                   for name, caption in captions.items()]
    write_markdown(path, html_report(result, figures, phases, ladder.as_dict()))


RECORDS = RecordOptions(_common, effects_of, _check_writable, channel_map_of, assist_of_effects, with_record_speed)
