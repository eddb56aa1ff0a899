"""``parksteer assist size``: the rack force a car needs at standstill and creeping, and the assist that keeps the
driver's torque under a target (parksteer.sweep.assist_sizing). ``parksteer assist creep``: how much of the tyre's
moment a creeping car keeps over the turn-slip slope (parksteer.figures.assist_creep). ``parksteer assist
identify``: an electric assist's boost table and its gear's hidden numbers from the car's own records
(parksteer.diagnose.identify.assist_identify)."""

from __future__ import annotations

import math
import time
from pathlib import Path

from ..errors import UsageError
from ..parameters import DEFAULT_PATH
from ..vehicle import ASSIST_EFFECTS, MAX_CREEPING_SPEED_KMH
from . import check_writable
from .measure import add_import_options, channel_map_of
from .vehicle import parameters_of


def register(sub) -> None:
    p = sub.add_parser("assist", help="power assistance studies of a vehicle")
    asub = p.add_subparsers(dest="assist_command", required=True, parser_class=type(p))
    s = asub.add_parser("size", help="peak rack force at standstill and creeping speeds, and the motor torque and "
                                     "current (or pressure) that keep the handwheel torque under a target")
    s.add_argument("--vehicle", required=True, metavar="FILE.toml", help="the vehicle file (data/vehicles/)")
    s.add_argument("--case", default=None, help="its load case (default: its first)")
    s.add_argument("--target-torque", type=float, required=True, metavar="NM",
                   help="the most handwheel torque the driver should need over the cycle (N m), e.g. 3")
    s.add_argument("--speeds-kmh", default="0,1,3,5", help="vehicle speeds, km/h, comma-separated (default 0,1,3,5)")
    s.add_argument("--assist", choices=tuple(ASSIST_EFFECTS), default=None,
                   help="the assist to size (default: the vehicle file's [assist], else a column assist at its "
                        "assumed defaults)")
    s.add_argument("--gain-half-speed-kmh", type=float, default=None, metavar="KMH",
                   help="electric: a speed-dependent boost curve, the gain falling as G / (1 + (v / v_half)^2) with "
                        "this v_half (km/h); one assist sized at the lowest speed then runs at every speed (default: "
                        "the vehicle file's speed_dependence and gain_half_speed, off unless it sets them)")
    s.add_argument("--out-dir", required=True, help="folder for sizing.csv and the two figures")
    s.add_argument("--parameters", default=str(DEFAULT_PATH), help="the base parameter file")
    s.set_defaults(func=_size)
    c = asub.add_parser("creep", help="creeping without assist at 1, 3 and 5 km/h over the tyre's turn-slip slope "
                                      "q_Dz8: the share of the standstill tyre moment kept, and where the tyre's "
                                      "share of the parking torque equals the rack friction's")
    c.add_argument("--vehicle", default=None, metavar="FILE.toml", help="a vehicle file (default: the paper's car)")
    c.add_argument("--case", default=None, help="its load case (default: its first)")
    c.add_argument("--parameters", default=str(DEFAULT_PATH), help="the base parameter file")
    c.set_defaults(func=_creep)
    i = asub.add_parser("identify", help="an electric assist's boost table, motor friction, product k_t eta N and "
                                         "torque-sensor offset from the car's records (torsion-bar torque and motor "
                                         "current), written into the vehicle file")
    i.add_argument("files", nargs="+", metavar="FILE",
                   help="records of the car (native CSV, a logger's CSV, MDF or a CAN log with --bus/--dbc), each with "
                        "the torsion-bar torque, the motor current and a rack or handwheel angle")
    i.add_argument("--vehicle", required=True, metavar="FILE.toml",
                   help="the vehicle file: its [assist] gives the gear's data (its boost curve is not used)")
    i.add_argument("--out", required=True, metavar="OUT.toml", help="the vehicle file written with what was identified")
    i.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    i.add_argument("--case", default=None, help="the load case of every record (default: each record's own)")
    i.add_argument("--surface", default=None, help="the surface of records that do not state one")
    add_import_options(i)
    i.add_argument("--json", action="store_true", help="print what was identified as JSON on stdout")
    i.add_argument("--quiet", action="store_true", help="no progress lines")
    i.set_defaults(func=_identify)


