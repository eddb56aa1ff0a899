"""What decides the assisted diagnosis on the independent truth: the owner's file against truths that share more
with it.

The assisted benchmark on an independent truth (parksteer.experiments.assisted_truth) diagnoses its records with
the owner's file: the gear's data sheet and the map point by point, the motor's friction at the template's assumed
0.02 N m and the band its friction and the worm's direction change over at the assumed ``friction_speed`` (rad/s
of the rotor; the model's tanh(rotor speed / w)). The truth's own rotor friction is 0.012 N m, Coulomb saturated
linearly below 1 rad/s of the rotor, and its worm passes from driving to back-driven over the same 1 rad/s (0.4 mm/s
of the rack); the car-wide friction smoothing, tanh(1000 s/m x rack speed), is about 1 mm/s of the rack (2.25 rad/s of
this rotor). The rungs change the truth, not the file, one owner-unknown at a time:

- ``as_is``: the benchmark's truth;
- ``friction``: the truth's rotor friction the file's 0.02 N m;
- ``band``: the truth's friction and direction band 2.25 rad/s (as wide as the car-wide smoothing);
- ``both``: both;
- ``model``: the nulls made by the model's own assisted replay (the Polo file's assist, its table) on the same hands,
  logged by the same loggers (rack, or the handwheel angle through the column and the torsion bar in series), and
  diagnosed with the Polo file: what the method does when the file is the truth.

Each rung diagnoses the same cases (nulls on the benchmark's eight hands, the four hidden candidates at 4 floors on
one hand; `--tiers rack,angle`), about 5 s a case; `--routes map,identified` diagnoses each also with the file
`parksteer assist identify` writes from the tier's baseline record, `--outclass` adds the four out-of-class forms at 3
floors (the bar of the owner's routes: `--rungs as_is --routes map,identified --outclass`). Run:

    PYTHONPATH=src python benchmarks/bench_assisted_truth_ladder.py [--tiers rack] [--routes map] [out.json]

Other cars of the truth: `--seed`, with `--hands`, `--floors`, `--replicates` and `--bits` for the cases, e.g. the
two quoted in docs/assist_diagnosis.md:

    PYTHONPATH=src python benchmarks/bench_assisted_truth_ladder.py --rungs as_is --routes map,identified --outclass \
        --seed 777 --hands mid_stroke_end,rate_8pc_50Hz,lock_overshoot --outclass-hand pauses --floors 3 \
        --replicates 2 --bits 12

and `--seed 31337 --hands rest_after_stop,pauses,uneven_strokes --outclass-hand uneven_strokes --replicates 1`.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
from parksteer.experiments.assisted_truth import run  # noqa: E402
from parksteer.experiments.assisted_truth_design import TruthDesign  # noqa: E402


def rungs(gear):
    """The truth's gear at each rung (module docstring)."""
    return {"as_is": gear, "friction": replace(gear, motor_friction_Nm=0.02),
            "band": replace(gear, friction_speed_rad_s=2.25, direction_speed_rad_s=2.25),
            "both": replace(gear, motor_friction_Nm=0.02, friction_speed_rad_s=2.25, direction_speed_rad_s=2.25)}


