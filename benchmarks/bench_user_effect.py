"""The loop a user runs, measured end to end: a record with a friction form outside the library, diagnosed from its
file (`unexplained`), the suggested effect written (`--suggest-effect missing.py`) and passed back as it stands
(`--effects=+missing.py`, nothing edited); and nulls, which must get no suggestion.

    python benchmarks/bench_user_effect.py [--records 2] [--nulls 3] [--steps 5] [--seed 5200] [--json OUT.json]

Three friction forms that no candidate of the library has, declared here (the diagnosis never sees them):

- centre friction: a rack friction peaked straight ahead, ``A / (1 + (x / 12 mm)^2) tanh(beta v)`` (a rack bore
  worn tight at the centre, where the car steers most);
- one-way drag: a drag only while the rack moves left, ``A (1 - tanh(beta v)) / 2 tanh(beta v)`` (a seal lip);
- pinched bearing: a column bearing pinched once per column turn, a friction torque
  ``A (1 + cos(theta_c - 0.9)) / 2 tanh(beta theta_c' / i)`` (an oval bearing seat; i the handwheel-to-rack ratio).

Each record is made as the signature benchmark makes its records (parksteer.experiments.outoflibrary: a hand and a
logger of the variation benchmark, its quantisation and noise, the base parameters perturbed as the benchmarks
perturb them, the prescribed-rack solve), the truth sized to `steps` converter steps of clean torque change RMS;
the nulls are the same records with nothing hidden. Every diagnosis is the command line's, on the written file, in
a process of its own, as a user runs it (`--torque-lag` where the logger delays its torque channel).

Scored: the signature's class is the form's (dissipative, direction, and dissipative x column for the pinched
bearing); the diagnosis of the record says `unexplained` and writes a suggestion; the suggestion passed back gives
`adequate` (the bar: 5 of 6); no null gets a suggestion. Printed: one line a record, then the counts.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import sympy as sp

from parksteer.measure.converter import quantisation_step
from parksteer.measure.io import write_measurement
from parksteer.model.symbolic.components import Effect, resolve_effects
from parksteer.model.symbolic.system import action_reaction, torque_between
from parksteer.parameters import Quantity, load_parameters
from parksteer.synthetic.datasets import BASE_PERTURBATION
from parksteer.synthetic.datasets import perturbed_base
from parksteer.synthetic.size_search import rms_difference
from parksteer.synthetic.variations import VARIATIONS, variation_rack, variation_record

PROBE_DT_S = 0.01


def _strength(name: str, unit: str, upper: float) -> tuple[Quantity, ...]:
    return (Quantity(f"{name}.strength", unit, 0.0, upper, lower_inclusive=True, default=0.0,
                     source="benchmark truth; 0 = absent"),)


class CentreFriction(Effect):
    name = "bench_centre_friction"
    description = "Rack friction peaked at the centre, A / (1 + (x / 12 mm)^2) tanh(beta v)"
    in_default_set = False
    diagnosis_candidate = False
    quantities = _strength(name, "N", 1e5)
    uses = (f"{name}.strength", "steering.friction_smoothing")

    def loads(self, model):
        k = model.kinematics
        s = sp.tanh(model.p("steering.friction_smoothing") * model.rack_u)
        force = model.p(f"{self.name}.strength") / (1 + (model.rack_q / 0.012) ** 2) * s
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


class OneWayDragLeft(Effect):
    name = "bench_one_way_drag"
    description = "Drag only while the rack moves left, A (1 - tanh(beta v)) / 2 tanh(beta v)"
    in_default_set = False
    diagnosis_candidate = False
    quantities = _strength(name, "N", 1e5)
    uses = (f"{name}.strength", "steering.friction_smoothing")

    def loads(self, model):
        k = model.kinematics
        s = sp.tanh(model.p("steering.friction_smoothing") * model.rack_u)
        force = model.p(f"{self.name}.strength") * (1 - s) / 2 * s
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)


class PinchedBearing(Effect):
    name = "bench_pinched_bearing"
    description = "Column bearing friction pinched once per turn, A (1 + cos(theta_c - 0.9)) / 2 tanh(beta w / i)"
    in_default_set = False
    diagnosis_candidate = False
    quantities = _strength(name, "N m", 10.0)
    uses = (f"{name}.strength", "steering.friction_smoothing", "steering.handwheel_to_rack_ratio")

    def loads(self, model):
        k = model.kinematics
        rate = k.column_rate / model.p("steering.handwheel_to_rack_ratio")
        torque = (model.p(f"{self.name}.strength") * (1 + sp.cos(k.column_angle - 0.9)) / 2
                  * sp.tanh(model.p("steering.friction_smoothing") * rate))
        return torque_between(-torque, k.B.y, k.column_frame, k.B)


FORMS = (CentreFriction(), OneWayDragLeft(), PinchedBearing())
# the signature class each form should be read as (parksteer.diagnose.signature): the pinched bearing is a friction
# shaped by the column angle, the product class dissipative x column
EXPECTED_CLASS = {"bench_centre_friction": "dissipative", "bench_one_way_drag": "direction",
                  "bench_pinched_bearing": "dissipative_column"}


def make_record(params, form: Effect | None, steps: float, variation, seed: int):
    """(measurement, truth strength): the variation's hand and logger, the perturbed base, `form` sized to `steps`
    converter steps of clean torque change RMS (one probe: each form is linear in its strength)."""
    from parksteer.model.numeric.simulate import simulate

    hand, logger = variation.settings(seed)
    base = perturbed_base(params, seed, BASE_PERTURBATION)
    if form is None:
        return variation_record(params, hand, logger, overrides=base), 0.0
    effects = [*resolve_effects(None), form]
    key = f"{form.name}.strength"
    drive = variation_rack(params, hand)

    def torque(strength: float) -> np.ndarray:
        return np.asarray(simulate("unladen", effects=effects, overrides={**base, key: strength}, rack_drive=drive,
                                   params=params, output_dt_s=PROBE_DT_S).columns["handwheel_torque_Nm"])

    probe = 100.0 if form.quantities[0].unit == "N" else 0.5
    target = steps * quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
    strength = probe * target / rms_difference(torque(probe), torque(0.0))
    return variation_record(params, hand, logger, overrides={**base, key: strength}, effects=effects), strength


def parksteer(*argv: str) -> tuple[dict, str, float]:
    """(JSON, stderr, seconds) of one `parksteer` command in a process of its own."""
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "parksteer.cli", *argv, "--json", "--jobs", "1"],
                          capture_output=True, text=True, env=os.environ.copy())
    if done.returncode != 0:
        raise RuntimeError(f"parksteer {' '.join(argv)} failed:\n{done.stderr}")
    return json.loads(done.stdout), done.stderr, time.perf_counter() - start


def over_floor(result: dict) -> float:
    return result["statistics"]["calibrated"]["weighted_rms_Nm"] / result["noise_floor_Nm"]


def run(args) -> list[dict]:
    params = load_parameters()
    cases = []
    k = 0
    for form in FORMS:
        for _ in range(args.records):
            cases.append((form, VARIATIONS[args.first_variation + k % 6], args.seed + k))
            k += 1
    for _ in range(args.nulls):
        cases.append((None, VARIATIONS[args.first_variation + k % 6], args.seed + k))
        k += 1
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_user_effect_") as temporary:
        folder = Path(args.keep or temporary)
        folder.mkdir(parents=True, exist_ok=True)
        for i, (form, variation, seed) in enumerate(cases):
            name = f"{form.name if form else 'null'}_{i}"
            measurement, strength = make_record(params, form, args.steps, variation, seed)
            record = folder / f"{name}.csv"
            write_measurement(record, measurement, params)
            lag = ["--torque-lag"] if variation.logger.torque_lag_s > 0.0 else []
            missing = folder / f"{name}_missing.py"
            first, log, first_s = parksteer("diagnose", str(record), *lag, "--suggest-effect", str(missing))
            row = {"name": name, "form": form.name if form else None, "variation": variation.name, "seed": seed,
                   "strength": strength, "verdict": first["verdict"], "named": first["effect"],
                   "class": (first.get("signature") or {}).get("class"),
                   "over_floor": over_floor(first), "suggested": missing.is_file(),
                   "promised": (first.get("suggestion") or {}).get("after_over_floor"),
                   "diagnosis_s": first_s, "passed_back": None, "after_over_floor": None, "pass_back_s": None}
            if missing.is_file():
                again, _, again_s = parksteer("diagnose", str(record), *lag, f"--effects=+{missing}")
                row.update(passed_back=again["verdict"], after_over_floor=over_floor(again), pass_back_s=again_s,
                           named_after=again["effect"])
            rows.append(row)
            after = "-" if row["after_over_floor"] is None else f"{row['after_over_floor']:.2f}"
            promised = "-" if row["promised"] is None else f"{row['promised']:.2f}"
            print(f"{name:28s} {variation.name:24s} {row['verdict']:11s} class {str(row['class']):11s} "
                  f"floors {row['over_floor']:5.2f} -> promised {promised:>5s}, passed back {after:>5s} "
                  f"{str(row['passed_back']):11s} ({first_s:.0f} s + {row['pass_back_s'] or 0:.0f} s)",
                  file=sys.stderr, flush=True)
    return rows


def summary(rows: list[dict]) -> dict:
    hidden = [r for r in rows if r["form"] is not None]
    nulls = [r for r in rows if r["form"] is None]
    return {
        "records": len(hidden), "nulls": len(nulls),
        "unexplained": sum(r["verdict"] == "unexplained" for r in hidden),
        "class_right": sum(r["class"] == EXPECTED_CLASS[r["form"]] for r in hidden),
        "suggested": sum(r["suggested"] for r in hidden),
        "adequate_when_passed_back": sum(r["passed_back"] == "adequate" for r in hidden),
        "by_form": {f.name: {"adequate": sum(r["passed_back"] == "adequate" for r in hidden if r["form"] == f.name),
                             "records": sum(r["form"] == f.name for r in hidden)} for f in FORMS},
        "suggestions_on_nulls": [r["name"] for r in nulls if r["suggested"]],
        "null_verdicts": [r["verdict"] for r in nulls],
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=2, help="records per form")
    parser.add_argument("--nulls", type=int, default=3)
    parser.add_argument("--steps", type=float, default=5.0, help="truth size, converter steps of torque RMS")
    parser.add_argument("--seed", type=int, default=5200)
    parser.add_argument("--first-variation", type=int, default=0, help="variations from this place on (0 or 6)")
    parser.add_argument("--json", help="write the rows and the summary here")
    parser.add_argument("--keep", help="keep the records and the suggested files in this folder")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    rows = run(args)
    s = summary(rows)
    print(f"\n{s['records']} records of 3 forms, {s['nulls']} nulls, {time.perf_counter() - start:.0f} s")
    print(f"class read right {s['class_right']} of {s['records']} (bar 5; the pinched bearing as dissipative x column)")
    print(f"unexplained {s['unexplained']} of {s['records']}, suggestion written {s['suggested']} of {s['records']}, "
          f"adequate when passed back as it stands {s['adequate_when_passed_back']} of {s['records']} (bar 5)")
    for form, t in s["by_form"].items():
        print(f"  {form:24s} adequate {t['adequate']} of {t['records']}")
    print(f"nulls: verdicts {', '.join(s['null_verdicts'])}; suggestions on nulls: "
          f"{', '.join(s['suggestions_on_nulls']) or 'none'}")
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "summary": s}, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
