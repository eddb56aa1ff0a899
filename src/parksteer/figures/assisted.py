"""figures/diag_assisted: the assisted benchmark (:mod:`parksteer.experiments.assisted_benchmark`) scored and drawn."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..plotting import COLOURS, new_figure, save_svg
from .diagnosis_benchmarks import VARIATION_SHADES, grid_cell

# The hidden candidates' names in the assisted benchmarks' figures (this one and figures/assisted_truth.py).
LABELS = {"assist_motor_friction": "motor friction", "torsion_bar_offset": "torsion-bar offset",
          "boost_gain_error": "boost gain error", "rack_friction": "rack friction (calibrated)"}


def assisted_figure(rows: list[dict], summary: dict, path: str | Path) -> None:
    """Left: per hidden candidate the records named (of those of at least the named-rate's size), the nulls called
    adequate and the out-of-class records without a confident wrong answer, each shaded by whether its target holds.
    Right: each record's calibrated weighted error in noise floors (nulls, hidden, out of class) against the
    diagnosis's adequate_rms_factor."""
    from ..diagnose.settings import DEFAULT_SETTINGS
    from ..experiments.variations import NAMED_TARGET, NULL_ADEQUATE_TARGET

    cells = [(LABELS.get(h, h), k, n, NAMED_TARGET) for h, (k, n) in summary["named_by_hidden"].items()]
    targets = summary["targets"]
    cells.append(("nothing hidden: adequate", *targets["null_adequate"]["count"], NULL_ADEQUATE_TARGET))
    outclass = [r for r in rows if r["kind"] == "outclass"]
    right = sum(not r["confident_wrong"] for r in outclass)
    cells.append(("out of class: no confident wrong", right, len(outclass), 1.0))
    fig, axes = new_figure(7.4, 0.34 * len(cells) + 1.4, ncols=2, gridspec_kw={"width_ratios": [0.8, 1.8]})
    ax = axes[0]
    for i, (_label, k, n, target) in enumerate(cells):
        ax.add_patch(grid_cell(0, i, VARIATION_SHADES[None if n == 0 else k / n >= target]))
        ax.text(0, i, f"{k}/{n}" if n else "-", ha="center", va="center", fontsize=7)
    ax.set_xlim(-0.5, 0.5)
    ax.set_ylim(len(cells) - 0.5, -0.5)
    ax.set_xticks([0], ["records"], fontsize=7)
    ax.xaxis.tick_top()
    ax.set_yticks(np.arange(len(cells)), [c[0] for c in cells], fontsize=7)
    ax.grid(False)
    ax = axes[1]
    kinds = (("null", "o", "nothing hidden"), ("hidden", "^", "candidate hidden"), ("outclass", "s", "out of class"))
    # A logarithmic axis drawn as log10 values taken one by one with math.log10: numpy's vectorised logarithm (a
    # log-scale axis's transform) may differ in the last bit between SIMD levels, and moves the layout with it.
    for j, (kind, marker, label) in enumerate(kinds):
        values = [math.log10(r["calibrated_over_floor"]) for r in rows if r["kind"] == kind]
        ax.plot(values, [j] * len(values), marker, color=COLOURS[j], markersize=5, alpha=0.7, linestyle="none",
                label=label)
    adequate = DEFAULT_SETTINGS.adequate_rms_factor
    ax.axvline(math.log10(adequate), color="black", linestyle="--", linewidth=1.0,
               label=f"adequate_rms_factor {adequate:g}")
    ax.set_yticks(range(len(kinds)), [k[2] for k in kinds], fontsize=7)
    ax.set_ylim(len(kinds) - 0.5, -0.5)
    ticks = [t for t in (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0) if t <= max(r["calibrated_over_floor"] for r in rows) * 1.2]
    ax.set_xticks([math.log10(t) for t in ticks], [f"{t:g}" for t in ticks])
    ax.set_xlabel("calibrated weighted RMS error / noise floor\n(torsion-bar torque and current)", fontsize=8)
    ax.legend(fontsize=6.5, loc="upper right")  # the nulls sit near 1: the upper right is free
    fig.tight_layout()
    save_svg(fig, path)


def _assisted_params(parameters: str | Path, vehicle: str | Path):
    from ..parameters import load_parameters
    from ..vehicle import load_vehicle

    return load_vehicle(vehicle, load_parameters(parameters))


def make_assisted_figure(parameters: str | Path, vehicle: str | Path, svg: str | Path, csv: str | Path,
                         json_path: str | Path, progress=None) -> dict:
    """Run the assisted benchmark on `vehicle` (its [assist]) over `parameters` in this process, write
    figures/diag_assisted.svg, its CSV (one row per record) and results/diag_assisted.json (the targets and the
    misses), without machine times."""
    from ..experiments.assisted_benchmark import AssistedDesign, run

    rows, summary = run(_assisted_params(parameters, vehicle), AssistedDesign(), progress=progress)
    return _write_outputs(rows, summary, vehicle, svg, csv, json_path)


def gather_assisted_figure(batches, names: list[str], vehicle: str | Path, svg: str | Path, csv: str | Path,
                           json_path: str | Path) -> dict:
    """make_assisted_figure's files from the rows the jobs of rule diag_assisted_batch wrote into the folders
    `batches` (parksteer.experiments.assisted_benchmark.run_batch), the cases `names` in the design's order: the
    same bytes."""
    from ..experiments.assisted_benchmark import read_rows, summarise

    rows = read_rows(batches, list(names))
    return _write_outputs(rows, summarise(rows), vehicle, svg, csv, json_path)


def _write_outputs(rows: list[dict], summary: dict, vehicle: str | Path, svg: str | Path, csv: str | Path,
                   json_path: str | Path) -> dict:
    from ..reporting.report import MACHINE_TIME_KEYS, without_machine_times
    from ..tables import write_csv, write_json

    assisted_figure(rows, summary, svg)
    fields = ["name", "kind", "variation", "hidden", "steps_requested", "steps", "strength", "verdict", "effect",
              "indistinguishable", "named", "covered", "relation", "bic_margin", "confident_wrong",
              "calibrated_over_floor"]

    def cell(value):
        if value is None:
            return ""
        return ("yes" if value else "no") if isinstance(value, bool) else value

    columns = {n: [cell(r.get(n)) for r in rows] for n in fields if n not in MACHINE_TIME_KEYS}
    write_csv(csv, columns, {"figure": "diag_assisted: one row per record of the assisted benchmark",
                             "vehicle": Path(vehicle).name,
                             "steps": "hidden size reached, converter steps of torsion-bar torque RMS",
                             "named": "hidden candidate named (or in the reported group); rack friction: adequate",
                             "covered": "rack friction: the calibrated interval holds the true value",
                             "confident_wrong": "out of class: an unrelated candidate named beyond the BIC band"})
    write_json(json_path, without_machine_times(summary))
    return summary
