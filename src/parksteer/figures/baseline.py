"""figures/diag_baseline: the baseline benchmark (:mod:`parksteer.experiments.baseline`), each later record's
verdict diagnosed absolutely and against the car's healthy record, side by side."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import COLOURS, new_figure, save_svg
from .diagnosis_benchmarks import VARIATION_SHADES, grid_cell

SIDE_LABELS = {"absolute": "against the\nmodel", "baseline": "against the\nhealthy record"}
SHORT = {"adequate": "adequate", "unexplained": "unexplained", "missing": "missing"}


def right(row: dict, side: str) -> bool | None:
    """Whether `side`'s answer on `row` is right (None: not run): a hidden effect named, a null adequate, an
    out-of-class change not named with confidence."""
    said = row[side]
    if said is None:
        return None
    if row["kind"] == "hidden":
        return said["named"]
    if row["kind"] == "null":
        return said["verdict"] == "adequate"
    return not said["confident"]


def _short(name: str) -> str:
    """A name as a cell shows it: a changed calibrated value by its quantity (changed: rack_friction_force)."""
    return "changed: " + name.split(":", 1)[1].rsplit(".", 1)[-1] if name.startswith("changed:") else name


def _label(said: dict | None) -> str:
    if said is None:
        return "not run"
    return _short(said["effect"]) if said["verdict"] == "missing" else SHORT.get(said["verdict"], said["verdict"])


def baseline_figure(cars: list[dict], path: str | Path) -> None:
    """Left: one line per later record (grouped by car: its quirk), its answer absolutely and against the healthy
    record, each cell green where right, red where wrong, grey where not run. Right: each record's calibrated
    weighted RMS error in noise floors on both sides, against the absolute adequate threshold and each car's threshold
    of "as the baseline" (the larger of it and the absolute one, as the diagnosis applies it)."""
    from ..diagnose.settings import DEFAULT_SETTINGS

    rows = [r for c in cars for r in c["rows"]]
    height_in = 0.27 * max(len(rows), 6) + 1.4
    fig, axes = new_figure(7.6, height_in, ncols=2, gridspec_kw={"width_ratios": [2.3, 1.4]})
    # margins fixed in inches, not found from the text's extents (tight_layout): the axes' box, and the clip
    # path's id hashed from it, then hold to the last bit under every BLAS kernel and SIMD level
    fig.subplots_adjust(left=1.75 / 7.6, right=1.0 - 0.15 / 7.6, bottom=0.5 / height_in, top=1.0 - 0.85 / height_in,
                        wspace=0.06)
    ax = axes[0]
    for i, row in enumerate(rows):
        for j, side in enumerate(("absolute", "baseline")):
            ax.add_patch(grid_cell(j, i, VARIATION_SHADES[right(row, side)]))
            ax.text(j, i, _label(row[side]), ha="center", va="center", fontsize=6)
    labels = [f"{r['car']}: {_short(r['hidden']) if r['kind'] != 'null' else 'nothing'}"
              + (f" {r['floors']:.1f}" if r["kind"] != "null" else "") for r in rows]
    ax.set_xlim(-0.5, 1.5)
    ax.set_ylim(len(rows) - 0.5, -0.5)
    ax.set_xticks([0, 1], [SIDE_LABELS["absolute"], SIDE_LABELS["baseline"]], fontsize=7)
    ax.xaxis.tick_top()
    ax.set_yticks(np.arange(len(rows)), labels, fontsize=6)
    ax.grid(False)
    ax = axes[1]
    for j, (side, marker) in enumerate((("absolute", "o"), ("baseline", "^"))):
        values = [(i, r[side]["over_floor"]) for i, r in enumerate(rows) if r[side] is not None]
        if values:
            ax.plot([v for _, v in values], [i for i, _ in values], marker, color=COLOURS[j], markersize=4,
                    linestyle="none", label=SIDE_LABELS[side].replace("\n", " "))
    adequate = DEFAULT_SETTINGS.adequate_rms_factor
    ax.axvline(adequate, color="black", linestyle="--", linewidth=1.0, label=f"adequate, absolute ({adequate:g})")
    first = True
    for c in cars:  # "as the baseline": the car's own threshold, from the spread of its healthy data
        learnt = c.get("learnt")
        places = [i for i, r in enumerate(rows) if r["car"] == c["car"]]
        if learnt is None or not places:
            continue
        ax.plot([max(adequate, learnt["threshold_over_floor"])] * 2, [min(places) - 0.4, max(places) + 0.4],
                color=COLOURS[1], linestyle=":", linewidth=1.2, label="as the baseline, the car's" if first else None)
        first = False
    ax.set_ylim(len(rows) - 0.5, -0.5)
    ax.set_yticks(np.arange(len(rows)), [""] * len(rows))
    ax.set_xscale("log")
    top = max([r[s]["over_floor"] for r in rows for s in ("absolute", "baseline") if r[s] is not None] or [2.0])
    ticks = [t for t in (0.5, 1.0, 1.5, 2.0, 3.0, 5.0, 8.0, 12.0) if t <= max(1.2 * top, 2.0)]
    ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
    ax.set_xticks([], minor=True)
    ax.set_xlabel("calibrated error / noise floor", fontsize=8)
    ax.legend(fontsize=6, loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=1, frameon=False)
    save_svg(fig, path)


def _base_params(parameters: str | Path, vehicle: str | Path | None):
    from ..parameters import load_parameters
    from ..vehicle import load_vehicle

    params = load_parameters(parameters)
    return load_vehicle(vehicle, params) if vehicle is not None else params


def run_baseline_car(parameters: str | Path, vehicle: str | Path, section: dict | None, name: str,
                     out: str | Path) -> None:
    """One job of rule diag_baseline_batch: the car `name` of config["baseline"] (`section`) run on both sides
    (parksteer.experiments.baseline.run_car), its rows into `out`. A manual car is the parameter file's, an
    assisted car `vehicle`'s."""
    import sys

    from ..experiments.baseline import car_by_name, design_from_config, run_car, write_car

    car = car_by_name(design_from_config(section), name)
    params = _base_params(parameters, vehicle if car.kind == "assisted" else None)
    write_car(run_car(params, car, vehicle, progress=lambda line: print(line, file=sys.stderr)), out)


