"""Figures of the diagnosis's benchmarks: in class (:func:`make_benchmark_figure`), out of class
(:func:`make_outclass_figure`) and over the variation grid (:func:`make_variations_figure`), and the grid cell
the benchmark figures share.

Every figure draws with :func:`parksteer.plotting.new_figure` and saves with
:func:`parksteer.plotting.save_svg` (byte-deterministic SVG).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import COLOURS, new_figure, save_svg


def benchmark_figure(rows: list, summary: dict, path: str | Path) -> None:
    """Confusion matrix of the hidden-effect benchmark, and accuracy against the hidden strength."""
    truths = sorted({r.hidden for r in rows if r.kind == "candidate"})
    truth_labels = truths + (["nothing"] if any(r.kind == "null" for r in rows) else []) + sorted(
        {f"outside: {r.hidden}" for r in rows if r.kind == "outside"})
    said_labels = truths + sorted({r.said for r in rows} - set(truths) - {"adequate", "unexplained"}) + [
        "adequate", "unexplained"]
    counts = np.zeros((len(truth_labels), len(said_labels)))
    for truth, said in summary["confusion"].items():
        for label, count in said.items():
            counts[truth_labels.index(truth), said_labels.index(label)] = count
    fig, axes = new_figure(7.0, 8.6, nrows=2, gridspec_kw={"height_ratios": [2.2, 1.0]})
    ax = axes[0]
    ax.imshow(counts, cmap="Blues", aspect="auto")
    for i in range(counts.shape[0]):
        for j in range(counts.shape[1]):
            if counts[i, j]:
                ax.text(j, i, f"{counts[i, j]:g}", ha="center", va="center", fontsize=7,
                        color="white" if counts[i, j] > counts.max() / 2 else "black")
    ax.set_xticks(np.arange(len(said_labels)), [s.replace("_", " ") for s in said_labels], rotation=60, ha="right",
                  fontsize=7)
    ax.set_yticks(np.arange(len(truth_labels)), [s.replace("_", " ") for s in truth_labels], fontsize=7)
    ax.set_xlabel("diagnosis")
    ax.set_ylabel("hidden")
    ax.grid(False)
    ax = axes[1]
    steps = sorted(float(s) for s in summary["by_steps"])
    first = [summary["by_steps"][f"{s:g}"]["named_first"] for s in steps]
    group = [summary["by_steps"][f"{s:g}"]["named_or_group"] for s in steps]
    # "named first" is a subset of "named or in the group": where the curves coincide the wide pale line
    # underneath stays visible beside the narrow dashed one on top
    ax.plot(steps, first, "o-", color=COLOURS[0], linewidth=4.0, markersize=9, alpha=0.55, zorder=2,
            label="named first")
    ax.plot(steps, group, "s--", color=COLOURS[1], linewidth=1.2, markersize=4, zorder=3,
            label="named first or in the indistinguishable group")
    ax.axhline(summary["targets"]["named_or_group_at_2_steps"], color="black", linestyle=":", linewidth=1.0,
               label="target from 2 steps")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlabel("hidden effect, converter steps of torque RMS")
    ax.set_ylabel("fraction of data sets")
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    save_svg(fig, path)


def make_benchmark_figure(truth_paths, diagnosis_paths, svg: str | Path, csv: str | Path, json_path: str | Path,
                          design=None) -> dict:
    """figures/diag_benchmark.svg (confusion matrix, accuracy against strength), its CSV, results JSON."""
    from ..experiments.benchmark import aggregate
    from ..reporting.report import MACHINE_TIME_KEYS, without_machine_times
    from ..experiments.rows import csv_columns
    from ..tables import write_csv, write_json

    rows, summary = aggregate(truth_paths, diagnosis_paths, design)
    benchmark_figure(rows, summary, svg)
    # machine times differ from run to run: out of the checksummed figure data and the key numbers
    columns = csv_columns(rows, MACHINE_TIME_KEYS)
    write_csv(csv, columns, {"figure": "diag_benchmark: one row per synthetic data set",
                             "steps": "hidden size as converter steps of torque RMS on the unladen ground file"})
    write_json(json_path, without_machine_times(summary))
    return summary


OUTCLASS_SHADES = {"closest": "#4daf4a", "related": "#b8e186", "unrelated": "#e41a1c", "unexplained": "#bdbdbd",
                   "adequate": "#ff7f00", "correct": "#4daf4a", "not adequate": "#bdbdbd", "false alarm": "#e41a1c"}


def outclass_figure(rows: list, path: str | Path) -> None:
    """The out-of-class confusion table: each hidden rival (a row, with its physically closest candidate) against
    what the diagnosis said (a column), the cell shaded by how the answer relates to the rival's physics and
    labelled with the BIC margin over the runner-up when a candidate was named, or with the nearest candidate when
    one was strongly evidenced but left the error too far above the floor to be named."""
    truths = sorted({(r.hidden, r.closest) for r in rows if r.kind == "rival"})
    truth_labels = [h for h, _ in truths] + (["nothing"] if any(r.kind == "null" for r in rows) else [])
    closest = dict(truths)
    named = sorted({r.said for r in rows} - {"adequate", "unexplained"})
    said_labels = named + ["adequate", "unexplained"]
    fig, ax = new_figure(7.0, 0.45 * len(truth_labels) + 2.2)
    for r in rows:
        i, j = truth_labels.index(r.hidden), said_labels.index(r.said)
        ax.add_patch(grid_cell(j, i, OUTCLASS_SHADES[r.relation]))
        text = f"{r.steps_actual:.1f} st" if r.kind == "rival" else r.relation
        if r.bic_margin is not None:
            text += f"\nΔBIC {r.bic_margin:.0f}"
        elif r.nearest != "none":
            text += f"\nnearest {r.nearest.replace('_', ' ')}"
        ax.text(j, i, text, ha="center", va="center", fontsize=6)
    ax.set_xlim(-0.5, len(said_labels) - 0.5)
    ax.set_ylim(len(truth_labels) - 0.5, -0.5)
    ax.set_xticks(np.arange(len(said_labels)), [s.replace("_", " ") for s in said_labels], rotation=45, ha="right",
                  fontsize=7)
    ax.set_yticks(np.arange(len(truth_labels)),
                  [f"{h.replace('_', ' ')} ({closest[h].replace('_', ' ')})" if h in closest else h
                   for h in truth_labels], fontsize=7)
    ax.set_xlabel("diagnosis")
    ax.set_ylabel("hidden rival (physically closest candidate)")
    ax.grid(False)
    from matplotlib.patches import Patch

    shown = [k for k in ("closest", "related", "unrelated", "unexplained", "adequate")
             if any(r.relation == k for r in rows if r.kind == "rival")]
    ax.legend(handles=[Patch(color=OUTCLASS_SHADES[k], label=k) for k in shown], fontsize=7, loc="upper left",
              bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    save_svg(fig, path)


def grid_cell(x: float, y: float, colour: str):
    from matplotlib.patches import Rectangle

    return Rectangle((x - 0.5, y - 0.5), 1.0, 1.0, color=colour, alpha=0.8)


def make_outclass_figure(truth_paths, diagnosis_paths, svg: str | Path, csv: str | Path, json_path: str | Path,
                         design=None) -> dict:
    """figures/diag_outclass.svg (the out-of-class confusion table), its CSV (one row per data set), results JSON."""
    from ..experiments.outclass import aggregate
    from ..reporting.report import MACHINE_TIME_KEYS, without_machine_times
    from ..experiments.rows import csv_columns
    from ..tables import write_csv, write_json

    rows, summary = aggregate(truth_paths, diagnosis_paths, design)
    outclass_figure(rows, svg)
    # machine times differ from run to run: out of the checksummed figure data and the key numbers
    columns = csv_columns(rows, MACHINE_TIME_KEYS, none="")
    write_csv(csv, columns, {"figure": "diag_outclass: one row per out-of-class data set",
                             "steps_actual": "hidden rival's RMS torque change in converter steps (all files)",
                             "bic_margin": "named candidate's BIC gain over the runner-up's",
                             "explained_fraction": "of the excess above the floor, by the named candidate or else "
                                                   "by the nearest",
                             "nearest": "strongly evidenced best candidate, named or not (none: no BIC gain above "
                                        "the threshold)"})
    write_json(json_path, without_machine_times(summary))
    return summary


VARIATION_SHADES = {True: "#4daf4a", False: "#e41a1c", None: "#e0e0e0"}


def variations_figure(rows: list[dict], summary: dict, path: str | Path) -> None:
    """The variation benchmark, one row per variation and one for the whole grid. Left: the three targets' rates
    (named, nulls adequate, intervals covering), each cell its count and shaded by whether the target holds.
    Right: each null record's calibrated weighted error in noise floors (circles) and each named record's error
    with the named effect (triangles), against the diagnosis's adequate_rms_factor and missing_rms_ceiling."""
    from ..diagnose.settings import DEFAULT_SETTINGS
    from ..experiments.variations import COVERAGE_TARGET, NAMED_TARGET, NULL_ADEQUATE_TARGET

    table = summary["variations"]
    labels = [v["variation"].replace("_", " ") for v in table] + ["all"]
    columns = [("named", NAMED_TARGET, f"named\n(≥ {summary['named_min_steps']:g} steps)"),
               ("null_adequate", NULL_ADEQUATE_TARGET, "nulls\nadequate"),
               ("coverage", COVERAGE_TARGET, "95 % intervals\ncovering")]
    fig, axes = new_figure(7.4, 0.34 * len(labels) + 1.6, ncols=2, gridspec_kw={"width_ratios": [1.1, 1.6]})
    ax = axes[0]
    for i, entry in enumerate(table + [None]):
        for j, (key, target, _title) in enumerate(columns):
            k, n = (entry[f"{key}_count"] if entry is not None else summary["targets"][key]["count"])
            met = None if n == 0 else k / n >= target
            ax.add_patch(grid_cell(j, i, VARIATION_SHADES[met]))
            ax.text(j, i, f"{k}/{n}" if n else "-", ha="center", va="center", fontsize=7,
                    fontweight="bold" if entry is None else "normal")
    ax.axhline(len(table) - 0.5, color="black", linewidth=0.8)
    ax.set_xlim(-0.5, len(columns) - 0.5)
    ax.set_ylim(len(labels) - 0.5, -0.5)
    ax.set_xticks(np.arange(len(columns)), [f"{t}\ntarget {100 * g:.0f} %" for _k, g, t in columns], fontsize=6.5)
    ax.xaxis.tick_top()
    ax.set_yticks(np.arange(len(labels)), labels, fontsize=7)
    ax.grid(False)
    ax = axes[1]
    for i, entry in enumerate(table):
        nulls = entry["null_over_floor"]
        after = entry["named_after_over_floor"]
        ax.plot(nulls, [i - 0.12] * len(nulls), "o", color=COLOURS[0], markersize=5, alpha=0.8,
                label="nothing hidden: calibrated model" if i == 0 else None)
        ax.plot(after, [i + 0.12] * len(after), "^", color=COLOURS[1], markersize=5, alpha=0.8,
                label="hidden effect named: with it" if i == 0 else None)
    adequate, ceiling = DEFAULT_SETTINGS.adequate_rms_factor, DEFAULT_SETTINGS.missing_rms_ceiling
    ax.axvline(adequate, color="black", linestyle="--", linewidth=1.0, label=f"adequate_rms_factor {adequate:g}")
    ax.axvline(ceiling, color="black", linestyle=":", linewidth=1.0, label=f"missing_rms_ceiling {ceiling:g}")
    values = [x for e in table for x in e["null_over_floor"] + e["named_after_over_floor"]]
    ax.set_xlim(min(values + [1.0]) - 0.05, max(values + [ceiling]) + 0.08)
    ax.set_ylim(len(labels) - 0.5, -0.5)
    ax.set_yticks(np.arange(len(labels)), [""] * len(labels))
    ax.set_xlabel("weighted RMS error, noise floors")
    # below the axes, clear of every row's markers
    ax.legend(fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2, frameon=False)
    fig.tight_layout()
    save_svg(fig, path)


