"""What decides the assisted diagnosis on the independent truth: the owner's file against truths that share more
with it.

The assisted benchmark on an independent truth (parksteer.experiments.assisted_truth) diagnoses its records with
the owner's file: the gear's data sheet and the map point by point, the motor's friction at the template's assumed
0.02 N m. The truth's own rotor friction is 0.012 N m, Coulomb saturated linearly below 1 rad/s of the rotor, and its
worm passes from driving to back-driven over the same 1 rad/s (0.4 mm/s of the rack); the model's frictions and its
gear's direction pass over tanh(1000 s/m x rack speed), about 1 mm/s of the rack (2.25 rad/s of this rotor). The
rungs change the truth, not the file, one owner-unknown at a time:

- ``as_is``: the benchmark's truth;
- ``friction``: the truth's rotor friction the file's 0.02 N m;
- ``band``: the truth's friction and direction band 2.25 rad/s (as wide as the model's smoothing);
- ``both``: both.

Each rung diagnoses the same cases (nulls on the benchmark's eight hands, the four hidden candidates at 4 floors on
one hand; `--tiers rack,angle`), about 5 s a case. Run:

    PYTHONPATH=src python benchmarks/bench_assisted_truth_ladder.py [--tiers rack] [out.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def rungs(gear):
    return {"as_is": gear, "friction": replace(gear, motor_friction_Nm=0.02),
            "band": replace(gear, friction_speed_rad_s=2.25, direction_speed_rad_s=2.25),
            "both": replace(gear, motor_friction_Nm=0.02, friction_speed_rad_s=2.25, direction_speed_rad_s=2.25)}


def main(argv=None) -> int:
    from parksteer.experiments.assisted_truth import TruthDesign, run
    from parksteer.model.symbolic.components import discover_effects
    from parksteer.vehicle import load_vehicle

    parser = argparse.ArgumentParser()
    parser.add_argument("out", nargs="?")
    parser.add_argument("--tiers", default="rack,angle")
    parser.add_argument("--rungs", default="as_is,friction,band,both")
    args = parser.parse_args(argv)
    discover_effects()
    vehicle = ROOT / "data" / "vehicles" / "polo_vi.toml"
    params = load_vehicle(vehicle)
    base = TruthDesign(tiers=tuple(args.tiers.split(",")), hidden_variations=("uneven_strokes",), floors=(4.0,),
                       out_of_class_variations=())
    out = {}
    for name in args.rungs.split(","):
        design = replace(base, gear=rungs(base.gear)[name])
        rows, summary = run(params, vehicle, design)
        out[name] = {tier: {"named": s["targets"]["named"]["count"],
                            "null_adequate": s["targets"]["null_adequate"]["count"],
                            "false_alarms": [f"{a['name']}: {a['verdict']} {a['effect']}" for a in s["false_alarms"]],
                            "missed": [f"{m['name']}: {m['verdict']} {m['effect']}" for m in s["missed"]]}
                     for tier, s in summary["routes"]["map"].items()}
        for tier, s in out[name].items():
            print(f"{name:9s} {tier:6s} named {s['named'][0]}/{s['named'][1]}  nulls adequate "
                  f"{s['null_adequate'][0]}/{s['null_adequate'][1]}  false alarms: {'; '.join(s['false_alarms'])}",
                  flush=True)
    if args.out:
        Path(args.out).write_text(json.dumps(out, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
