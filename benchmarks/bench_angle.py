"""What fitting the handwheel angle costs: one replay with and without the angle, with and without a lash.

The replay of an 18 s record (the unladen cycle of a free run, logged at 50 Hz with a 12-bit rack and a 14-bit
angle, as in tests/diagnose/test_angle.py) is timed four ways: the torque alone (the torque-only diagnosis's
replay), the torque with the handwheel angle (the solve's outputs: the twist at 5 ms, the column angle), each for
the paper's model and with a rack lash (whose twist is integrated through the dead band's law). Then the whole
diagnosis of that record with and without --angle. Medians of REPEATS (replays) and of DIAGNOSES (diagnoses),
ratios to the torque-only replay and diagnosis. Run:

    PYTHONPATH=src python benchmarks/bench_angle.py [out.json]

Measured on the 2-core development machine (shared with another job, load 6, `nice`), medians of 15: a replay of the
paper's model 0.075 s for the torque, 0.107 s with the angle (x1.4); with the lash 0.056 s and 0.191 s (the twist
through the dead band's law, x3.4). The diagnosis of the lash record (medians of 3): 10.2 s torque-only (lash
unobservable), 39.1 s with the angle (x3.9: every replay with outputs, the lash now refitted and evidenced, its
replay uncertainty estimated again, and a second start of each refit from the file's column).
"""

from __future__ import annotations

import dataclasses
import json
import statistics
import sys
import time

from parksteer.diagnose.problem import prepare_file
from parksteer.diagnose.replay import Replay
from parksteer.diagnose.select import diagnose
from parksteer.diagnose.settings import DEFAULT_SETTINGS
from parksteer.model.symbolic.components import resolve_effects
from parksteer.parameters import load_parameters
from parksteer.synthetic.datasets import clean_run, hand
from parksteer.synthetic.example import example_logger
from parksteer.synthetic.logger import synthetic_measurement

REPEATS = 15
DIAGNOSES = 3


def record(params):
    clean = clean_run(params, "unladen", "ground", hand(params, 11), "+rack_lash", {"rack_lash.lash": 0.0002})
    logger = example_logger(params)
    logger = dataclasses.replace(logger, seed=61, column_bits={"handwheel_angle_rad": 14, "rack_m": 12},
                                 noise_rms={**logger.noise_rms, "handwheel_angle_rad": 2e-4, "rack_m": 2e-5})
    return synthetic_measurement(clean["time_s"], {k: v for k, v in clean.items() if k != "time_s"}, logger,
                                 case="unladen", surface="ground", source="benchmarks/bench_angle.py")


def median_s(function, repeats: int) -> float:
    function()  # warm: the compiled model loaded, the run prepared
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    params = load_parameters()
    measurement = record(params)
    f = prepare_file(measurement, label="lash")
    out = {"replay_s": {}, "diagnosis_s": {}}
    for model, spec, overrides in (("paper", None, {}), ("rack_lash", "+rack_lash", {"rack_lash.lash": 0.0002})):
        replay = Replay(resolve_effects(spec), f.case, f.surface, params, f.rack, f.time_s)
        out["replay_s"][f"{model}_torque"] = median_s(lambda: replay.torque(overrides), REPEATS)
        out["replay_s"][f"{model}_with_angle"] = median_s(lambda: replay.solve(overrides, outputs=True), REPEATS)
    for label, settings in (("torque", DEFAULT_SETTINGS),
                            ("with_angle", dataclasses.replace(DEFAULT_SETTINGS, use_handwheel_angle=True))):
        times = []
        for _ in range(DIAGNOSES):
            start = time.perf_counter()
            diagnose([prepare_file(measurement, label="lash")], params, settings=settings, workers=1)
            times.append(time.perf_counter() - start)
        out["diagnosis_s"][label] = statistics.median(times)
    base = out["replay_s"]["paper_torque"]
    out["replay_ratio_to_paper_torque"] = {k: v / base for k, v in out["replay_s"].items()}
    out["diagnosis_ratio"] = out["diagnosis_s"]["with_angle"] / out["diagnosis_s"]["torque"]
    text = json.dumps(out, indent=1)
    print(text)
    if len(sys.argv) > 1:
        with open(sys.argv[1], "w", encoding="utf-8") as handle:
            handle.write(text + "\n")


if __name__ == "__main__":
    main()
