"""Sweep scale: how the DAG build, `parksteer sweep expand`, the batching and the gathering grow from a thousand
to a million points, and what a million points would take on a SLURM cluster.

For each size (10^3, 10^4, 10^5, 10^6 points by default; a grid of tyre pressure x front axle load x spacer
offset x steering ratio around the unladen test car) it measures, once each, on this machine:

* dag: `snakemake -n sweep_<name> --config sweep=<declaration>` in a scratch working directory (links to src/,
  workflow/, config/, data/, paper/; no .snakemake/, so the plan and the batch index are computed), wall and CPU
  time of the process and its children;
* expand: `parksteer sweep expand <declaration> > /dev/null`, wall time;
* batching: in process, load_sweep (read, check, expand, hash) and Sweep.batches, and the writing of the batch
  index, wall time each;
* gather: the gathering (parksteer.figures.sweep.make_sweep_figure: table, key numbers, maps) over synthetic batch
  files, one per batch, with records shaped as run_batch writes them (trimmed of the fields the gathering does not
  read); no point is simulated. Wall and CPU time and the peak resident memory of the gathering process
  (ru_maxrss; base_rss_mb: that of the process with its imports, before the gathering), then, after it in the same
  process, the peak with the sweep's expansion (load_sweep) made as well, for comparison.

It prints, per stage, each size's time and its cost per point (linear growth: the cost per point roughly
constant), writes all numbers to the JSON file given, and, with --point-cost, measures a sweep point's cost
(in-process simulate_point of the example sweep's points, compiled model loaded) and a batch job's fixed cost
(a Python process importing the simulation and loading the model), then predicts the wall time of the largest
size on 1, 16, 128 and 1,024 cores under the SLURM profile (Amdahl: DAG build, submission and gathering serial).

    python benchmarks/bench_sweep_scale.py results/bench_sweep_scale.json [--sizes 1000 10000 100000 1000000]
        [--stages dag expand batching gather] [--point-cost] [--repo PATH]

--repo runs another checkout's code (its src/ first on PYTHONPATH, its workflow/), e.g. an export of an older
commit, for a before/after comparison; its stages that no longer exist there are skipped.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
PARAMETERS = "src/parksteer/data/parameters.toml"
BATCH_SIZE = 50  # config/config.yaml sweep_batch_size
# grid sizes per axis (pressure, load, offset, ratio) of each sweep size
GRIDS = {1000: (10, 10, 5, 2), 10000: (10, 10, 10, 10), 100000: (100, 10, 10, 10), 1000000: (100, 100, 10, 10)}
CORES = (1, 16, 128, 1024)
# The SLURM profile (workflow/profiles/slurm): batches per group job, and batches run at once in a group.
GROUP_BATCHES, GROUP_CORES = 8, 4


def declaration(n_points: int) -> str:
    p, w, o, r = GRIDS[n_points]
    return (f"name: scale{n_points}\nbase_case: unladen\naxes:\n"
            f"  tyre.tyre_pressure: {{start: 122500, stop: 300000, num: {p}}}\n"
            f"  design.front_axle_load: {{start: 5000, stop: 9000, num: {w}}}\n"
            f"  design.extra_offset: {{start: 0.0, stop: 0.07, num: {o}}}\n"
            f"  design.steering_ratio: {{start: 14.0, stop: 24.0, num: {r}}}\n"
            "map: {x: tyre.tyre_pressure, y: design.front_axle_load, panels: design.steering_ratio,\n"
            "      quantity: peak_torque_Nm}\n"
            "assistance:\n"
            "  rim_force: {value: 150, unit: N, source: benchmark}\n"
            "  rim_radius: {value: 0.19, unit: m, source: benchmark}\n")


def _env(repo: Path) -> dict:
    return dict(os.environ, PYTHONPATH=str(repo / "src"))


def _timed(cmd, cwd, env, stdout=subprocess.DEVNULL) -> dict:
    """Run `cmd`; its wall time and the CPU time (user + system) of it and its children."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, env=env, stdout=stdout, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, cmd))}: exit {done.returncode}\n{done.stderr[-2000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall_s": wall, "cpu_s": cpu, "stderr": done.stderr}


def scratch_copy(repo: Path, dest: Path) -> Path:
    dest.mkdir(parents=True)
    for name in ("src", "workflow", "config", "data", "paper", "examples"):
        if (repo / name).exists():
            (dest / name).symlink_to(repo / name)
    return dest


