"""``parksteer simulate``, ``parksteer effects`` and ``parksteer derive``: the multibody steering model."""

from __future__ import annotations

import json
import sys
import time
from contextlib import nullcontext
from pathlib import Path

from ..names import SURFACES
from ..errors import UsageError, naming
from ..parameters import DEFAULT_PATH, load_parameters
from . import add_quiet_option
from .measure import add_import_options, channel_map_of
from .vehicle import add_vehicle_option, parameters_of


def register(sub) -> None:
    p = sub.add_parser("simulate", help="simulate the steering model for one case and write its time history (CSV)")
    p.add_argument("--case", default=None,
                   help="a Table B1 case of the parameter file, e.g. unladen (with --rack-from: default the file's case)")
    p.add_argument("--effects", default=None, help="effects spec, e.g. --effects=-rack_friction,+hooke_joint (default: the paper's five)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a quantity by its key, e.g. tyre.tyre_pressure=180000 or rack_lash.lash=0.0002 (keys: `parksteer effects`, the parameter file; case.<name> for the case; repeatable)")
    p.add_argument("--surface", choices=tuple(SURFACES), default=None,
                   help="default ground (with --rack-from: the file's surface)")
    p.add_argument("--speed-kmh", type=float, default=None,
                   help="the car creeps at this constant speed while it steers, 0-10.8 km/h (adds the turn_slip "
                        "effect: the tyre moment of a rolling wheel; 0 = the standstill torque)")
    p.add_argument("--rack-from", default=None, metavar="FILE.csv",
                   help="prescribe the rack of a measurement file (data/measurements/README.md) and solve for the "
                        "handwheel torque; the measured rack is smoothed as `parksteer compare` smooths it (a "
                        "least-squares spline within the rack's noise, a knot at each reversal)")
    p.add_argument("--raw-rack", action="store_true",
                   help="with --rack-from: replay the raw rack samples through an interpolating cubic spline instead "
                        "of smoothing them; a logged rack's converter steps then become spikes of rack speed and "
                        "acceleration that flip the rack friction (several N m wrong on 8-bit data), which is why "
                        "smoothing is the default")
    add_import_options(p)
    p.add_argument("--parameters", default=str(DEFAULT_PATH), help="parameter file (default: the packaged parksteer/data/parameters.toml)")
    add_vehicle_option(p)
    p.add_argument("--with-assist", action="store_true",
                   help="with --vehicle: add the vehicle file's [assist] to the effects (without it a file's runs "
                        "are the car without assistance, as before the file had one)")
    p.add_argument("--output-dt", type=float, default=0.01, help="output spacing, s (default 0.01)")
    p.add_argument("--out", required=True, help="output CSV")
    add_quiet_option(p)
    p.set_defaults(func=_simulate)

    p = sub.add_parser("effects", help="list the model's effects, their slots and needs, and the quantities each uses")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--parameters", default=str(DEFAULT_PATH))
    p.set_defaults(func=_effects)

    p = sub.add_parser("derive", help="derive, generate and compile the model for an effect set (cached)")
    p.add_argument("--effects", default=None, help="effects spec (default: all five)")
    p.add_argument("--out", default=None, help="also write a JSON manifest of the cache entry here")
    p.add_argument("--prebuilt", action="store_true",
                   help="instead: derive the models of a diagnosis with the default effects (against any manual "
                        "car's baseline too), and those of the pipeline's model manifests given, and keep their C in "
                        "the package (src/parksteer/model/prebuilt), where a cold cache compiles it without deriving; "
                        "run after any change to the symbolic half (the tests say when) as "
                        "`parksteer derive --prebuilt results/model/*.json`")
    p.add_argument("manifests", nargs="*", metavar="MANIFEST",
                   help="with --prebuilt: model manifests the pipeline wrote (results/model/<name>.json), whose "
                        "effect sets are pre-derived too")
    add_quiet_option(p)
    p.set_defaults(func=_derive)


