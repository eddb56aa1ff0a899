"""``parksteer vehicle new`` and ``parksteer vehicle check``: a vehicle file from a car's specification."""

from __future__ import annotations

import math
import re
from pathlib import Path

from ..errors import UsageError
from ..parameters import DEFAULT_PATH, load_parameters
from ..model.numeric.assist import ASSIST_EFFECTS

BAR_PA = 1.0e5
INCH_M = 0.0254
# King-pin inclination and castor: the registry's bounds, 0.5 rad (geometry.kingpin_inclination, castor_angle).
MAX_AXIS_ANGLE_DEG = math.degrees(0.5)
TYRE_SIZE = re.compile(r"^\s*(\d{3})\s*/\s*(\d{2})\s*Z?R\s*(\d{2}(?:\.\d)?)\s*$", re.IGNORECASE)


def register(sub) -> None:
    p = sub.add_parser("vehicle", help="write or check a vehicle file (your own car)")
    vsub = p.add_subparsers(dest="vehicle_command", required=True, parser_class=type(p))

    n = vsub.add_parser("new", help="write a commented vehicle file from a car's specification, deriving the rest")
    n.add_argument("--out", required=True, metavar="FILE.toml", help="the vehicle file to write (its stem names the car)")
    load = n.add_mutually_exclusive_group(required=True)
    load.add_argument("--front-axle-mass-kg", type=float, help="front axle load as a mass (kg), e.g. 780")
    load.add_argument("--front-axle-load-N", type=float, help="front axle load (N)")
    n.add_argument("--left-share", type=float, default=0.5,
                   help="share of the front axle load on the left wheel (default 0.5)")
    n.add_argument("--track-m", type=float, required=True, help="front track, wheel centre to wheel centre (m)")
    n.add_argument("--kingpin-inclination-deg", type=float, required=True, help="king-pin inclination (degrees)")
    n.add_argument("--castor-deg", type=float, required=True, help="castor angle (degrees)")
    offset = n.add_mutually_exclusive_group(required=True)
    offset.add_argument("--scrub-radius-m", type=float,
                        help="scrub radius at the ground, contact centre outboard of the axis positive (m)")
    offset.add_argument("--kingpin-offset-m", type=float,
                        help="king-pin offset at wheel-centre height, wheel centre outboard of the axis positive (m)")
    tyre = n.add_mutually_exclusive_group(required=True)
    tyre.add_argument("--tyre-size", help="ISO size, e.g. 185/65R15 (the unloaded radius is derived from it)")
    tyre.add_argument("--tyre-radius-m", type=float, help="tyre radius (m)")
    n.add_argument("--tyre-pressure-bar", type=float, required=True, help="front tyre pressure, gauge (bar)")
    n.add_argument("--steering-ratio", type=float, required=True, help="overall steering ratio (handwheel/road wheel)")
    n.add_argument("--lock-turns", type=float, required=True, help="handwheel turns lock to lock")
    n.add_argument("--assist", choices=tuple(ASSIST_EFFECTS), default=None,
                   help="power assistance: electric at the column, pinion or rack, or hydraulic; writes [assist] "
                        "with the values given below and the rest assumed (typical, with ranges and sources)")
    n.add_argument("--assist-reduction", type=float, default=None,
                   help="electric: the motor's reduction (worm gear ratio; rack: rad of motor per m of rack)")
    n.add_argument("--assist-motor-torque-Nm", type=float, default=None, help="electric: the motor's peak torque (N m)")
    n.add_argument("--assist-relief-pressure-bar", type=float, default=None,
                   help="hydraulic: the relief valve's pressure (bar)")
    n.add_argument("--assist-boost", default=None, metavar="T:A,T:A",
                   help="boost-curve points, torsion-bar torque (N m) : assist, rising (electric: written as the "
                        "table [assist.boost], 0:0 added in front if missing, the assist in the unit "
                        "--assist-boost-unit says; hydraulic: the valve's pressure "
                        "in bar)")
    n.add_argument("--assist-boost-unit", choices=BOOST_POINT_UNITS, default=None,
                   help="electric: what the assist of --assist-boost is: the motor's torque (N m; turned into the "
                        "point of action's through eta N), or the torque at the column or pinion (N m), or the force "
                        "at the rack (N); default the point of action's own")
    n.add_argument("--assist-gain-half-speed-kmh", type=float, default=None, metavar="KMH",
                   help="electric: a speed-dependent boost curve, the gain falling as G / (1 + (v / v_half)^2) with "
                        "this v_half (km/h); without it the gain does not depend on speed")
    n.add_argument("--case", default="kerb", help="name of the load case (default kerb)")
    n.add_argument("--force", action="store_true", help="overwrite an existing file")
    n.add_argument("--parameters", default=str(DEFAULT_PATH),
                   help="parameter file whose car fills what a specification does not give")
    n.set_defaults(func=_new)

    c = vsub.add_parser("check", help="validate a vehicle file (registry, statics, geometry, lock)")
    c.add_argument("path")
    c.add_argument("--parameters", default=str(DEFAULT_PATH), help="the base parameter file")
    c.set_defaults(func=_check)