def stage_dag(repo: Path, work: Path, decl: Path, n: int) -> dict:
    shutil.rmtree(work / ".snakemake", ignore_errors=True)
    out = _timed([str(BIN / "snakemake"), "-n", f"sweep_scale{n}", "--config", f"sweep={decl}",
                  f"sweep_batch_size={BATCH_SIZE}"], work, _env(repo))
    return {"wall_s": out["wall_s"], "cpu_s": out["cpu_s"]}


def stage_expand(repo: Path, decl: Path) -> dict:
    out = _timed([sys.executable, "-m", "parksteer.cli", "sweep", "expand", str(decl)], repo, _env(repo))
    return {"wall_s": out["wall_s"], "cpu_s": out["cpu_s"]}


BATCHING = """
import json, sys, tempfile, time
from parksteer.parameters import load_parameters
from parksteer.sweep import load_sweep
try:
    import parksteer.sweep.batch_index as index_module
except ImportError:  # before the batch index had a module of its own
    import parksteer.sweep.declaration as index_module
params = load_parameters(sys.argv[2])
start = time.perf_counter()
sweep = load_sweep(sys.argv[1], params)
loaded = time.perf_counter()
batches = sweep.batches(int(sys.argv[3]))
batched = time.perf_counter()
out = {"load_sweep_s": loaded - start, "batches_s": batched - loaded, "n_batches": len(batches)}
if hasattr(index_module, "write_batch_index"):
    with tempfile.TemporaryDirectory() as folder:
        index_module.write_batch_index(sweep, int(sys.argv[3]), folder)
    out["batch_index_s"] = time.perf_counter() - batched
else:  # the plan formed each batch's spec
    begun = time.perf_counter()
    for batch in sorted(batches)[:int(sys.argv[4])]:
        sweep.batch_spec(batch, int(sys.argv[3]))
    out["batch_specs_sample_s"] = time.perf_counter() - begun
    out["batch_specs_sampled"] = min(len(batches), int(sys.argv[4]))
print(json.dumps(out))
"""


def _timed_json(cmd, cwd, env) -> dict:
    start = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{cmd[0]}: exit {done.returncode}\n{done.stderr[-2000:]}")
    return {**json.loads(done.stdout.strip().splitlines()[-1]), "wall_s": time.perf_counter() - start}


SYNTHETIC = """
import json, math, sys
from pathlib import Path
from parksteer.parameters import load_parameters
from parksteer.sweep import load_sweep
sweep = load_sweep(sys.argv[1], load_parameters(sys.argv[2]))
folder = Path(sys.argv[3]); folder.mkdir(parents=True, exist_ok=True)
shares = ("carcass_compliance", "hooke_joint", "inertia", "lifting", "rack_friction", "tyre_friction")
method = "model effect braked_wheels at brake_fraction = 1 (wheels held), simulated"
def record(point):
    v = point.values
    peak = 25.0 * (v["design.front_axle_load"] / 5576.0) ** 1.5 * (122500.0 / v["tyre.tyre_pressure"]) ** 0.3 \\
        * 16.0 / v["design.steering_ratio"] * (1.0 + 2.0 * v["design.extra_offset"])
    merits = {"peak_torque_Nm": peak, "plateau_torque_Nm": 0.88 * peak, "lock_torque_Nm": 0.97 * peak,
              "reversal_drop_Nm": 0.48 * peak, "sliding_start_rack_m": 0.022,
              **{f"share_contrib_{s}_Nm": 1.0 / len(shares) for s in shares}}
    braked = {"method": method, "factor": 1.0 + 4.0 * v["design.extra_offset"], "ground_offset_m": 0.006,
              "plateau_torque_Nm": 0.9 * peak, "peak_torque_Nm": 1.02 * peak, "lock_torque_Nm": peak}
    return {"sweep": sweep.name, "point": point.id, "case": "unladen", "surface": "ground",
            "effects": ["carcass_compliance", "hooke_joint", "lifting", "rack_friction", "tyre_friction"],
            "model_key": "synthetic", "values": v, "merits": merits, "braked": braked}
paths = []
for batch, members in sorted(sweep.batches(int(sys.argv[4])).items()):
    path = folder / f"{batch}.json"
    path.write_text(json.dumps({"sweep": sweep.name, "batch": batch, "points": list(members),
                                "records": [record(sweep.point(m)) for m in members]}), encoding="utf-8")
    paths.append(str(path))
(folder / "paths.txt").write_text("\\n".join(paths), encoding="utf-8")
print(json.dumps({"files": len(paths)}))
"""