def _assisted_vehicle_sets() -> list:
    """(spec, effects) of the models a diagnosis with its assist (`--with-assist`) builds for each vehicle file of
    the checkout's data/vehicles that has an [assist], and of the car with each assisted candidate (what the
    assisted benchmark makes its records with): the README's assisted example and the assisted benchmark (the
    Polo's) then compile them instead of deriving them."""
    from ..diagnose.candidates import assisted_models
    from ..model.codegen.cache import checkout_root
    from ..vehicle import load_vehicle

    root = checkout_root()
    sets = []
    for vehicle in sorted((root / "data" / "vehicles").glob("*.toml")) if root is not None else []:
        sets += [([e.name for e in effects], effects) for effects in assisted_models(load_vehicle(vehicle, load_parameters()))]
    return sets


def _assist_type_sets() -> list:
    """(spec, effects) of the paper's car with each power assist of the library (`--effects=+NAME`,
    model.numeric.assist.ASSIST_EFFECTS), spec ``"+NAME"``: the first run of any assist type on the default car
    compiles instead of deriving (docs/assist.md)."""
    from ..model.numeric.assist import ASSIST_EFFECTS
    from ..model.symbolic.components import resolve_effects

    return [(f"+{name}", resolve_effects(f"+{name}")) for name in ASSIST_EFFECTS.values()]


def _suggestion_shape_sets() -> list:
    """(spec, effects) of the models a suggestion on the default car is fitted with: the default set and each form
    of a suggested effect (parksteer.diagnose.suggest.shape_forms), spec ``{"shape": name}``."""
    from ..diagnose.suggest import shape_forms
    from ..model.symbolic.components import resolve_effects

    base = resolve_effects(None)
    return [({"shape": form.name}, sorted([*base, form], key=lambda e: e.name)) for form in shape_forms()]


def _spec_sets(specs) -> list:
    """(spec, effects) of each effects spec of `specs`, the spec as written."""
    from ..model.symbolic.components import resolve_effects

    return [(spec, resolve_effects(spec)) for spec in specs]


def _ablation_sets() -> list:
    """(spec, effects) of the paper's model without each of its effects, spec ``"-NAME"``: the first question a
    reader asks of a share (docs/model.md's `--effects`), and a physical check's reference (lifting or the Hooke
    joint switched off, as tests/model/test_cycle.py and test_hooke.py switch them), compiled instead of derived."""
    from ..model.symbolic.components import resolve_effects

    return _spec_sets(f"-{effect.name}" for effect in resolve_effects(None))


# The effects specs the documents' commands run that no other category ships (a test finds every plain spec the
# documents run among the shipped models): docs/model.md's king-pin friction in place of the rack's.
DOCUMENTED_SPECS = ("-rack_friction,+kingpin_friction",)


# The folders of example effect files, relative to the checkout: the user's worked example (docs/signature.md) and
# the package's own (docs/measurement.md, docs/diagnosis.md).
EXAMPLE_EFFECT_FOLDERS = ("examples/user_effect", "src/parksteer/examples")


def example_effect_files(root: Path) -> list[Path]:
    """The example effect files of the checkout `root` (:data:`EXAMPLE_EFFECT_FOLDERS`), folder by folder."""
    return [path for folder in EXAMPLE_EFFECT_FOLDERS for path in sorted((root / folder).glob("[!_]*.py"))]


def _example_effect_sets() -> list:
    """(spec, effects) of the models a diagnosis with each of :func:`example_effect_files` (`--effects=+FILE`)
    builds, spec ``{"example": the file relative to the checkout, "effects": the other effects}``: the documents'
    worked examples compile them instead of deriving them."""
    from ..diagnose.candidates import candidate_effects, models_to_build
    from ..model.codegen.cache import checkout_root
    from ..model.symbolic.components import resolve_effects

    root = checkout_root()
    sets = []
    for path in example_effect_files(root) if root is not None else []:
        base = resolve_effects(f"+{path}")
        example = next(e for e in base if e.name == path.stem)
        sets += [({"example": path.relative_to(root).as_posix(), "effects": [e.name for e in effects if e is not example]},
                  effects) for effects in models_to_build(base, candidate_effects(base)[0])]
    return sets


def _signature_truth_sets() -> list:
    """(spec, effects) of the models the signature benchmark makes its records with: the default set and each truth
    form outside the library (parksteer.synthetic.outoflibrary), spec ``{"truth_form": name}``; its jobs then
    compile them instead of deriving them."""
    from ..experiments.outoflibrary import truth_effects
    from ..synthetic.outoflibrary import ALL_FORMS

    return [({"truth_form": form.effect.name}, truth_effects(form)) for form in ALL_FORMS]