def make_variations_figure(truth_paths, diagnosis_paths, svg: str | Path, csv: str | Path, json_path: str | Path,
                           design=None) -> dict:
    """figures/diag_variations.svg (targets per variation, errors against the thresholds), its CSV (one row per
    record) and results/diag_variations.json (the per-variation table and the targets)."""
    from ..reporting.report import MACHINE_TIME_KEYS, without_machine_times
    from ..experiments.rows import csv_columns
    from ..experiments.variation_summary import aggregate
    from ..tables import write_csv, write_json

    rows, summary = aggregate(truth_paths, diagnosis_paths, design)
    variations_figure(rows, summary, svg)
    # machine times differ from run to run: out of the checksummed figure data and the key numbers
    columns = csv_columns(rows, MACHINE_TIME_KEYS, none="")
    write_csv(csv, columns, {"figure": "diag_variations: one row per record set of the variation benchmark",
                             "steps": "hidden size requested, converter steps of torque RMS over the case's files",
                             "steps_actual": "the size the strength search reached",
                             "steps_observable": "the part of it the calibrated parameters cannot absorb, steps RMS",
                             "named": "verdict missing with the hidden effect named or in the reported group",
                             "calibrated_over_floor": "calibrated base model's weighted RMS error, noise floors",
                             "after_over_floor": "with the named effect, noise floors",
                             "covered": "of the reported model's 95 % intervals, those holding the true value"})
    write_json(json_path, without_machine_times(summary))
    return summary
