"""``parksteer simulate``, ``parksteer effects`` and ``parksteer derive``: the multibody steering model."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

from ..errors import UsageError
from ..parameters import DEFAULT_PATH, load_parameters
from ..tables import write_json


def register(sub) -> None:
    p = sub.add_parser("simulate", help="simulate the steering model for one case and write its time history (CSV)")
    p.add_argument("--case", required=True, help="a Table B1 case of the parameter file, e.g. unladen")
    p.add_argument("--effects", default=None, help="effects spec, e.g. --effects=-rack_friction,+hooke_joint (default: the paper's five)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="OWNER.PARAM=VALUE",
                   help="override a parameter of an effect or of a parameter-file section (repeatable)")
    p.add_argument("--surface", choices=("ground", "air_bearing"), default="ground")
    p.add_argument("--rack-from", default=None, metavar="FILE.csv",
                   help="prescribe the rack from a CSV with time_s and rack_m columns; solve for the handwheel torque")
    p.add_argument("--parameters", default=str(DEFAULT_PATH), help="parameter file (default: data/parameters.toml)")
    p.add_argument("--output-dt", type=float, default=0.01, help="output spacing, s (default 0.01)")
    p.add_argument("--out", required=True, help="output CSV")
    p.set_defaults(func=_simulate)

    p = sub.add_parser("effects", help="list the model's effects (components) and their parameters")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--parameters", default=str(DEFAULT_PATH))
    p.set_defaults(func=_effects)

    p = sub.add_parser("derive", help="derive, generate and compile the model for an effect set (cached)")
    p.add_argument("--effects", default=None, help="effects spec (default: all five)")
    p.add_argument("--out", default=None, help="also write a JSON manifest of the cache entry here")
    p.set_defaults(func=_derive)


def _simulate(args) -> int:
    from ..model.numeric.simulate import simulate
    from ..model.numeric.values import parse_overrides

    overrides = parse_overrides(args.overrides)
    if args.rack_from is not None and not Path(args.rack_from).is_file():
        raise UsageError(f"--rack-from {args.rack_from}: no such file")
    params = load_parameters(args.parameters)
    result = simulate(args.case, effects=args.effects, overrides=overrides, surface=args.surface,
                      rack_drive=args.rack_from, params=params, output_dt_s=args.output_dt)
    result.write_csv(args.out)
    return 0


def _effects(args) -> int:
    from ..model.symbolic.components import discover_effects

    params = load_parameters(args.parameters)
    described = [e.describe(params) for e in discover_effects().values()]
    if args.json:
        json.dump(described, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return 0
    for d in described:
        mark = "*" if d["in_default_set"] else " "
        print(f"{mark} {d['name']}: {d['description']}")
        for par in d["parameters"]:
            print(f"      {par['name']} = {par['default']:g} {par['unit']}  [{par['min']:g}, {par['max']:g}]")
    print("(* in the default set)")
    return 0


def _derive(args) -> int:
    from ..model.codegen.cache import ensure_entry, entry_path, model_key
    from ..model.symbolic.components import resolve_effects

    effects = resolve_effects(args.effects)
    start = time.perf_counter()
    existed = (entry_path(effects) / "model.json").is_file()
    directory = ensure_entry(effects)
    info = json.loads((directory / "model.json").read_text(encoding="utf-8"))
    manifest = {
        "effects": [e.name for e in effects],
        "key": model_key(effects),
        "directory": str(directory),
        "coordinates": info["coordinates"],
        "n_parameters": len(info["parameters"]),
        "derivation_timings_s": info["timings_s"],
    }
    if args.out:
        write_json(args.out, manifest)
    elapsed = time.perf_counter() - start
    print(f"{'cached' if existed else 'derived'} {','.join(manifest['effects']) or 'none'} -> {directory} ({elapsed:.1f} s)")
    return 0