def tyre_radius_m(size: str) -> float:
    """Unloaded radius of an ISO tyre size: rim / 2 + width x aspect (185/65R15: 0.1905 + 0.12025 m)."""
    match = TYRE_SIZE.match(size)
    if match is None:
        raise UsageError(f"--tyre-size {size!r}: expected an ISO size such as 185/65R15")
    width_mm, aspect_pct, rim_in = float(match[1]), float(match[2]), float(match[3])
    return rim_in * INCH_M / 2.0 + width_mm / 1000.0 * aspect_pct / 100.0


def specification(args, gravity: float):
    """The :class:`parksteer.vehicle.Specification` of the command line, in SI units."""
    from ..vehicle.specification import Specification

    load_N = args.front_axle_load_N if args.front_axle_load_N is not None else args.front_axle_mass_kg * gravity
    load_option = "--front-axle-load-N" if args.front_axle_load_N is not None else "--front-axle-mass-kg"
    load_given = args.front_axle_load_N if args.front_axle_load_N is not None else args.front_axle_mass_kg
    if not load_N > 0.0:
        raise UsageError(f"{load_option} {load_given:g}: must be positive")
    for option, degrees in (("--kingpin-inclination-deg", args.kingpin_inclination_deg),
                            ("--castor-deg", args.castor_deg)):
        if not abs(degrees) <= MAX_AXIS_ANGLE_DEG:
            raise UsageError(f"{option} {degrees:g}: outside +-{MAX_AXIS_ANGLE_DEG:g} degrees (road cars: 0-20)")
    if args.tyre_radius_m is not None and not 0.1 < args.tyre_radius_m < 1.0:
        raise UsageError(f"--tyre-radius-m {args.tyre_radius_m:g}: outside (0.1, 1) m")
    radius = args.tyre_radius_m if args.tyre_radius_m is not None else tyre_radius_m(args.tyre_size)
    chi, eps = math.radians(args.kingpin_inclination_deg), math.radians(args.castor_deg)
    if args.scrub_radius_m is not None:
        scrub = args.scrub_radius_m
    else:  # the axis runs inboard by tan(kpi)/cos(castor) per unit height above the ground
        from .. import portable as pm  # numpy: imported where used, not for --help

        scrub = args.kingpin_offset_m - radius * pm.tan(chi) / pm.cos(eps)
    for option, value, low, high in (("--left-share", args.left_share, 0.0, 1.0),
                                     ("--steering-ratio", args.steering_ratio, 1.0, 100.0),
                                     ("--lock-turns", args.lock_turns, 0.1, 10.0),
                                     ("--track-m", args.track_m, 0.5, 3.0),
                                     ("--tyre-pressure-bar", args.tyre_pressure_bar, 0.1, 10.0)):
        if not low < value < high:
            raise UsageError(f"{option} {value:g}: outside ({low:g}, {high:g})")
    sources = [("tyre_radius_m", f"derived from the tyre size {args.tyre_size}")] if args.tyre_size else []
    if args.front_axle_mass_kg is not None:
        sources.append(("front_axle_load_N", f"front axle mass {args.front_axle_mass_kg:g} kg x g"))
    if args.kingpin_offset_m is not None:
        sources.append(("scrub_radius_m", f"from the king-pin offset {args.kingpin_offset_m:g} m"))
    return Specification(
        front_axle_load_N=load_N, left_share=args.left_share, track_m=args.track_m, kingpin_inclination_rad=chi,
        castor_rad=eps, scrub_radius_m=scrub, tyre_radius_m=radius,
        tyre_pressure_Pa=args.tyre_pressure_bar * BAR_PA, steering_ratio=args.steering_ratio,
        lock_turns=args.lock_turns, case=args.case, spec_sources=tuple(sources))


