"""Whether a change to the diagnosis's code leaves its answers unchanged: the JSON of five reference diagnoses,
before and after, compared number for number (the timings apart).

The records are synthetic (the variation benchmark's hands and loggers, and tests/diagnose/test_angle.py's angle
record): a null (rate_8pc_50Hz, seed 5), a rack stiction behind a 10 ms torque lag diagnosed with --torque-lag
(lag_10ms_50Hz, seed 8: the lag moves, and again with the named stiction, so the table runs twice), the same on two
workers, a column friction (rate_8pc_50Hz, seed 4) and a rack lash with --angle. Run, at the old code and at the
new:

    python benchmarks/same_diagnosis.py make OUT_BEFORE      # at the old revision
    python benchmarks/same_diagnosis.py make OUT_AFTER       # at the new one
    python benchmarks/same_diagnosis.py compare OUT_BEFORE OUT_AFTER

`compare` exits 1 and lists every differing value if any JSON differs; RENAMED maps JSON keys renamed on purpose
(old name -> new) so that a rename alone does not count as a change.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RENAMED = {"calibrated_weighted_rms_over_noise_floor": "calibrated_over_floor"}


def _records(folder: Path) -> dict[str, tuple[Path, list[str]]]:
    sys.path.insert(0, str(REPO / "tests" / "diagnose"))
    from parksteer.measure.io import write_measurement
    from parksteer.parameters import load_parameters
    from parksteer.synthetic.variations import variation_by_name, variation_record

    params = load_parameters()
    folder.mkdir(parents=True, exist_ok=True)

    def record(name, variation, seed, **hidden):
        path = folder / f"{name}.csv"
        if not path.exists():
            hand, logger = variation_by_name(variation).settings(seed)
            write_measurement(path, variation_record(params, hand, logger, **hidden), params)
        return path

    angle = folder / "angle.csv"
    if not angle.exists():
        from test_angle import OFF_NOMINAL, angle_record

        write_measurement(angle, angle_record(params, "+rack_lash", {**OFF_NOMINAL, "rack_lash.lash": 0.0002}), params)
    stiction = record("stiction_lag", "lag_10ms_50Hz", 8, effects="+rack_stiction",
                      overrides={"rack_stiction.breakaway_excess": 760.0})
    return {"null": (record("null", "rate_8pc_50Hz", 5), ["--jobs", "1"]),
            "stiction_lag": (stiction, ["--torque-lag", "--jobs", "1"]),
            "stiction_lag_jobs2": (stiction, ["--torque-lag", "--jobs", "2"]),
            "friction": (record("friction", "rate_8pc_50Hz", 4, effects="+column_friction"), ["--jobs", "1"]),
            "angle": (angle, ["--angle", "--jobs", "1"])}


def make(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for name, (path, options) in _records(out / "records").items():
        run = subprocess.run(["parksteer", "diagnose", str(path), "--json", "--quiet", *options],
                             capture_output=True, text=True, check=True)
        (out / f"{name}.json").write_text(run.stdout, encoding="utf-8")
        result = json.loads(run.stdout)
        print(f"{name}: {result['verdict']} {result.get('effect') or ''}")


def _comparable(result: dict) -> dict:
    result["cost"].pop("timings_s", None)

    def renamed(value):
        if isinstance(value, dict):
            return {RENAMED.get(k, k): renamed(v) for k, v in value.items()}
        if isinstance(value, list):
            return [renamed(v) for v in value]
        return value

    return renamed(result)


def _differences(a, b, path: str = "") -> list[str]:
    if type(a) is not type(b):
        return [f"{path}: {a!r} | {b!r}"]
    if isinstance(a, dict):
        return [d for k in dict.fromkeys([*a, *b]) for d in _differences(a.get(k), b.get(k), f"{path}/{k}")]
    if isinstance(a, list):
        if len(a) != len(b):
            return [f"{path}: {len(a)} items | {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _differences(x, y, f"{path}[{i}]")]
    return [] if a == b else [f"{path}: {a!r} | {b!r}"]


def compare(before: Path, after: Path) -> int:
    changed = 0
    for path in sorted(before.glob("*.json")):
        a = _comparable(json.loads(path.read_text(encoding="utf-8")))
        b = _comparable(json.loads((after / path.name).read_text(encoding="utf-8")))
        same = json.dumps(a) == json.dumps(b)
        print(f"{path.name}: {'identical' if same else 'DIFFERENT'}")
        if not same:
            changed += 1
            print("\n".join(f"  {d}" for d in _differences(a, b)) or "  (the order of keys)")
    return 1 if changed else 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["make"] and len(sys.argv) == 3:
        make(Path(sys.argv[2]))
    elif sys.argv[1:2] == ["compare"] and len(sys.argv) == 4:
        sys.exit(compare(Path(sys.argv[2]), Path(sys.argv[3])))
    else:
        sys.exit(__doc__)
