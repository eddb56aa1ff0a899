"""``parksteer assist size``: the rack force a car needs at standstill and creeping, and the assist that keeps the
driver's torque under a target (parksteer.sweep.assist_sizing)."""

from __future__ import annotations

import math
import time
from pathlib import Path

from ..errors import UsageError
from ..parameters import DEFAULT_PATH
from ..vehicle import ASSIST_EFFECTS
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
    s.add_argument("--out-dir", required=True, help="folder for sizing.csv and the two figures")
    s.add_argument("--parameters", default=str(DEFAULT_PATH), help="the base parameter file")
    s.set_defaults(func=_size)


def _speeds(text: str) -> tuple[float, ...]:
    try:
        speeds = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise UsageError(f"--speeds-kmh {text}: expected numbers separated by commas") from None
    if not speeds or any(not (0.0 <= s <= 10.8) or not math.isfinite(s) for s in speeds):
        raise UsageError(f"--speeds-kmh {text}: speeds within 0-10.8 km/h")
    return speeds


def _size(args) -> int:
    from ..figures.assist import write_sizing
    from ..sweep.assist_sizing import size_assist
    from ..vehicle import vehicle_name

    params = parameters_of(args)
    case = args.case or params.case_names[0]
    if case not in params.case_names:
        raise UsageError(f"--case {case}: not a case of {args.vehicle} ({', '.join(params.case_names)})")
    start = time.perf_counter()
    study = size_assist(params, case, args.target_torque, _speeds(args.speeds_kmh),
                        ASSIST_EFFECTS[args.assist] if args.assist else None)
    written = write_sizing(study, Path(args.out_dir), vehicle_name(args.vehicle))
    elapsed = time.perf_counter() - start
    hydraulic = study.assist == ASSIST_EFFECTS["hydraulic"]
    print(f"{vehicle_name(args.vehicle)}, case {case}, {study.assist}, target {args.target_torque:g} N m "
          f"({elapsed:.1f} s)")
    print("speed km/h  peak rack force N  manual peak N m  " + ("pressure bar" if hydraulic else
                                                                  "motor torque N m  motor current A")
          + "  assisted peak N m")
    for r in study.rows:
        middle = (f"{r.pressure_Pa / 1e5:12.1f}" if hydraulic else f"{r.motor_torque_Nm:16.2f}  {r.motor_current_A:15.1f}")
        print(f"{r.speed_kmh:10.1f}  {r.peak_rack_force_N:17.0f}  {r.peak_handwheel_manual_Nm:15.2f}  {middle}  "
              f"{r.peak_handwheel_assisted_Nm:17.2f}")
    for path in written:
        print(f"wrote {path}")
    return 0