def _identify(args) -> int:
    import contextlib
    import json
    import sys

    from ..diagnose.identify.assist_identify import identify_boost
    from ..tables import atomic_path

    out = Path(args.out)
    if out.resolve() == Path(args.vehicle).resolve():
        raise UsageError(f"--out {args.out}: the vehicle file given; write the identified file beside it")
    if out.is_dir() or not out.resolve().parent.is_dir():
        raise UsageError(f"--out {args.out}: name a file in an existing folder")
    if out.suffix != ".toml":
        raise UsageError(f"--out {args.out}: a vehicle file is TOML; name it .toml")
    if out.exists() and not args.force:
        raise UsageError(f"--out {args.out}: exists (--force to overwrite)")
    check_writable("--out", args.out, out.resolve().parent)
    # what the identification prints while it runs is progress: stderr, so that stdout holds the result alone
    with contextlib.redirect_stdout(sys.stderr):
        found = identify_boost(args.files, args.vehicle, args.case, args.surface, channel_map_of(args),
                               quiet=args.quiet)
    text = found.to_vehicle_toml(Path(args.vehicle).read_text(encoding="utf-8"))
    _check_identified(text, out, found, args.files)  # the file must load as the vehicle it describes, or no file
    with atomic_path(out) as tmp:
        tmp.write_text(text, encoding="utf-8")
    if args.json:
        json.dump(found.as_dict(), sys.stdout, indent=1)
        sys.stdout.write("\n")
    else:
        print("\n".join(found.summary_lines()))
    print(f"wrote {out}", file=sys.stderr if args.json else sys.stdout)
    return 0


def _creep(args) -> int:
    from ..figures.assist_creep import creep_study, summary_lines

    params = parameters_of(args)
    case = args.case or params.case_names[0]
    if case not in params.case_names:
        raise UsageError(f"--case {case}: not a case of {args.vehicle or args.parameters} "
                         f"({', '.join(params.case_names)})")
    print("\n".join(summary_lines(creep_study(params, case))))
    return 0


def _check_out_dir(value: str) -> None:
    """--out-dir: a folder, or one that can be made, in a place that can be written (checked before the work)."""
    folder = Path(value).resolve()
    if folder.exists() and not folder.is_dir():
        raise UsageError(f"--out-dir {value}: is a file, not a folder")
    existing = folder
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise UsageError(f"--out-dir {value}: {existing} is a file, not a folder")
    check_writable("--out-dir", value, existing)


# A map whose largest current is below this many times the map's own noise has not seen the motor work.
CURRENT_SEEN_NOISES = 3.0


def _check_identified(text: str, out: Path, found, records) -> None:
    """The identified vehicle file `text` loaded and its assist checked; a value no gear has is told in the
    records' terms (their motor current), naming the records, never the file that was not written."""
    from ..model.numeric.assist import check_assist
    from ..parameters import ParameterError
    from ..vehicle import vehicle_from_text

    try:
        check_assist(vehicle_from_text(text, out))
    except ParameterError as exc:
        detail = str(exc).removeprefix(f"{out}: ")
        names = ", ".join(str(r) for r in records)
        result = found.as_dict()
        current = [abs(c) for c in result["table"]["current_A"]]
        noise = result["map_noise_A"]
        if max(current) <= CURRENT_SEEN_NOISES * noise:
            raise UsageError(f"{names}: motor_current_A: the motor current does not follow the torsion-bar torque "
                             f"(at most {max(current):.3g} A at the map's points, its noise {noise:.3g} A), so the "
                             "assist cannot be read from it: record with the assist working, the current in "
                             "amperes; nothing written") from None
        raise UsageError(f"{names}: what these records give is no gear's ({detail}); check the current's channel "
                         "and unit and the [assist] data; nothing written") from None


def _speeds(text: str) -> tuple[float, ...]:
    try:
        speeds = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise UsageError(f"--speeds-kmh {text}: expected numbers separated by commas") from None
    if not speeds or any(not (0.0 <= s <= MAX_CREEPING_SPEED_KMH) or not math.isfinite(s) for s in speeds):
        raise UsageError(f"--speeds-kmh {text}: speeds within 0-{MAX_CREEPING_SPEED_KMH:g} km/h")
    return speeds