GATHER = """
import json, resource, sys, time
from pathlib import Path
from parksteer.parameters import load_parameters
from parksteer.sweep import load_sweep
from parksteer.figures.sweep import make_sweep_figure
def cpu():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime
params = load_parameters(sys.argv[2])
paths = Path(sys.argv[3], "paths.txt").read_text(encoding="utf-8").split()
out = Path(sys.argv[4])
base_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
start, start_cpu = time.perf_counter(), cpu()
make_sweep_figure(sys.argv[1], params, paths, out / "s.svg", out / "s.csv", out / "s.json")
result = {"gather_s": time.perf_counter() - start, "gather_cpu_s": cpu() - start_cpu, "base_rss_mb": base_mb,
          "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
          "summary_bytes": (out / "s.json").stat().st_size, "table_bytes": (out / "s.csv").stat().st_size}
sweep = load_sweep(sys.argv[1], params)  # after the gathering, so that its peak is the gathering's own
result["expansion_peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps(result))
"""


def stage_gather(repo: Path, decl: Path, scratch: Path) -> dict:
    batches = scratch / "batches"
    made = _timed_json([sys.executable, "-c", SYNTHETIC, str(decl), PARAMETERS, str(batches), str(BATCH_SIZE)],
                       repo, _env(repo))
    out = scratch / "gathered"
    out.mkdir()
    result = _timed_json([sys.executable, "-c", GATHER, str(decl), PARAMETERS, str(batches), str(out)], repo,
                         _env(repo))
    shutil.rmtree(batches)
    return {**result, "synthetic_files": made["files"], "synthetic_write_s": made["wall_s"]}


POINT_COST = """
import json, sys, time
start = time.perf_counter()
from parksteer.parameters import load_parameters
from parksteer.sweep import load_sweep
from parksteer.sweep.run import simulate_point
params = load_parameters(sys.argv[2])
sweep = load_sweep(sys.argv[1], params)
specs = [sweep.point_spec(i) for i in sweep.point_ids[: int(sys.argv[3])]]
first = time.perf_counter()
simulate_point(specs[0], params)
loaded = time.perf_counter()
for spec in specs[1:]:
    simulate_point(spec, params)
done = time.perf_counter()
print(json.dumps({"start_s": first - start, "first_point_s": loaded - first,
                  "point_s": (done - loaded) / (len(specs) - 1), "points": len(specs)}))
"""


def point_cost(repo: Path, n_points: int = 21) -> dict:
    """A point's cost in a batch job (the example sweep's points: free-rolling and braked simulations) and a batch
    job's fixed cost: interpreter start, imports, parameters, the first point's model load minus a point."""
    measured = _timed_json([sys.executable, "-c", POINT_COST, "config/sweeps/design.yaml", PARAMETERS,
                            str(n_points)], repo, _env(repo))
    measured["job_start_s"] = measured["wall_s"] - measured["point_s"] * measured["points"]
    return measured


def predict(n_points: int, dag_s: float, gather_s: float, cost: dict, submit_s: float, n_batches: int | None = None
            ) -> list[dict]:
    """Wall time of an n_points sweep under the SLURM profile on `cores` cores (Amdahl): the serial parts (DAG
    build, one sbatch per group job, the gathering) plus the batch work shared by the cores, each batch paying a
    job start; at most one core per batch."""
    n_batches = n_batches or math.ceil(n_points / BATCH_SIZE)
    n_groups = math.ceil(n_batches / GROUP_BATCHES)
    work_s = n_points * cost["point_s"] + n_batches * cost["job_start_s"]
    serial_s = dag_s + n_groups * submit_s + gather_s
    rows = []
    for cores in CORES:
        parallel_s = work_s / min(cores, n_batches)
        rows.append({"cores": cores, "serial_s": serial_s, "parallel_s": parallel_s, "wall_s": serial_s + parallel_s,
                     "speedup": (serial_s + work_s) / (serial_s + parallel_s),
                     "jobs_needed": math.ceil(min(cores, n_batches) / GROUP_CORES)})
    return rows


