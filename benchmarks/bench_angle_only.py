"""Angle-only records (a car's own bus: handwheel angle and torque, no rack) against the same records with their rack.

Each record is a variation of :mod:`parksteer.synthetic.variations` (its own hand and logger) whose logger also logs
the handwheel angle (a 14- or 16-bit encoder on +-16 rad, 2e-4 rad of noise), with nothing hidden or with a library
effect hidden at 3.5 torque converter steps RMS (:func:`parksteer.experiments.variations.hidden_strength`). Each is
written twice, with its rack channel and with that column removed, and diagnosed from the file as a user would
(``parksteer diagnose FILE --json``); the angle-only file's rack is then derived from the angle and torque
(:func:`parksteer.measure.column.rack_from_angle`). Printed: per record, both verdicts and named effects and the
calibrated RMS error over the noise floor; then the rates (nulls adequate, hidden effects named) of each.
Run:

    PYTHONPATH=src python benchmarks/bench_angle_only.py [out.json]

Measured (2-core development machine, 6 hands/loggers x (null, rack_stiction, column_friction) = 18 records, about
4 minutes): with the rack, nulls adequate 6/6 and hidden effects named 11/12; angle only, 6/6 and 11/12, the same
records (the one unnamed, a column friction at 3.5 steps of a 12-bit torque, is adequate either way). Nulls at
0.92-1.09 noise floors with the rack, 0.99-1.05 angle only. Before the rack was derived through the damped
column, the angle_channel null (seed 1) was unexplained at 1.190 floors; before the pause test allowed the angle's
step, the pauses null was unexplained at 1.236.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import sys
import tempfile
from pathlib import Path

from parksteer.cli import main
from parksteer.experiments.variations import hidden_strength
from parksteer.measure.io import Measurement, format_measurement
from parksteer.parameters import load_parameters
from parksteer.measure.converter import quantisation_step
from parksteer.synthetic.variations import variation_by_name, variation_record

# (variation, angle converter bits): hands and loggers of the variation benchmark, each logging an angle too
GRID = (("rest_after_stop", 14), ("pauses", 14), ("mid_stroke_end", 16), ("lock_overshoot", 14),
        ("rate_8pc_50Hz", 16), ("rack_8bit_torque_12bit", 14))
HIDDEN = (None, "rack_stiction", "column_friction")
STEPS = 3.5
SEED = 20261126


def diagnose(path: Path) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["diagnose", str(path), "--jobs", "1", "--quiet", "--json"]) == 0
    return json.loads(out.getvalue())


def summary(result: dict) -> dict:
    return {"verdict": result["verdict"], "effect": result["effect"],
            "over_floor": result["selection"]["calibrated_over_floor"]}


def main_(out_path: str | None) -> int:
    params = load_parameters()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for i, (name, bits) in enumerate(GRID):
            variation = variation_by_name(name)
            hand, logger = variation.settings(SEED + 10 * i)
            logger = dataclasses.replace(logger, angle_bits=bits)
            step = quantisation_step(logger.torque_full_scale_Nm, logger.torque_bits)
            for hidden in HIDDEN:
                effects = overrides = None
                if hidden is not None:
                    files = [("unladen", "ground", hand, logger)]
                    key, strength, _change, _observable = hidden_strength(params, files, {}, hidden, STEPS * step)
                    effects, overrides = f"+{hidden}", {key: strength}
                record = variation_record(params, hand, logger, effects=effects, overrides=overrides)
                with_rack = folder / f"{name}_{hidden}_rack.csv"
                angle_only = folder / f"{name}_{hidden}_angle.csv"
                with_rack.write_text(format_measurement(record), encoding="utf-8")
                columns = {k: v for k, v in record.columns.items() if k != "rack_m"}
                angle_only.write_text(format_measurement(Measurement(None, columns, record.metadata)),
                                      encoding="utf-8")
                row = {"variation": name, "angle_bits": bits, "hidden": hidden,
                       "rack": summary(diagnose(with_rack)), "angle_only": summary(diagnose(angle_only))}
                rows.append(row)
                r, a = row["rack"], row["angle_only"]
                print(f"{name:16s} {bits:2d} bit  {str(hidden):16s} rack: {r['verdict']:11s} {str(r['effect']):16s} "
                      f"{r['over_floor']:.3f}   angle only: {a['verdict']:11s} {str(a['effect']):16s} "
                      f"{a['over_floor']:.3f}", flush=True)
    for which in ("rack", "angle_only"):
        nulls = [r[which] for r in rows if r["hidden"] is None]
        hidden = [(r["hidden"], r[which]) for r in rows if r["hidden"] is not None]
        adequate = sum(n["verdict"] == "adequate" for n in nulls)
        named = sum(d["effect"] == h for h, d in hidden)
        print(f"{which:10s}: nulls adequate {adequate}/{len(nulls)}, hidden effects named {named}/{len(hidden)}")
    if out_path:
        Path(out_path).write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main_(sys.argv[1] if len(sys.argv) > 1 else None))