def _size(args) -> int:
    from ..figures.assist import write_sizing
    from ..sweep.assist_sizing import size_assist
    from ..vehicle import vehicle_name

    _check_out_dir(args.out_dir)
    params = parameters_of(args)
    case = args.case or params.case_names[0]
    if case not in params.case_names:
        raise UsageError(f"--case {case}: not a case of {args.vehicle} ({', '.join(params.case_names)})")
    params = with_gain_half_speed(params, args)
    start = time.perf_counter()
    study = size_assist(params, case, args.target_torque, _speeds(args.speeds_kmh),
                        ASSIST_EFFECTS[args.assist] if args.assist else None)
    written = write_sizing(study, Path(args.out_dir), vehicle_name(args.vehicle))
    elapsed = time.perf_counter() - start
    hydraulic = study.assist == ASSIST_EFFECTS["hydraulic"]
    falloff = "" if hydraulic or not params[f"{study.assist}.speed_dependence"] else (
        f", gain falling with speed (v_half {params[f'{study.assist}.gain_half_speed'] * 3.6:g} km/h)")
    print(f"{vehicle_name(args.vehicle)}, case {case}, {study.assist}{falloff}, target {args.target_torque:g} N m "
          f"({elapsed:.1f} s)")
    print("speed km/h  peak rack force N  manual peak N m  " + ("pressure bar" if hydraulic else
                                                                  "motor torque N m  motor current A")
          + "  gain  assisted peak N m  " + ("check pressure bar" if hydraulic else "check motor N m"))
    for r in study.rows:
        middle = (f"{r.pressure_Pa / 1e5:12.1f}" if hydraulic else f"{r.motor_torque_Nm:16.2f}  {r.motor_current_A:15.1f}")
        print(f"{r.speed_kmh:10.1f}  {r.peak_rack_force_N:17.0f}  {r.peak_handwheel_manual_Nm:15.2f}  {middle}  "
              f"{r.gain:4.2f}  {r.peak_handwheel_assisted_Nm:17.2f}  "
              + (f"{r.check_pressure_Pa / 1e5:18.1f}" if hydraulic else f"{r.check_motor_torque_Nm:15.2f}"))
    print_friction_band(study)
    for path in written:
        print(f"wrote {path}")
    return 0


def print_friction_band(study) -> None:
    """The standstill rack force over the tyre-ground friction band, with and without the rack's own friction,
    against the published class range, and the assist sized at the range's ends; a warning on stderr when a force
    of the band is below the range."""
    import sys

    from ..sweep.assist_sizing import PUBLISHED_STANDSTILL_RACK_FORCE_N

    low, high = PUBLISHED_STANDSTILL_RACK_FORCE_N
    hydraulic = study.assist == ASSIST_EFFECTS["hydraulic"]
    print(f"standstill over the tyre-ground friction of dry asphalt (published for small and medium cars: "
          f"{low / 1e3:g}-{high / 1e3:g} kN)")
    print("friction  peak rack force N  without rack friction N" + ("" if hydraulic else
                                                                    "  motor torque N m  motor current A"))
    for r in study.friction_band:
        print(f"{r.friction:8.2f}  {r.peak_rack_force_N:17.0f}  {r.peak_rack_force_without_rack_friction_N:23.0f}"
              + ("" if hydraulic else f"  {r.motor_torque_Nm:16.2f}  {r.motor_current_A:15.1f}"))
    print("sized at the class range's ends (quasi-static, through this car's gear at its standstill peak)")
    print("rack force N  " + ("pressure bar" if hydraulic else "motor torque N m  motor current A"))
    for r in study.class_load:
        print(f"{r.rack_force_N:12.0f}  " + (f"{r.pressure_Pa / 1e5:12.1f}" if hydraulic else
                                            f"{r.motor_torque_Nm:16.2f}  {r.motor_current_A:15.1f}"))
    below = study.below_published()
    if below:
        frictions = ", ".join(f"{r.friction:g}" for r in below)
        top = max(r.peak_rack_force_N for r in study.friction_band)
        print(f"warning: at tyre-ground friction {frictions} the standstill rack force is below the "
              f"{low / 1e3:g}-{high / 1e3:g} kN published for current small and medium cars ({top:.0f} N at the "
              "band's top): the tyre's bore torque (equation (2)) or the car's loads may be those of an older or "
              "lighter car; size the motor for the band's top or the class range's", file=sys.stderr)


def with_gain_half_speed(params, args):
    """`params` with the assist's gain falling with speed at --gain-half-speed-kmh (unchanged without it)."""
    if args.gain_half_speed_kmh is None:
        return params
    from ..model.numeric.assist import check_assist

    name = ASSIST_EFFECTS[args.assist] if args.assist else (check_assist(params) or ASSIST_EFFECTS["column"])
    if name == ASSIST_EFFECTS["hydraulic"]:
        raise UsageError("--gain-half-speed-kmh: the hydraulic assist's valve does not depend on speed")
    option = f"--gain-half-speed-kmh {args.gain_half_speed_kmh:g}"
    if not (math.isfinite(args.gain_half_speed_kmh) and args.gain_half_speed_kmh > 0.0):
        raise UsageError(f"{option}: must be a positive speed (km/h)")
    try:
        return params.with_overrides({f"{name}.speed_dependence": 1.0,
                                      f"{name}.gain_half_speed": args.gain_half_speed_kmh / 3.6})
    except UsageError as exc:
        raise UsageError(f"{option}: {exc}") from None
