"""``parksteer compare`` and ``parksteer diagnose``: the model against measurement files. The command parses its
options and prints; what the options mean to the method is the intake's (:mod:`parksteer.diagnose.intake`), what
it writes beside its JSON :mod:`.diagnosis_files`'s."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from ..names import SURFACES
from ..errors import UsageError
from ..parameters import DEFAULT_PATH
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
    from ..measure.channel_map import channel_map_from_options

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


def request_of(args, params, **options):
    """The intake's request (:class:`parksteer.diagnose.intake.Request`) of the record options in `args`, for the
    car `params`; `options`: the request's further fields (the diagnosis's options)."""
    from ..diagnose.intake import Request

    return Request(args.files, params, args.effects, vehicle=getattr(args, "vehicle", None),
                   with_assist=getattr(args, "with_assist", False), case=args.case, surface=args.surface,
                   channel_map=channel_map_of(args), command=args.command, **options)


def effects_of(args, params) -> list:
    """The model's effects: --effects, with the vehicle file's [assist] added under --with-assist
    (:func:`parksteer.diagnose.intake.model_effects`)."""
    from ..diagnose.intake import Request, model_effects

    return model_effects(Request((), params, args.effects, vehicle=getattr(args, "vehicle", None),
                                 with_assist=getattr(args, "with_assist", False), command=args.command))


def _compare(args) -> int:
    from ..diagnose.compare import compare_files
    from ..diagnose.intake import intake
    from ..model.numeric.values import parse_overrides

    _check_outputs(args)
    overrides = parse_overrides(args.overrides)
    taken = intake(request_of(args, parameters_of(args)))
    result = compare_files(taken.files, taken.params, taken.effects, overrides)
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
    from ..diagnose.intake import intake
    from .diagnosis_files import write_diagnosis

    _check_outputs(args)
    if not (args.json or args.report or args.plot or args.html or args.suggest_effect):
        raise UsageError("say where the result goes: --json, --report OUT.md, --html OUT.html, --plot OUT.svg and/or "
                         "--suggest-effect OUT.py")
    taken = intake(request_of(args, parameters_of(args), angle=args.angle, torque_lag=args.torque_lag,
                              jobs=args.jobs))
    diagnosis = taken.diagnose(quiet=args.quiet, baseline=baseline_of(args, taken.params, taken.effects,
                                                                       taken.settings, taken.workers, RECORDS))
    result = write_diagnosis(diagnosis, taken, plot=args.plot, report=args.report, html=args.html,
                             suggest_effect=args.suggest_effect)
    if args.json:
        _print_json(result)
    return 0


RECORDS = RecordOptions(_common, effects_of, _check_writable, channel_map_of, request_of)