def gather_baseline_figure(paths, svg: str | Path, csv: str | Path, json_path: str | Path) -> dict:
    """figures/diag_baseline.svg, its CSV (one row per later record) and results/diag_baseline.json (the score
    per car and side, no machine times) from the jobs' files `paths`."""
    from ..experiments.baseline import read_cars, summarise
    from ..tables import write_csv, write_json

    cars = read_cars(paths)
    summary = summarise(cars)
    baseline_figure(cars, svg)
    rows = [r for c in cars for r in c["rows"]]

    def side(r, s, key):
        if r[s] is None:
            return "not run"
        value = r[s][key]
        return ("yes" if value else "no") if isinstance(value, bool) else value

    columns = {k: [r[k] for r in rows] for k in ("car", "name", "kind", "hidden", "hand", "bits", "tier",
                                                  "floors_requested", "floors")}
    for s in ("absolute", "baseline"):
        for key in ("verdict", "effect", "named", "confident", "over_floor"):
            columns[f"{s}_{key}"] = [side(r, s, key) for r in rows]
    write_csv(csv, columns, {"figure": "diag_baseline: one row per later record of the baseline benchmark, "
                                       "diagnosed absolutely and against the car's healthy record",
                             "floors": "hidden size reached, noise floors of torque RMS",
                             "named": "the hidden effect named (or in the reported group)",
                             "confident": "a candidate named beyond the BIC band"})
    write_json(json_path, summary)
    return summary