def _new(args) -> int:
    from ..tables import atomic_path
    from ..vehicle import vehicle_from_text, vehicle_name
    from ..vehicle.specification import template_text, vehicle_values

    out = Path(args.out)
    if out.suffix != ".toml":
        raise UsageError(f"--out {args.out}: a vehicle file is TOML; name it .toml")
    if not out.resolve().parent.is_dir():
        raise UsageError(f"--out {args.out}: folder {out.resolve().parent} does not exist")
    if out.exists() and not args.force:
        raise UsageError(f"--out {args.out}: exists (--force to overwrite)")
    base = load_parameters(args.parameters)
    spec = specification(args, base["vehicle.gravity"])
    values = vehicle_values(spec, base)
    text = template_text(vehicle_name(out), spec, values) + assist_section(args, base)
    try:
        params = vehicle_from_text(text, out, base)  # checked as a vehicle file before anything is written
        if args.assist is not None:
            from ..model.numeric.assist import check_assist

            check_assist(params)
    except UsageError as exc:
        raise UsageError(f"the specification gives no valid car, nothing written: {exc}") from None
    with atomic_path(out) as tmp:
        tmp.write_text(text, encoding="utf-8")
    print(f"{out}: vehicle {vehicle_name(out)}, case {spec.case}" + (f", {args.assist} assist" if args.assist else ""))
    for d in values:
        how = f" = {d.how}" if d.how else ""
        print(f"  {d.key} = {d.value:.6g} {d.unit}  [{d.source}]{how}")
    return 0


# What the assist of --assist-boost points is: the motor's torque, or the assist at a point of action.
BOOST_POINT_UNITS = ("motor", "column", "pinion", "rack")


def boost_points(text: str) -> list[tuple[float, float]]:
    """--assist-boost T:A,T:A,... as points; one-line UsageError otherwise."""
    try:
        points = [tuple(float(x) for x in item.split(":")) for item in text.split(",")]
    except ValueError:
        points = [()]
    if any(len(pt) != 2 for pt in points):
        raise UsageError(f"--assist-boost {text}: expected points T:A separated by commas")
    return points  # type: ignore[return-value]


def boost_table_text(args, efficiency: float, reduction: float) -> str:
    """The ``[assist.boost]`` section of --assist-boost, its assist at the point of action (a motor torque through
    eta N); checked as a boost table."""
    from ..boost_table import BoostTableError, check_table

    unit = args.assist_boost_unit or args.assist
    if args.assist != "hydraulic" and unit not in ("motor", args.assist):
        raise UsageError(f"--assist-boost-unit {unit}: a {args.assist} assist takes its points as motor torque or "
                         f"as the assist at the {args.assist}")
    points = boost_points(args.assist_boost)
    if points and points[0][0] > 0.0:
        points = [(0.0, 0.0), *points]  # a curve given from its dead band on starts at the origin
    torques = [t for t, _ in points]
    scale = efficiency * reduction if unit == "motor" else 1.0
    assist = [a * scale for _, a in points]
    try:
        check_table(torques, None, [assist])
    except BoostTableError as exc:
        raise UsageError(f"--assist-boost {args.assist_boost}: {exc}") from None
    how = (f"motor torque x eta N = {scale:g} (the reduction and forward efficiency of [assist])" if unit == "motor"
           else "the valve's pressure" if unit == "hydraulic" else f"the assist at the {unit}")
    assist_unit = {"rack": "N", "hydraulic": "bar"}.get(args.assist, "N m")
    source = f"specification: --assist-boost {args.assist_boost} ({how})"
    what = "valve's characteristic" if args.assist == "hydraulic" else "boost curve as the control unit's table"
    return (f"\n# The {what} (parksteer.boost_table): monotone cubic between the points.\n"
            "[assist.boost]\n"
            f'torsion_bar_torque = {{ value = {[float(t) for t in torques]}, unit = "N m", source = "{source}" }}\n'
            f'assist = {{ value = {[float(f"{a:.10g}") for a in assist]}, unit = "{assist_unit}", source = "{source}" }}\n')


