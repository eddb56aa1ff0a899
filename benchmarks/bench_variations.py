"""Benchmark of the diagnosis on records its generator did not make (not a test): one row per variation.

    python benchmarks/bench_variations.py OUT.json [--full] [--hidden rack_stiction,column_friction]
        [--steps 3.5] [--seeds 1]

Each variation of :func:`parksteer.synthetic.variations.null_variations` (another hand: a smooth
3-8 % rate variation, pauses, a record cut mid-stroke or going on at rest after the stop; another
logger: a 12-bit rack beside an 8-bit torque at 50, 100 or 200 Hz; the torque from the
prescribed-rack solve) makes one file of the unladen car on the ground, base parameters moved off
the parameter file's values (the benchmark's perturbation, config/config.yaml). In each variation:

- a null (nothing hidden): a false alarm is a ``missing`` verdict; ``adequate`` is the right answer;
- each hidden library effect of ``--hidden`` at ``--steps`` converter steps of torque RMS (strength found by
  one linearised estimate from a small probe and one secant step on the prescribed-rack solve): named when
  the diagnosis names it first or in its indistinguishable group;
- coverage: the fraction of the 95 % intervals of the reported model (the calibrated base, or with the named
  effect when the verdict is ``missing``: its strength too) that hold the true values.

The default grid (six variations, one seed, a null and rack stiction in each: twelve diagnoses) takes a few
minutes on 2 cores, too long for the pipeline's DAG; ``--full`` adds seeds and hidden effects.
Prints the table per variation and writes every record's outcome as JSON.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("--full", action="store_true", help="three seeds and three hidden effects")
    parser.add_argument("--hidden", default="rack_stiction", help="comma-separated library effects to hide")
    parser.add_argument("--steps", type=float, default=3.5, help="hidden size, converter steps of torque RMS")
    parser.add_argument("--seeds", type=int, default=1, help="seeds per variation")
    parser.add_argument("--only", default="", help="comma-separated variation names (default: all)")
    args = parser.parse_args(argv)
    hidden = [h for h in args.hidden.split(",") if h]
    seeds = args.seeds
    if args.full:
        hidden, seeds = ["rack_stiction", "column_friction", "kingpin_friction"], 3

    import numpy as np
    import yaml

    from parksteer.diagnose.problem import prepare_file
    from parksteer.diagnose.select import diagnose
    from parksteer.model.numeric.simulate import simulate
    from parksteer.model.symbolic.components import discover_effects, strength_parameter
    from parksteer.parameters import load_parameters
    from parksteer.synthetic.datasets import perturbed_base
    from parksteer.synthetic.logger import quantisation_step
    from parksteer.synthetic.variations import null_variations, variation_rack, variation_record
    from parksteer.tables import write_json

    params = load_parameters()
    config = yaml.safe_load((Path(__file__).resolve().parents[1] / "config" / "config.yaml").read_text("utf-8"))
    perturbation = {str(k): float(v) for k, v in config["benchmark"]["perturbation"].items()}
    registry = discover_effects()

    def hidden_strength(effect: str, hand, base: dict, target_Nm: float) -> float:
        """Strength changing the clean torque by `target_Nm` RMS: linear estimate from a probe, one secant step."""
        key = strength_parameter(registry[effect], params)
        drive = variation_rack(params, hand)

        def change(s: float) -> float:
            runs = [simulate("unladen", effects=f"+{effect}" if s else None, overrides={**base, key.key: s} if s else base,
                             rack_drive=drive, params=params, output_dt_s=0.01).columns["handwheel_torque_Nm"]
                    for s in (0.0, s)]
            return float(np.sqrt(np.mean((np.asarray(runs[1]) - np.asarray(runs[0])) ** 2)))

        s0 = key.upper * 1e-2
        d0 = change(s0)
        s1 = min(s0 * target_Nm / d0, key.upper)
        d1 = change(s1)
        if d1 <= 0 or abs(math.log(d1 / d0)) < 1e-9:
            return s1
        slope = math.log(d1 / d0) / math.log(s1 / s0) if s1 != s0 else 1.0  # secant in log-log
        return min(s1 * (target_Nm / d1) ** (1.0 / max(slope, 0.1)), key.upper)

    records = []
    for seed in range(seeds):
        for name, hand, logger in null_variations(seed * 10):
            if args.only and name not in args.only.split(","):
                continue
            base = perturbed_base(params, 9000 + seed * 10 + len(records), perturbation)
            step = quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
            for effect in [None] + hidden:
                overrides = dict(base)
                if effect is not None:
                    key = strength_parameter(registry[effect], params).key
                    overrides[key] = hidden_strength(effect, hand, base, args.steps * step)
                record = variation_record(params, hand, logger, overrides=overrides,
                                          effects=f"+{effect}" if effect else None)
                start = time.perf_counter()
                d = diagnose([prepare_file(record, "unladen", name)], params)
                wall = time.perf_counter() - start
                group = [s.effect for s in d.indistinguishable]
                # the intervals of the model the diagnosis reports: with the named effect when it says missing
                fit = d.best.refit if d.verdict == "missing" and d.best.refit is not None else d.calibration
                intervals = fit.intervals(d.problem)
                truth = dict(overrides) if d.verdict != "missing" or d.effect == effect else dict(base)
                covered = {k: bool(v["ci95"][0] <= truth[k] <= v["ci95"][1]) for k, v in intervals.items()
                           if k in truth}
                floor = d.problem.files[0].noise.total_rms
                stats = fit_statistics_ratio(d)
                row = {"variation": name, "seed": seed, "hidden": effect or "nothing", "verdict": d.verdict,
                       "effect": d.effect, "indistinguishable": group,
                       "named": effect is not None and (d.effect == effect or (d.verdict == "missing" and effect in group)),
                       "false_alarm": effect is None and d.verdict == "missing",
                       "calibrated_over_floor": stats, "covered": covered,
                       "intervals": {k: v["ci95"] for k, v in intervals.items()}, "truth": truth,
                       "wall_s": wall, "noise_floor_Nm": floor}
                records.append(row)
                print(f"{name:16s} seed {seed} hidden {row['hidden']:16s} -> {d.verdict:11s} {d.effect or '':16s} "
                      f"{stats:5.2f} floors  covered {sum(covered.values())}/{len(covered)}  {wall:5.1f} s",
                      file=sys.stderr, flush=True)

    table = {}
    for name in dict.fromkeys(r["variation"] for r in records):
        rows = [r for r in records if r["variation"] == name]
        nulls = [r for r in rows if r["hidden"] == "nothing"]
        hid = [r for r in rows if r["hidden"] != "nothing"]
        cover = [c for r in rows for c in r["covered"].values()]
        table[name] = {"named": _frac(r["named"] for r in hid), "false_alarm": _frac(r["false_alarm"] for r in nulls),
                       "adequate_on_nulls": _frac(r["verdict"] == "adequate" for r in nulls),
                       "coverage": _frac(cover), "null_over_floor": [r["calibrated_over_floor"] for r in nulls],
                       "wall_s_median": float(np.median([r["wall_s"] for r in rows]))}
    write_json(args.out, {"steps": args.steps, "hidden": hidden, "seeds": seeds, "table": table, "records": records})
    print(f"{'variation':16s} {'named':>6s} {'false':>6s} {'adequate':>8s} {'cover':>6s} {'null/floor':>10s} {'time':>6s}")
    for name, t in table.items():
        print(f"{name:16s} {_fmt(t['named'])} {_fmt(t['false_alarm'])} {_fmt(t['adequate_on_nulls']):>8s} "
              f"{_fmt(t['coverage'])} {' '.join(f'{v:.2f}' for v in t['null_over_floor']):>10s} {t['wall_s_median']:5.1f}s")
    return 0


def fit_statistics_ratio(d) -> float:
    """Calibrated base model's weighted RMS error over the noise floor."""
    from parksteer.diagnose.problem import fit_statistics

    stats = fit_statistics(d.problem, d.calibration.predictions)
    return stats["weighted_rms_Nm"] / stats["noise_floor_Nm"]


def _frac(values) -> float | None:
    values = list(values)
    return sum(bool(v) for v in values) / len(values) if values else None


def _fmt(value) -> str:
    return "     -" if value is None else f"{value:6.2f}"


if __name__ == "__main__":
    sys.exit(main())