def main(argv=None) -> int:
    from parksteer.model.symbolic.components import discover_effects
    from parksteer.vehicle import load_vehicle

    parser = argparse.ArgumentParser()
    parser.add_argument("out", nargs="?")
    parser.add_argument("--tiers", default="rack,angle")
    parser.add_argument("--rungs", default="as_is,friction,band,both,model")
    parser.add_argument("--routes", default="map", help="the files diagnosed with: map, identified or both")
    parser.add_argument("--outclass", action="store_true", help="also the four out-of-class forms at 3 floors")
    parser.add_argument("--seed", type=int, default=TruthDesign.seed, help="the design's seed: another set of cars")
    parser.add_argument("--hands", default="uneven_strokes", help="the hands of the hidden cases")
    parser.add_argument("--outclass-hand", default="uneven_strokes", help="the hand of the out-of-class cases")
    parser.add_argument("--floors", type=float, default=4.0, help="the hidden cases' size in noise floors")
    parser.add_argument("--replicates", type=int, default=1, help="null records on each of the eight hands")
    parser.add_argument("--bits", type=int, choices=(10, 11, 12), help="one torsion-bar converter (default: the "
                        "design's three)")
    args = parser.parse_args(argv)
    discover_effects()
    vehicle = ROOT / "data" / "vehicles" / "polo_vi.toml"
    params = load_vehicle(vehicle)
    converters = TruthDesign.torque_converters
    if args.bits is not None:
        converters = tuple(c for c in converters if c[0] == args.bits)
    base = TruthDesign(tiers=tuple(args.tiers.split(",")), hidden_variations=tuple(args.hands.split(",")),
                       floors=(args.floors,), null_replicates=args.replicates, seed=args.seed,
                       torque_converters=converters,
                       out_of_class_variations=(args.outclass_hand,) if args.outclass else (),
                       routes=tuple(args.routes.split(",")))
    out = {}
    for name in args.rungs.split(","):
        if name == "model":
            out[name] = model_nulls(params, base)
            for tier, counts in out[name].items():
                print(f"{name:9s} {tier:6s} nulls adequate {counts[0]}/{counts[1]}", flush=True)
            continue
        design = replace(base, gear=rungs(base.gear)[name])
        rows, summary = run(params, vehicle, design)
        out[name] = {route: {tier: {
            "named": s["targets"]["named"]["count"], "null_adequate": s["targets"]["null_adequate"]["count"],
            "out_of_class_not_named": s["out_of_class_not_named"],
            "confident_wrong": s["targets"]["confident_wrong_out_of_class"]["value"],
            "false_alarms": [f"{a['name']}: {a['verdict']} {a['effect']}" for a in s["false_alarms"]],
            "missed": [f"{m['name']}: {m['verdict']} {m['effect']}" for m in s["missed"]]}
            for tier, s in tiers.items()} for route, tiers in summary["routes"].items()}
        for route, tiers in out[name].items():
            for tier, s in tiers.items():
                print(f"{name:9s} {route:10s} {tier:6s} named {s['named'][0]}/{s['named'][1]}  nulls adequate "
                      f"{s['null_adequate'][0]}/{s['null_adequate'][1]}  out of class not named "
                      f"{s['out_of_class_not_named'][0]}/{s['out_of_class_not_named'][1]}  confident wrong "
                      f"{s['confident_wrong']}  false alarms: {'; '.join(s['false_alarms'])}", flush=True)
    if args.out:
        Path(args.out).write_text(json.dumps(out, indent=1), encoding="utf-8")
    return 0


def model_nulls(params, design) -> dict:
    """{tier: [adequate, nulls]} of the model's own assisted records on the design's null hands and loggers."""
    import tempfile

    from parksteer.diagnose.problem import load_files
    from parksteer.reporting.report import diagnosis_dict
    from parksteer.diagnose.select import diagnose
    from parksteer.experiments.assisted_truth import _logger, _write
    from parksteer.experiments.assisted_truth_design import cases
    from parksteer.experiments.benchmark import BENCHMARK_SETTINGS
    from parksteer.geometry import column_twist
    from parksteer.model.numeric.assist import effects_with_assist
    from parksteer.model.symbolic.components import resolve_effects
    from parksteer.synthetic.assisted import assisted_clean
    from parksteer.synthetic.assisted_truth import column_of_pinion, truth_record
    from parksteer.synthetic.datasets import BASE_PERTURBATION, perturbed_base
    from parksteer.synthetic.variations import variation_by_name

    spec = effects_with_assist(None, params)
    effects, name = resolve_effects(spec), spec.lstrip("+")
    s = params.sections["steering"]
    k, c, bar = s["column_torsional_stiffness"], s["column_torsional_damping"], params[f"{name}.torsion_bar_stiffness"]
    series = k * bar / (k + bar)
    out: dict[str, list[int]] = {}
    with tempfile.TemporaryDirectory() as folder:
        for case in (c_ for c_ in cases(design) if c_.kind == "null"):
            hand, _ = variation_by_name(case.variation).settings(case.seed)
            base = perturbed_base(params, case.seed, BASE_PERTURBATION)
            clean = assisted_clean(params, hand, spec, design.case, overrides=base, dt_s=0.002)
            theta_c = column_of_pinion(s["handwheel_to_rack_ratio"] * clean["rack_m"], s["hooke_joint_angle"],
                                       s["hooke_joint_phase"])
            twist, _ = column_twist(clean["time_s"], clean["handwheel_torque_Nm"], series, c * series / k)
            clean["handwheel_angle_rad"] = theta_c + twist
            path = Path(folder) / f"{case.name}.csv"
            _write(path, truth_record(clean, _logger(design, case), design.case), params)
            result = diagnosis_dict(diagnose(load_files([path], params, assist=name), params, effects,
                                             settings=BENCHMARK_SETTINGS))
            counts = out.setdefault(case.tier, [0, 0])
            counts[0] += result["verdict"] == "adequate"
            counts[1] += 1
    return out


if __name__ == "__main__":
    sys.exit(main())
