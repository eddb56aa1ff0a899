"""Benchmark of the multibody model (not a test): medians of repeated timings.

    python benchmarks/bench_model.py OUT.json [--repeats 7]

Times: one 18 s cycle of the nominal case (one call of the generated integrator, ps_integrate, with
the analytic Jacobian, cache warm), and as a reference in the same run the same compiled right-hand side and
Jacobian called back from scipy's odeint (LSODA), the path before the integrator moved into C; one 18 s
prescribed-rack replay of data/measurements/example_unladen.csv
(the solver of ``parksteer simulate --rack-from`` and ``parksteer compare``, on the smoothed rack;
target 0.3 s); all the simulations of Figs. 12-16 and the contribution figure;
derivation + code generation + compilation of the default model (into a scratch cache);
and a baseline in the same run: the same sympy equations through plain ``lambdify`` and
``solve_ivp(Radau)`` (finite-difference Jacobian) at the same tolerances. Prints a table
and writes the numbers as JSON.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def _median_time(function, repeats: int) -> tuple[float, list[float]]:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), times


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file for the results")
    parser.add_argument("--repeats", type=int, default=7, help="repeats of the fast timings (default 7)")
    parser.add_argument("--derive-repeats", type=int, default=3, help="repeats of the derivation (default 3)")
    parser.add_argument("--baseline-repeats", type=int, default=3, help="repeats of the baseline (default 3)")
    args = parser.parse_args(argv)

    import sympy as sp
    from scipy.integrate import solve_ivp

    import yaml

    from parksteer.figures.model import FigureDesign, run_simulation
    from parksteer.model.codegen.cache import build_entry
    from parksteer.model.symbolic.components import resolve_effects
    from parksteer.model.symbolic.derive import derive
    from parksteer.measure.io import read_measurement
    from parksteer.measure.smoothing import smooth_rack
    from parksteer.model.numeric.prescribed import solve as solve_prescribed
    from parksteer.model.numeric.simulate import _atol, prepare, simulate, static_state
    from parksteer.model.numeric.tolerances import RTOL
    from parksteer.parameters import load_parameters
    from parksteer.tables import write_json

    params = load_parameters()
    effects = resolve_effects(None)
    design = FigureDesign.from_config(yaml.safe_load((REPO / "config" / "config.yaml").read_text(encoding="utf-8")))
    runs = [(case, design.variants[variant].effects, design.variants[variant].surface)
            for case, variant in design.all_simulations()]
    for case, variant_effects, surface in runs:  # warm the cache (derives any missing model once)
        run_simulation(params, case, variant_effects, surface)

    cycle_s, cycle_all = _median_time(lambda: simulate("unladen", params=params), args.repeats)

    measurement = read_measurement(REPO / "data" / "measurements" / "example_unladen.csv", params)
    smoothing_s, smoothing_all = _median_time(lambda: smooth_rack(measurement.time_s, measurement.rack_m),
                                              args.repeats)
    rack = smooth_rack(measurement.time_s, measurement.rack_m)
    replay_run = prepare(measurement.case, effects=effects, surface=measurement.surface, params=params)
    replay_s, replay_all = _median_time(
        lambda: solve_prescribed(replay_run, replay_run.p, rack, measurement.time_s), args.repeats)
    replay_outputs_s, replay_outputs_all = _median_time(
        lambda: solve_prescribed(replay_run, replay_run.p, rack, measurement.time_s, outputs=True), args.repeats)
    figures_s, figures_all = _median_time(
        lambda: [run_simulation(params, c, e, s) for c, e, s in runs], max(3, args.repeats // 2))

    derive_totals, derive_parts = [], []
    for _ in range(args.derive_repeats):
        with tempfile.TemporaryDirectory() as scratch:
            start = time.perf_counter()
            info = build_entry(effects, Path(scratch) / "entry")
            derive_totals.append(time.perf_counter() - start)
            derive_parts.append(info["timings_s"])
    derive_s = statistics.median(derive_totals)

    # Baseline: plain lambdify of the same equations, solve_ivp Radau, same tolerances and outputs.
    run = prepare("unladen", effects=effects, params=params)
    derivation = derive(effects)
    space, plain = derivation.space, derivation.plain_symbols()
    n = run.model.n_q
    q = [plain[x] for x in space.q]
    u = [plain[x] for x in space.u]
    symbols = [space.parameter_symbols[k] for k in run.model.info["parameters"]]
    p_model = run.p[: len(symbols)]
    profile = run.profile
    y0 = static_state(run)
    t_out = np.round(np.arange(0.0, 18.0 + 0.005, 0.01), 12)
    fast_torque = simulate("unladen", params=params).columns["handwheel_torque_Nm"]

    def time_baseline(cse: bool, repeats: int) -> dict:
        start = time.perf_counter()
        arguments = [q, u, symbols, space.handwheel_angle, space.handwheel_rate]
        mass = sp.lambdify(arguments, derivation.mass_matrix.xreplace(plain), "numpy", cse=cse)
        forcing = sp.lambdify(arguments, derivation.forcing.xreplace(plain), "numpy", cse=cse)
        lambdify_s = time.perf_counter() - start

        def rhs(t, y):
            angle, rate = profile.angle_rate(t)
            hw = (angle[0], rate[0])
            a = np.linalg.solve(mass(y[:n], y[n:], p_model, *hw), np.ravel(forcing(y[:n], y[n:], p_model, *hw)))
            return np.concatenate([y[n:], a])

        solutions = []

        def baseline():
            solutions.append(solve_ivp(rhs, (0.0, 18.0), y0, method="Radau", rtol=RTOL, atol=_atol(run.model),
                                       t_eval=t_out))

        median, every = _median_time(baseline, repeats)
        sol = solutions[-1]
        torque = run.model.evaluate_outputs(sol.t, sol.y.T, run.p)["column_torque_Nm"]
        return {"median": median, "all": every, "lambdify_s": lambdify_s, "rhs_evaluations": int(sol.nfev),
                "jacobian_evaluations": int(sol.njev),
                "max_torque_difference_to_fast_path_Nm": float(np.max(np.abs(torque - fast_torque)))}

    # Reference: the same compiled functions called back from odeint (LSODA), same tolerances and outputs.
    from scipy.integrate import odeint

    model, p = run.model, run.p
    corners = np.array([piece[0] for piece in profile.pieces])
    lsoda_solutions = []

    def lsoda():
        lsoda_solutions.append(odeint(lambda y, t: model.rhs(t, y, p), y0, t_out,
                                      Dfun=lambda y, t: model.jacobian(t, y, p), rtol=RTOL, atol=_atol(model),
                                      mxstep=5000, tcrit=corners))

    lsoda_s, lsoda_all = _median_time(lsoda, args.repeats)
    lsoda_torque = model.evaluate_outputs(t_out, lsoda_solutions[-1], p)["column_torque_Nm"]
    lsoda_reference = {"median": lsoda_s, "all": lsoda_all,
                       "max_torque_difference_to_fast_path_Nm": float(np.max(np.abs(lsoda_torque - fast_torque)))}

    plain_baseline = time_baseline(False, args.baseline_repeats)
    cse_baseline = time_baseline(True, args.baseline_repeats)
    baseline_s = plain_baseline["median"]

    results = {
        "machine": {"python": sys.version.split()[0], "platform": platform.platform(), "cpus": os.cpu_count()},
        "repeats": {"fast": args.repeats, "derive": args.derive_repeats, "baseline": args.baseline_repeats},
        "one_cycle_s": {"median": cycle_s, "all": cycle_all, "target": 0.01},
        "reference_odeint_callbacks_s": lsoda_reference,
        "speedup_one_cycle_vs_odeint_callbacks": lsoda_s / cycle_s,
        "prescribed_rack_replay_s": {"median": replay_s, "all": replay_all, "target": 0.3,
                                     "file": "data/measurements/example_unladen.csv"},
        "prescribed_rack_replay_with_outputs_s": {"median": replay_outputs_s, "all": replay_outputs_all,
                                                  "target": 0.3},
        "rack_smoothing_s": {"median": smoothing_s, "all": smoothing_all},
        "figure_simulations_s": {"median": figures_s, "all": figures_all, "count": len(runs)},
        "derive_codegen_compile_s": {"median": derive_s, "all": derive_totals, "target": 5.0,
                                     "parts_of_last": derive_parts[-1]},
        "baseline_lambdify_radau_s": plain_baseline,
        "baseline_lambdify_cse_radau_s": cse_baseline,
        "speedup_one_cycle_vs_baseline": baseline_s / cycle_s,
        "speedup_one_cycle_vs_cse_baseline": cse_baseline["median"] / cycle_s,
        "tolerances": {"rtol": RTOL, "atol": _atol(run.model).tolist()},
    }
    write_json(args.out, results)
    rows = [
        ("one 18 s cycle (generated C integrator)", cycle_s),
        ("reference: the same C called back from odeint", lsoda_s),
        ("one 18 s prescribed-rack replay (torque)", replay_s),
        ("the same with outputs (simulate --rack-from)", replay_outputs_s),
        ("smoothing its rack", smoothing_s),
        (f"all figure simulations ({len(runs)})", figures_s),
        ("derivation + codegen + compile", derive_s),
        ("baseline: lambdify + Radau, one cycle", baseline_s),
        ("baseline: lambdify(cse=True) + Radau, one cycle", cse_baseline["median"]),
    ]
    width = max(len(r[0]) for r in rows)
    print(f"{'timing (median)':<{width}}  seconds")
    for label, value in rows:
        print(f"{label:<{width}}  {value:9.4f}")
    print(f"{'speed-up of one cycle over odeint callbacks':<{width}}  {lsoda_s / cycle_s:9.1f}x")
    print(f"{'speed-up of one cycle over the baseline':<{width}}  {baseline_s / cycle_s:9.1f}x")
    print(f"{'speed-up over the cse baseline':<{width}}  {cse_baseline['median'] / cycle_s:9.1f}x")
    print(f"{'baseline vs fast path, max torque difference':<{width}}  "
          f"{plain_baseline['max_torque_difference_to_fast_path_Nm']:9.4f} N m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
