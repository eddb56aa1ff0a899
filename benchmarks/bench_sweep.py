"""Sweep cost: wall time of 48, 1,000 and 2,000 points on 2 cores, in process and in the DAG, and how it grows.

Two ways of running the same point code (parksteer.sweep.run.simulate_point):

* snakemake: the pipeline's rules in a scratch working directory (symlinks to the repository's data,
  src and workflow, with the benchmark's sweep in place of config/sweeps/design.yaml), the points in
  sweep_batch jobs of about --batch-size points (default: config/config.yaml's sweep_batch_size), `--cores 2`;
  the derivation rule runs first and is timed apart; the wall time includes Snakemake's own start and DAG build;
* inprocess: a pool of 2 worker processes calling simulate_point directly, each loading the compiled
  model once (the floor under any scheduler's overhead).

For each it reports the wall time per size (the median of --repeats runs, all runs kept), the cost per point, the
ratio of the DAG's cost per point to the in-process one, and a linear fit (slope, intercept, R^2) of the medians.
No point may derive the model: in the pool a derivation raises; around the Snakemake runs the model
cache's entries are compared before and after, and every point records the same model key.

    python benchmarks/bench_sweep.py results/bench_sweep.json [--sizes 48 1000 2000] [--mode both] [--repeats 1]
        [--batch-size N]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).with_name("snakemake")


def declaration(n_points: int) -> str:
    """A sweep of exactly n_points: tyre pressures x front axle loads around the test car (5, 4, 3, 2 or 1 loads,
    the most that divide n_points)."""
    loads = next(k for k in (5, 4, 3, 2, 1) if n_points % k == 0)
    load_axis = f"{{start: 5000, stop: 9000, num: {loads}}}" if loads > 1 else "[5576]"
    return (
        f"name: bench{n_points}\n"
        "base_case: unladen\n"
        "axes:\n"
        f"  tyre.tyre_pressure: {{start: 120000, stop: 300000, num: {n_points // loads}}}\n"
        f"  design.front_axle_load: {load_axis}\n"
    )


def linear_fit(sizes, seconds) -> dict | None:
    """Least-squares line through (points, seconds); None for fewer than two sizes."""
    if len(set(sizes)) < 2:
        return None
    x, y = np.asarray(sizes, dtype=float), np.asarray(seconds, dtype=float)
    slope, intercept = np.polyfit(x, y, 1)
    residual = y - (slope * x + intercept)
    r2 = 1.0 - float(np.sum(residual**2) / np.sum((y - y.mean()) ** 2))
    return {"slope_s_per_point": float(slope), "intercept_s": float(intercept), "r_squared": r2}


def cache_snapshot() -> dict[str, float]:
    from parksteer.model.codegen.cache import cache_root

    root = cache_root()
    return {p.parent.name: p.stat().st_mtime for p in root.glob("*/model.so")} if root.is_dir() else {}


# ---------------------------------------------------------------------------- in process


def _forbid_derivation():
    import parksteer.model.codegen.cache as compiled

    def refuse(*args, **kwargs):
        raise RuntimeError("a sweep point tried to derive the model")

    compiled.build_entry = refuse


def _run_spec(spec):
    from parksteer.parameters import load_parameters
    from parksteer.sweep.run import simulate_point

    record = simulate_point(spec, load_parameters())
    return record["model_key"]


def bench_inprocess(sizes, cores, repeats) -> dict:
    from parksteer.parameters import load_parameters
    from parksteer.sweep import load_sweep

    params = load_parameters()
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for n in sizes:
            path = Path(scratch) / f"bench{n}.yaml"
            path.write_text(declaration(n), encoding="utf-8")
            sweep = load_sweep(path, params)
            specs = [sweep.point_spec(i) for i in sweep.point_ids]
            walls, keys = [], set()
            for _ in range(repeats):
                start = time.perf_counter()
                with multiprocessing.get_context("fork").Pool(cores, initializer=_forbid_derivation) as pool:
                    keys.update(pool.map(_run_spec, specs, chunksize=1))
                walls.append(time.perf_counter() - start)
            wall = float(np.median(walls))
            rows.append({"points": n, "wall_s": wall, "per_point_s": wall / n, "runs_s": walls,
                         "model_keys": sorted(keys)})
            print(f"inprocess {n:4d} points: {wall:7.2f} s ({1000 * wall / n:.1f} ms per point)", flush=True)
    return {"rows": rows, "fit": linear_fit([r["points"] for r in rows], [r["wall_s"] for r in rows]),
            "derivations": 0, "note": "a derivation in a worker raises, so a completed run derived nothing"}


# ---------------------------------------------------------------------------- snakemake


def _workdir(scratch: Path, n: int) -> tuple[Path, Path]:
    """A working directory that sees the repository, with the benchmark's sweep as the default sweep; its
    workflow/Snakefile (the repository's, through the symlink)."""
    work = scratch / f"work{n}"
    (work / "config" / "sweeps").mkdir(parents=True)
    for name in ("src", "paper", "workflow"):
        (work / name).symlink_to(REPO / name)
    (work / "config" / "config.yaml").symlink_to(REPO / "config" / "config.yaml")
    (work / "config" / "sweeps" / "design.yaml").write_text(declaration(n), encoding="utf-8")
    return work, work / "workflow" / "Snakefile"


def _snakemake(snakefile: Path, work: Path, cores: int, targets: list[str], batch_size: int) -> float:
    cmd = [str(SNAKEMAKE), *targets, "--snakefile", str(snakefile), "--directory", str(work), "--cores", str(cores),
           "--config", f"sweep_batch_size={batch_size}", "--quiet", "all"]
    start = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode:
        logs = sorted((work / ".snakemake" / "log").glob("*.log"))
        detail = logs[-1].read_text(encoding="utf-8")[-3000:] if logs else done.stderr[-3000:]
        raise SystemExit(f"snakemake failed ({' '.join(cmd)}):\n{detail}")
    return wall


def bench_snakemake(sizes, cores, repeats, batch_size) -> dict:
    from parksteer.parameters import load_parameters
    from parksteer.sweep import load_sweep

    params = load_parameters()
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for n in sizes:
            work, snakefile = _workdir(Path(scratch), n)
            sweep = load_sweep(work / "config" / "sweeps" / "design.yaml", params)
            derive_s = _snakemake(snakefile, work, cores, ["results/model/full.json"], batch_size)
            batches = sweep.batches(batch_size)
            files = [f"results/sweeps/{sweep.name}/batches/{b}.json" for b in sorted(batches)]
            before = cache_snapshot()
            walls = []
            for repeat in range(repeats):
                for f in files if repeat else []:
                    (work / f).unlink()
                walls.append(_snakemake(snakefile, work, cores, files, batch_size))
            after = cache_snapshot()
            points_s = float(np.median(walls))
            records = [r for f in files for r in json.loads((work / f).read_text())["records"]]
            assert len(records) == n, (len(records), n)
            keys = {r["model_key"] for r in records}
            # The entry the points used existed before they ran and was not rebuilt by them (other entries may
            # come and go with unrelated work on the machine).
            cache_unchanged = all(k in before and after.get(k) == before[k] for k in keys)
            gather_s = _snakemake(snakefile, work, cores, [f"sweep_{sweep.name}"], batch_size)
            rows.append({"points": n, "batches": len(batches), "wall_s": points_s, "per_point_s": points_s / n,
                         "runs_s": walls, "derive_rule_s": derive_s, "gather_s": gather_s,
                         "model_keys": sorted(keys), "cache_unchanged_by_points": cache_unchanged})
            print(f"snakemake {n:4d} points in {len(batches)} batches: {points_s:7.2f} s ({1000 * points_s / n:.1f} "
                  f"ms per point; derive rule {derive_s:.1f} s, gather {gather_s:.1f} s)", flush=True)
    return {"rows": rows, "batch_size": batch_size,
            "fit": linear_fit([r["points"] for r in rows], [r["wall_s"] for r in rows]),
            "cache_unchanged": all(r["cache_unchanged_by_points"] for r in rows),
            "note": "wall_s is the batch jobs alone, with Snakemake's start and DAG build (median of runs_s); the "
                    "derive rule ran first (derive_rule_s) and the model entry the points used was compared before "
                    "and after them"}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("--sizes", type=int, nargs="+", default=[48, 1000, 2000])
    parser.add_argument("--mode", choices=("snakemake", "inprocess", "both"), default="both")
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=1, help="runs per size; the median is fitted")
    parser.add_argument("--batch-size", type=int, default=None,
                        help="points per sweep_batch job (default: config/config.yaml's sweep_batch_size)")
    args = parser.parse_args(argv)
    os.chdir(REPO)
    import yaml

    batch_size = args.batch_size or yaml.safe_load((REPO / "config" / "config.yaml").read_text())["sweep_batch_size"]
    from parksteer.model.codegen.cache import ensure
    from parksteer.model.symbolic.components import resolve_effects

    ensure(resolve_effects(None))  # the one derivation, before any timing
    result = {"sizes": args.sizes, "cores": args.cores, "repeats": args.repeats, "machine": platform.platform(),
              "cpu_count": os.cpu_count(), "python": platform.python_version(),
              "load_average_at_start": os.getloadavg()}
    if args.mode in ("inprocess", "both"):
        result["inprocess"] = bench_inprocess(args.sizes, args.cores, args.repeats)
    if args.mode in ("snakemake", "both"):
        result["snakemake"] = bench_snakemake(args.sizes, args.cores, args.repeats, batch_size)
    if "inprocess" in result and "snakemake" in result:
        result["dag_over_inprocess"] = {
            str(a["points"]): b["per_point_s"] / a["per_point_s"]
            for a, b in zip(result["inprocess"]["rows"], result["snakemake"]["rows"])
        }
        for n, ratio in result["dag_over_inprocess"].items():
            print(f"{n} points: the DAG costs {ratio:.2f} x the in-process cost per point")
    result["load_average_at_end"] = os.getloadavg()
    for mode in ("inprocess", "snakemake"):
        if mode in result:
            fit = result[mode]["fit"]
            if fit is None:
                continue
            print(f"{mode}: {fit['slope_s_per_point'] * 1000:.1f} ms per point, intercept {fit['intercept_s']:.2f} s, "
                  f"R^2 {fit['r_squared']:.4f}")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    one_key_per_size = all(len(r["model_keys"]) == 1 for mode in ("inprocess", "snakemake") if mode in result
                           for r in result[mode]["rows"])
    if not one_key_per_size or not result.get("snakemake", {}).get("cache_unchanged", True):
        print("error: the model was derived during the sweep", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