def assist_section(args, base) -> str:
    """The ``[assist]`` section of `args` (empty without --assist): given values from the options, the rest assumed."""
    electric_only = (("--assist-reduction", args.assist_reduction),
                     ("--assist-motor-torque-Nm", args.assist_motor_torque_Nm),
                     ("--assist-gain-half-speed-kmh", args.assist_gain_half_speed_kmh))
    if args.assist is None:
        given = [o for o, v in (*electric_only, ("--assist-relief-pressure-bar", args.assist_relief_pressure_bar),
                                ("--assist-boost", args.assist_boost),
                                ("--assist-boost-unit", args.assist_boost_unit)) if v is not None]
        if given:
            raise UsageError(f"{given[0]} needs --assist")
        return ""
    from ..model.numeric.assist import assist_template, gear_values

    hydraulic = args.assist == "hydraulic"
    wrong = [o for o, v in (*electric_only, ("--assist-boost-unit", args.assist_boost_unit)) if v is not None
             ] if hydraulic else (["--assist-relief-pressure-bar"] if args.assist_relief_pressure_bar is not None else [])
    if args.assist_boost_unit is not None and args.assist_boost is None:
        raise UsageError("--assist-boost-unit needs --assist-boost")
    if not hydraulic and args.assist_boost is not None and args.assist_gain_half_speed_kmh is not None:
        raise UsageError("--assist-gain-half-speed-kmh: a boost table gives the curve (one row per speed in "
                         "[assist.boost]), not a gain falling with speed")
    if wrong:
        raise UsageError(f"{wrong[0]}: not a value of a {args.assist} assist")
    given: dict[str, tuple[float, str]] = {}
    if args.assist_reduction is not None:
        given["reduction_ratio"] = (args.assist_reduction, "specification")
    if args.assist_motor_torque_Nm is not None:
        given["motor_torque_limit"] = (args.assist_motor_torque_Nm, "specification")
    if args.assist_gain_half_speed_kmh is not None:
        source = f"specification: the gain halves at {args.assist_gain_half_speed_kmh:g} km/h (km/h / 3.6)"
        given["speed_dependence"] = (1.0, "specification: a speed-dependent boost curve")
        given["gain_half_speed"] = (args.assist_gain_half_speed_kmh / 3.6, source)
    if args.assist_relief_pressure_bar is not None:
        given["relief_pressure"] = (args.assist_relief_pressure_bar * BAR_PA, "specification (bar x 1e5)")
    if args.assist_boost is None:
        return assist_template(args.assist, given)
    efficiency, reduction = (1.0, 1.0) if hydraulic else gear_values(args.assist, given)
    return assist_template(args.assist, given, table=True) + boost_table_text(args, efficiency, reduction)


def _check(args) -> int:
    from ..vehicle import load_vehicle

    from ..model.numeric.assist import check_assist

    params = load_vehicle(args.path, args.parameters)
    assist = check_assist(params)
    print(f"{args.path}: vehicle valid; cases: {', '.join(params.case_names)}" + (f"; assist {assist}" if assist else ""))
    return 0


def add_vehicle_option(p) -> None:
    """--vehicle FILE: run on that car (its values and cases over the base parameter file)."""
    p.add_argument("--vehicle", default=None, metavar="FILE.toml",
                   help="a vehicle file (data/vehicles/, `parksteer vehicle new`): its car and load cases replace "
                        "the paper's; --case names one of its cases where a file does not")


def parameters_of(args):
    """The parameters of a command: --parameters, with the car of --vehicle over it when given
    (:func:`parksteer.diagnose.intake.car_parameters`)."""
    from ..diagnose.intake import car_parameters

    return car_parameters(args.parameters, getattr(args, "vehicle", None))