def _held_form_sets() -> list:
    """(spec, effects) of the models a diagnosis against a manual car's baseline builds, whatever form the baseline
    learnt: each form a suggestion can take (parksteer.diagnose.suggest.shape_forms) held on the default set, with
    the diagnosis models over it (:func:`parksteer.diagnose.candidates.models_to_build`), spec ``{"shape": name,
    "effects": [the other effects]}``. A manual car's model is the default set whatever its vehicle file, so a later
    record of any manual car compiles these instead of deriving them. An assisted car's form is held on the car's
    own assisted model, which is not pre-derived (its job derives it). The first model of each form is its
    suggestion's (:func:`_suggestion_shape_sets`), which the package ships under that spec."""
    from ..diagnose.candidates import candidate_effects, models_to_build

    sets = []
    for spec, base in _suggestion_shape_sets():
        sets += [({"shape": spec["shape"], "effects": [e.name for e in model if e.name != spec["shape"]]}, model)
                 for model in models_to_build(base, candidate_effects(base)[0])]
    return sets


def _manifest_spec(path: str):
    """The effects spec of a model manifest the pipeline's derive rule wrote (its `spec`), refused in one line."""
    try:
        manifest = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise UsageError(f"{path}: not a model manifest ({error})") from None
    if not isinstance(manifest, dict) or "spec" not in manifest:
        raise UsageError(f"{path}: not a model manifest of the pipeline (no 'spec'; `snakemake --cores 2 {path}` "
                         "writes one)")
    return manifest["spec"]


def _simulate(args) -> int:
    from ..model.numeric.simulate import simulate
    from ..model.numeric.values import parse_overrides

    overrides = parse_overrides(args.overrides)
    if Path(args.out).is_dir():
        raise UsageError(f"--out {args.out}: is a directory; name a file to write")
    if args.raw_rack and args.rack_from is None:
        raise UsageError("--raw-rack needs --rack-from FILE")
    if args.with_assist and args.vehicle is None:
        raise UsageError("--with-assist needs --vehicle FILE (the assist is the vehicle file's [assist])")
    if args.rack_from is not None and not Path(args.rack_from).exists() and not Path(args.rack_from).is_symlink():
        raise UsageError(f"--rack-from {args.rack_from}: no such file")  # a link that leads nowhere: said on reading
    params = parameters_of(args)
    if args.rack_from is None and args.case is None:
        if args.vehicle is None or len(params.case_names) != 1:
            raise UsageError("--case is required (or --rack-from FILE, whose metadata names the case)")
        args.case = params.case_names[0]  # a vehicle file with one load case
    case, surface, rack, drive = args.case, args.surface or "ground", None, None
    if args.rack_from is not None:
        case, surface, rack, drive = _measured_rack(args.rack_from, params, args.raw_rack,
                                                    channel_map_of(args), args.case,
                                                    args.surface or "ground")  # a drive needs no surface
        case, surface = args.case or case, args.surface or surface
    if not (args.output_dt > 0):
        raise UsageError(f"--output-dt {args.output_dt:g}: the output step must be positive")
    with naming(f"--rack-from {args.rack_from}") if args.rack_from is not None else nullcontext():
        from ..model.numeric.assist import check_assist, effects_with_assist

        effects = effects_with_assist(args.effects, params) if args.with_assist else args.effects
        if args.with_assist and effects == args.effects and check_assist(params) is None:
            raise UsageError(f"--with-assist: {args.vehicle} has no [assist] section")
        if args.speed_kmh is not None:
            effects, overrides = with_speed(effects, overrides, args.speed_kmh)
        result = simulate(case, effects=effects, overrides=overrides, surface=surface,
                          rack_drive=rack, params=params, output_dt_s=args.output_dt)
    if drive is not None:
        result.header["drive"] = drive
    result.write_csv(args.out)
    return 0


