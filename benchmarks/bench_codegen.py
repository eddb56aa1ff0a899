"""Where one cold model build goes: derivation (Kane's method, the generalized forces), code generation (the
expressions in C symbols, common-subexpression elimination, the chain-rule Jacobian, C printing) and `cc`; and
a check that the generated C is byte-identical to another checkout's.

    python benchmarks/bench_codegen.py OUT.json [--models default with_brush_patch ...] [--runs 3]
        [--repo PATH] [--reference OTHER.json]

Each run of each model is a fresh Python process (as a rule derive job is: nothing cached in memory), which
imports sympy and parksteer, derives, generates and compiles the model into a scratch directory (no model cache
read or written) and reports its stages; the table gives the median of the runs per stage. Stages:

* import: sympy and parksteer's symbolic half imported;
* kane: the system built and KanesMethod's mass matrix and forcing (Derivation.timings_s["kane_s"]);
* forces: the rest of the derivation, each effect's generalized forces (timings_s["forces_s"]);
* expressions: generate's set-up, every expression rewritten in C symbols (codegen_timings_s["expressions_s"]);
* cse: sympy.cse over the mass matrix and forcing, the Jacobian's residual, the drive and the outputs;
* chain_rule: the Jacobian's partial derivatives through the subexpressions (_derivative_block without its cse
  and printing);
* print: the C printer (_Printer.doprint), every line;
* rest: generate's remainder (the source assembled, the portability check);
* cc: the compiler on model.c alone (the runtime it links, compiled once per cache, is not timed; on trees before
  the runtime was compiled apart, model.c holds it).

Each stage is timed in wall time and in CPU time (the CPU time of generate's set-up and remainder together, as
expressions_rest; the Kane and forces stages split at the first group's generalized forces; cc's from the
compiler's resource usage): on a shared machine the CPU times are the measure, the wall times grow with the load.

It also records each model's generated C (its sha256 and size) per run: the runs of one model must agree, and
with --reference (the JSON of a run of this script on another checkout, e.g. `--repo` an export of an older
commit) every model's C must be byte-identical to the reference's; the script exits 1 otherwise. The model
cache keys and every model figure's last bits depend on that C.

--repo runs another checkout's code (its src/ first on PYTHONPATH).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
# Effect sets the workflow derives (rule derive; config/config.yaml variants, the rivals, the diagnosis
# candidates), by the name of their manifest, and the spec that gives each. with_brush_patch is the largest
# (nine coordinates); diagnosis is the one model of a diagnosis, every candidate effect in one derivation (the
# largest C).
MODELS = {
    "default": None,
    "no_friction": "-rack_friction,-tyre_friction",
    "with_ackermann": "+ackermann",
    "with_rack_lash": "+rack_lash",
    "with_carcass_hysteresis": "+carcass_hysteresis",
    "assist_hydraulic": "+hydraulic_assist",
    "assist_column": "+electric_assist_column",
    "with_brush_patch": "+brush_patch",
    "diagnosis": "+ackermann,+braked_wheels,+column_friction,+kingpin_friction,+rack_damping,+rack_lash,+rack_stiction",
}
STAGES = ("import", "kane", "forces", "expressions", "cse", "chain_rule", "print", "rest", "cc")
# besides: python_cpu, the CPU time of the build's Python process (all but cc): near the sum of the Python stages
# when the machine is otherwise idle. CPU_STAGES: the CPU time of each stage (generate's set-up and remainder
# together; cc's from the compiler's resource usage), the measure that holds when the machine is shared.
CPU_STAGES = ("import", "kane", "forces", "expressions_rest", "cse", "chain_rule", "print", "cc")


def child(spec: str | None, out_dir: Path) -> dict:
    """One cold build of the model of `spec` in this process, its stages timed (wall and CPU)."""
    start = time.perf_counter()
    import parksteer  # noqa: F401  (first, as in every parksteer process: it sizes sympy's cache)
    import sympy

    from parksteer.model.codegen import cache, generate as gen
    from parksteer.model.symbolic import derive as derive_module
    from parksteer.model.symbolic.components import resolve_effects

    effects = resolve_effects(spec)
    took = {"import": time.perf_counter() - start, "cse": 0.0, "print": 0.0, "chain_rule": 0.0}
    cpu = {"import": time.process_time(), "cse": 0.0, "print": 0.0, "chain_rule": 0.0}

    def timed(function, stage):
        def wrapper(*args, **kwargs):
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                return function(*args, **kwargs)
            finally:
                took[stage] += time.perf_counter() - t0
                cpu[stage] += time.process_time() - c0
        return wrapper

    sympy.cse = timed(sympy.cse, "cse")
    gen._Printer.doprint = timed(gen._Printer.doprint, "print")
    derivative_block = gen._derivative_block

    def chain_rule(*args, **kwargs):  # its own time less the cse and printing inside it (counted there)
        t0, c0 = time.perf_counter(), time.process_time()
        inner, inner_cpu = took["cse"] + took["print"], cpu["cse"] + cpu["print"]
        try:
            return derivative_block(*args, **kwargs)
        finally:
            took["chain_rule"] += time.perf_counter() - t0 - (took["cse"] + took["print"] - inner)
            cpu["chain_rule"] += time.process_time() - c0 - (cpu["cse"] + cpu["print"] - inner_cpu)

    gen._derivative_block = chain_rule
    generalized_forces, forces_start = derive_module.generalized_forces, []

    def first_forces(*args, **kwargs):  # the forces stage starts at the first group's generalized forces
        if not forces_start:
            forces_start.append(time.process_time())
        return generalized_forces(*args, **kwargs)

    derive_module.generalized_forces = first_forces
    c0 = time.process_time()
    derivation = derive_module.derive(effects)
    c1 = time.process_time()
    took["kane"] = derivation.timings_s["kane_s"]
    took["forces"] = derivation.timings_s["forces_s"]
    cpu["kane"], cpu["forces"] = forces_start[0] - c0, c1 - forces_start[0]
    t0, c0 = time.perf_counter(), time.process_time()
    cse_before, print_before = took["cse"], took["print"]
    cpu_before = cpu["cse"] + cpu["print"]
    source, info = gen.generate(derivation)
    generate_s, generate_cpu = time.perf_counter() - t0, time.process_time() - c0
    timings = info["codegen_timings_s"]
    took["expressions"] = timings["expressions_s"]
    took["rest"] = generate_s - took["expressions"] - (took["cse"] - cse_before) - (took["print"] - print_before) \
        - took["chain_rule"]
    # generate's set-up and remainder together (its set-up is timed inside it, in wall time only)
    cpu["expressions_rest"] = generate_cpu - (cpu["cse"] + cpu["print"] - cpu_before) - cpu["chain_rule"]
    c_file = out_dir / "model.c"
    c_file.write_text(source, encoding="utf-8")
    t0, children = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    cmd = [cache.find_compiler(), *cache.COMPILE_FLAGS, "-o", str(out_dir / "model.so"), str(c_file), "-lm"]
    subprocess.run(cmd, check=True, capture_output=True)
    took["cc"] = time.perf_counter() - t0
    done = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu["cc"] = done.ru_utime + done.ru_stime - children.ru_utime - children.ru_stime
    took["python_cpu"] = time.process_time()
    return {"stages_s": took, "cpu_s": cpu, "effects": [e.name for e in effects],
            "coordinates": len(info["coordinates"]), "c_sha256": hashlib.sha256(source.encode()).hexdigest(),
            "c_bytes": len(source.encode()), "c_lines": source.count("\n")}


def run(repo: Path, name: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(repo / "src"))
    with tempfile.TemporaryDirectory() as scratch:
        cmd = [sys.executable, __file__, "--child", json.dumps(MODELS[name]), scratch]
        start = time.perf_counter()
        done = subprocess.run(cmd, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"{name}: the build failed:\n{done.stderr[-2000:]}")
    result = json.loads(done.stdout.strip().splitlines()[-1])
    result["process_s"] = wall
    return result


def main() -> int:
    if len(sys.argv) == 4 and sys.argv[1] == "--child":
        spec = json.loads(sys.argv[2])
        print(json.dumps(child(spec, Path(sys.argv[3]))))
        return 0
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--models", nargs="+", default=list(MODELS), choices=list(MODELS))
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--repo", type=Path, default=REPO)
    parser.add_argument("--reference", type=Path, help="a JSON of this script whose models' C must match")
    args = parser.parse_args()
    results = {"machine": platform.platform(), "cpus": os.cpu_count(), "repo": str(args.repo),
               "load_average": os.getloadavg(), "runs": args.runs, "models": {}}
    failures = []
    for name in args.models:
        runs = [run(args.repo, name) for _ in range(args.runs)]
        median = {stage: statistics.median(r["stages_s"][stage] for r in runs) for stage in STAGES}
        median["total"] = sum(median.values())
        median["process"] = statistics.median(r["process_s"] for r in runs)
        median["python_cpu"] = statistics.median(r["stages_s"]["python_cpu"] for r in runs)
        median_cpu = {stage: statistics.median(r["cpu_s"][stage] for r in runs) for stage in CPU_STAGES}
        median_cpu["total"] = sum(median_cpu.values())
        hashes = sorted({r["c_sha256"] for r in runs})
        if len(hashes) != 1:
            failures.append(f"{name}: the runs generated different C ({', '.join(h[:12] for h in hashes)})")
        results["models"][name] = {"effects": runs[0]["effects"], "coordinates": runs[0]["coordinates"],
                                   "c_sha256": hashes[0], "c_bytes": runs[0]["c_bytes"],
                                   "c_lines": runs[0]["c_lines"], "median_s": median,
                                   "median_cpu_s": median_cpu, "runs_s": [r["stages_s"] for r in runs],
                                   "runs_cpu_s": [r["cpu_s"] for r in runs]}
        shown = (*STAGES, "total", "process", "python_cpu")
        print(f"{name:26s} wall " + " ".join(f"{s} {median[s]:.2f}" for s in shown), flush=True)
        print(f"{name:26s} cpu  " + " ".join(f"{s} {median_cpu[s]:.2f}" for s in (*CPU_STAGES, "total")), flush=True)
    if args.reference:
        reference = json.loads(args.reference.read_text())["models"]
        for name, model in results["models"].items():
            if name not in reference:
                continue
            same = model["c_sha256"] == reference[name]["c_sha256"]
            results["models"][name]["c_same_as_reference"] = same
            if not same:
                failures.append(f"{name}: generated C differs from {args.reference} "
                                f"({model['c_bytes']} vs {reference[name]['c_bytes']} bytes)")
        print(f"generated C compared with {args.reference}: "
              + ("identical for every model" if not failures else "DIFFERENT"))
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(results, indent=1) + "\n", encoding="utf-8")
    for failure in failures:
        print(failure, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
