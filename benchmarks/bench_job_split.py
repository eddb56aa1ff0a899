"""Where one pipeline job's time goes: the job run again under cProfile, its time split into imports, loading the
compiled models, making the records' truths, the diagnoses, and writing.

Each TARGET is one job's output (results/diagnose/benchmark/bench_00, say) of a checkout whose job inputs are built
(the models derived). `snakemake --cores 1 --force TARGET` runs the job again in this checkout (its outputs are
written anew; the rules after it are then out of date until the next run), with a `sitecustomize` on PYTHONPATH
that profiles the rule script's process (scripts under .snakemake/scripts/) and keeps the profile. From it, per job,
the cumulative seconds of: the imports (importlib's `_find_and_load`, outermost calls: the method's own lazy
imports among them), the models loaded (`CompiledModels.entry`, `ensure_entry`), the truths made (the rule's
record generator: :data:`TRUTHS`), the diagnoses (`intake` and `Intake.diagnose`: reading the written files back
and the method) and the writing (`write_measurement`, `write_json`). cProfile inflates Python-heavy parts, so the
shares are what to read; the columns overlap where a lazy import runs inside a diagnosis.

    python benchmarks/bench_job_split.py results/bench_job_split.json TARGET [TARGET ...]
"""

from __future__ import annotations

import argparse
import json
import os
import pstats
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).with_name("snakemake")
PROFILE_ENV = "PARKSTEER_JOB_PROFILE"
SITECUSTOMIZE = f'''import os, sys
if os.environ.get("{PROFILE_ENV}") and ".snakemake/scripts/" in (sys.argv[0] if sys.argv else ""):
    import atexit, cProfile
    _profile = cProfile.Profile()
    _profile.enable()

    def _dump():
        _profile.disable()
        name = f"{{os.path.basename(sys.argv[0])}}.{{os.getpid()}}.prof"
        _profile.dump_stats(os.path.join(os.environ["{PROFILE_ENV}"], name))

    atexit.register(_dump)
'''
# The record generator of each rule's cases: (file suffix, function), their cumulative time the truths'.
TRUTHS = {
    "diag_bench_batch": [("synthetic/datasets.py", "make_dataset")],
    "diag_outclass_batch": [("synthetic/outclass.py", "make_outclass_dataset")],
    "diag_signature_batch": [("experiments/outoflibrary.py", "make_record")],
    "diag_variation_batch": [("experiments/variations.py", "case_records")],
    "diag_peers_batch": [("experiments/variations.py", "case_records")],
    "diag_assisted_batch": [("experiments/assisted_benchmark.py", "case_truth_and_record")],
    "diag_assisted_truth_batch": [("experiments/assisted_truth.py", "case_truth_and_record")],
}
PARTS = {
    "imports": [("importlib._bootstrap>", "_find_and_load")],
    "models": [("numeric/compiled.py", "entry"), ("codegen/cache.py", "ensure_entry")],
    "diagnoses": [("diagnose/intake.py", "intake"), ("diagnose/intake.py", "diagnose")],
    "writing": [("measure/io.py", "write_measurement"), ("parksteer/tables.py", "write_json")],
}


def cumulative(stats: pstats.Stats, functions) -> float:
    """Summed cumulative seconds of the functions named (file suffix, name): cProfile counts a recursive
    function's outermost calls only."""
    return sum(row[3] for (path, _line, name), row in stats.stats.items()
               if any(path.endswith(suffix) and name == wanted for suffix, wanted in functions))


def split(profile: Path, rule: str) -> dict:
    stats = pstats.Stats(str(profile))
    parts = {"total": max(row[3] for row in stats.stats.values())}
    parts.update({part: cumulative(stats, functions) for part, functions in PARTS.items()})
    parts["truths"] = cumulative(stats, TRUTHS.get(rule, []))
    return {k: round(v, 2) for k, v in parts.items()}


def rule_of(script: str) -> str:
    """The rule a kept script ran for: Snakemake names it tmp<random>.<script name>."""
    return script.split(".")[1] if script.count(".") >= 2 else script


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("targets", nargs="+")
    args = parser.parse_args()
    jobs = []
    with tempfile.TemporaryDirectory() as scratch:
        hook, profiles = Path(scratch, "hook"), Path(scratch, "profiles")
        hook.mkdir()
        profiles.mkdir()
        (hook / "sitecustomize.py").write_text(SITECUSTOMIZE, encoding="utf-8")
        env = {**os.environ, PROFILE_ENV: str(profiles),
               "PYTHONPATH": os.pathsep.join(filter(None, [str(hook), str(REPO / "src"), os.environ.get("PYTHONPATH")]))}
        for target in args.targets:
            before = set(profiles.iterdir())
            done = subprocess.run([str(SNAKEMAKE), "--cores", "1", "--force", target], cwd=REPO, env=env,
                                  capture_output=True, text=True)
            if done.returncode != 0:
                print(done.stderr[-2000:], file=sys.stderr)
                return 1
            for profile in sorted(set(profiles.iterdir()) - before):
                rule = rule_of(profile.name)
                jobs.append({"target": target, "rule": rule, **split(profile, rule)})
    Path(args.out).write_text(json.dumps({"jobs": jobs}, indent=1) + "\n", encoding="utf-8")
    columns = ("total", "imports", "models", "truths", "diagnoses", "writing")
    print(f"{'job':<45}" + "".join(f"{c:>10}" for c in columns))
    for job in jobs:
        print(f"{job['target']:<45}" + "".join(f"{job[c]:>10.2f}" for c in columns))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