def main() -> int:
    global BATCH_SIZE
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--sizes", type=int, nargs="+", default=sorted(GRIDS), choices=sorted(GRIDS))
    parser.add_argument("--stages", nargs="+", default=["dag", "expand", "batching", "gather"],
                        choices=["dag", "expand", "batching", "gather"])
    parser.add_argument("--point-cost", action="store_true")
    parser.add_argument("--submit-s", type=float, default=0.25,
                        help="seconds per sbatch submission (the executor submits each group job in turn; an "
                             "assumption: sbatch alone takes 0.05 s on the test cluster of tests/cluster, a busy "
                             "controller several times that)")
    parser.add_argument("--repo", type=Path, default=REPO)
    parser.add_argument("--from-json", type=Path,
                        help="measure nothing: report (and predict) from the results file of an earlier run")
    parser.add_argument("--batch-size", type=int, default=BATCH_SIZE,
                        help="points per batch (config sweep_batch_size; the pipeline's default 50)")
    args = parser.parse_args()
    BATCH_SIZE = args.batch_size
    repo = args.repo.resolve()
    if args.from_json:
        results = json.loads(args.from_json.read_text(encoding="utf-8"))
        _report(results, args)
        Path(args.out).write_text(json.dumps(results, indent=1) + "\n", encoding="utf-8")
        return 0
    results: dict = {"machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                                 "platform": platform.platform(), "load_average": os.getloadavg()},
                     "repo": str(repo), "batch_size": BATCH_SIZE, "sizes": {}}
    with tempfile.TemporaryDirectory(prefix="bench_sweep_scale_") as tmp:
        work = scratch_copy(repo, Path(tmp) / "work")
        for n in args.sizes:
            decl = Path(tmp) / f"scale{n}.yaml"
            decl.write_text(declaration(n), encoding="utf-8")
            row = results["sizes"].setdefault(str(n), {})
            for stage in args.stages:
                scratch = Path(tmp) / f"{stage}{n}"
                scratch.mkdir()
                if stage == "dag":
                    row[stage] = stage_dag(repo, work, decl, n)
                elif stage == "expand":
                    row[stage] = stage_expand(repo, decl)
                elif stage == "batching":
                    row[stage] = _timed_json([sys.executable, "-c", BATCHING, str(decl), PARAMETERS, str(BATCH_SIZE),
                                              "20"], repo, _env(repo))
                else:
                    row[stage] = stage_gather(repo, decl, scratch)
                shutil.rmtree(scratch, ignore_errors=True)
                print(f"{n:>8} points  {stage:<8} {json.dumps(row[stage])}", flush=True)
        if args.point_cost:
            results["point_cost"] = point_cost(repo)
            print(f"point cost {json.dumps(results['point_cost'])}", flush=True)
    _report(results, args)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(results, indent=1) + "\n", encoding="utf-8")
    return 0


def _report(results: dict, args) -> None:
    print("\npoints     dag wall s (cpu s)   expand s   load+batch s   gather s   gather peak MB   us/point (dag, expand, "
          "gather)")
    for n, row in results["sizes"].items():
        n_points = int(n)
        dag, expand, gather = row.get("dag"), row.get("expand"), row.get("gather")
        batching = row.get("batching")
        cells = [f"{n_points:>8}",
                 f"{dag['wall_s']:8.1f} ({dag['cpu_s']:6.1f})" if dag else f"{'-':>17}",
                 f"{expand['wall_s']:8.1f}" if expand else f"{'-':>8}",
                 f"{batching['load_sweep_s'] + batching['batches_s']:10.2f}" if batching else f"{'-':>10}",
                 f"{gather['gather_s']:9.1f}" if gather else f"{'-':>9}",
                 f"{gather['peak_rss_mb']:10.0f}" if gather else f"{'-':>10}"]
        per = [f"{1e6 * s[k] / n_points:.0f}" if s else "-" for s, k in ((dag, "wall_s"), (expand, "wall_s"),
                                                                     (gather, "gather_s"))]
        print("   ".join(cells) + "       " + ", ".join(per))
    if "point_cost" in results and results["sizes"]:
        largest = max(results["sizes"], key=int)
        row = results["sizes"][largest]
        if "dag" in row and "gather" in row:
            rows = predict(int(largest), row["dag"]["wall_s"], row["gather"]["gather_s"], results["point_cost"],
                           args.submit_s, row.get("batching", {}).get("n_batches"))
            results["prediction"] = {"points": int(largest), "submit_s": args.submit_s, "rows": rows}
            print(f"\n{int(largest):,} points under the SLURM profile (point {results['point_cost']['point_s']:.3f} s, "
                  f"job start {results['point_cost']['job_start_s']:.2f} s, sbatch {args.submit_s} s)")
            print("cores   serial s   parallel s   wall s   wall h   speedup   group jobs at once")
            for r in rows:
                print(f"{r['cores']:>5} {r['serial_s']:10.0f} {r['parallel_s']:12.0f} {r['wall_s']:8.0f} "
                      f"{r['wall_s'] / 3600:8.2f} {r['speedup']:9.1f} {r['jobs_needed']:12d}")


if __name__ == "__main__":
    sys.exit(main())