def with_speed(effects: str | None, overrides: dict, speed_kmh: float) -> tuple[str, dict]:
    """The effects spec with turn_slip and the overrides with the run's vehicle speed (m/s) of `speed_kmh`."""
    from ..vehicle import MAX_CREEPING_SPEED_KMH, creeping_overrides

    if not 0.0 <= speed_kmh <= MAX_CREEPING_SPEED_KMH:
        raise UsageError(f"--speed-kmh {speed_kmh:g}: outside 0-{MAX_CREEPING_SPEED_KMH:g} km/h "
                         "(parking and creeping)")
    if not (effects and "turn_slip" in effects):
        signed = not effects or all(s.strip()[:1] in "+-" for s in effects.split(",") if s.strip())
        effects = (f"{effects}," if effects else "") + ("+turn_slip" if signed else "turn_slip")
    return effects, {**overrides, **creeping_overrides(speed_kmh)}


def _measured_rack(path: str, params, raw: bool, channel_map=None, case=None, surface=None):
    """(case, surface, rack motion, description) of a measurement file's rack: smoothed as compare does, or raw."""
    from ..measure.importers import load_rack_drive
    from ..measure.smoothing import smooth_rack
    from ..measure.rack_spline import interpolate_rack

    measurement = load_rack_drive(path, channel_map, case=case, surface=surface, params=params)
    with naming(path):
        rack = (interpolate_rack if raw else smooth_rack)(measurement.time_s, measurement.rack_m)
    if raw:
        drive = f"prescribed rack from {path}: the raw samples through an interpolating cubic spline"
    else:
        drive = (f"prescribed rack from {path}: smoothed by a least-squares cubic spline, knots "
                 f"{rack.knot_spacing_s:.3g} s apart, fit RMS {rack.fit_rms_m:.3g} m (parksteer.measure.smoothing)")
    return measurement.case, measurement.surface, rack, drive


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
        needs = [f"fills {d['replaces']}"] if d["replaces"] else []
        needs += [f"requires {', '.join(d['requires'])}"] if d["requires"] else []
        if needs:
            print(f"      ({'; '.join(needs)})")
        table = [par for par in d["parameters"] if par["key"].partition(".")[2].startswith("boost_")]
        for par in d["parameters"]:
            if par not in table:
                print(f"      {par['key']} = {par['default']:g} {par['unit']}  [{par['min']:g}, {par['max']:g}]")
        if table:  # the boost table's scalars, filled from [assist.boost] (parksteer.boost_table): one line
            print(f"      {d['name']}.boost_*: {len(table)} scalars of the boost table [assist.boost] (points, speeds, "
                  "assists, slopes); default 0: no table (--json lists them)")
    print("(* in the default set)")
    return 0


def _derive(args) -> int:
    from ..model.codegen.cache import ensure
    from ..model.symbolic.components import resolve_effects

    start = time.perf_counter()
    if args.prebuilt:
        from ..diagnose.candidates import default_diagnosis_models
        from ..model.codegen.cache import write_prebuilt

        if args.effects is not None or args.out is not None:
            raise UsageError("--prebuilt derives the default diagnosis' models and the manifests' sets: give it no "
                             "--effects or --out")
        sets = [([e.name for e in effects], effects) for effects in default_diagnosis_models()]
        sets += (_assisted_vehicle_sets() + _assist_type_sets() + _signature_truth_sets() + _suggestion_shape_sets()
                 + _held_form_sets() + _example_effect_sets())
        for path in args.manifests:
            spec = _manifest_spec(path)
            sets.append((spec, resolve_effects(spec)))
        # after the manifests: a set both ship keeps the manifest's spec
        sets += _ablation_sets() + _spec_sets(DOCUMENTED_SPECS)
        written = write_prebuilt(sets)
        print(f"pre-derived {len(written) // 2} models -> {written[0].parent} ({time.perf_counter() - start:.1f} s)")
        return 0
    if args.manifests:
        raise UsageError(f"{args.manifests[0]}: manifests are read only with --prebuilt")
    manifest = ensure(resolve_effects(args.effects), note_cached=True)
    if args.out:
        from ..tables import write_json  # numpy: imported where a manifest is written, not for --help

        write_json(args.out, manifest)
    elapsed = time.perf_counter() - start
    print(f"{'derived' if manifest['built_now'] else 'cached'} {','.join(manifest['effects']) or 'none'} -> "
          f"{manifest['directory']} ({elapsed:.1f} s)")
    return 0
