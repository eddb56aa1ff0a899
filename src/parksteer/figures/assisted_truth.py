"""figures/diag_assisted_truth: the assisted benchmark on an independent truth
(:mod:`parksteer.experiments.assisted_truth`) scored and drawn, one column per tier (rack logged, angle only)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import COLOURS, new_figure, save_svg
from .assisted import LABELS
from .diagnosis_benchmarks import VARIATION_SHADES, grid_cell

TIER_LABELS = {"rack": "rack logged", "angle": "angle only"}


def _cells(summary: dict) -> list[tuple[str, int, int, float]]:
    """(label, count, of, target) of one route and tier's summary."""
    from ..experiments.variations import NAMED_TARGET, NULL_ADEQUATE_TARGET

    cells = [(LABELS.get(h, h), k, n, NAMED_TARGET) for h, (k, n) in summary["named_by_hidden"].items()]
    cells.append(("nothing hidden: adequate", *summary["targets"]["null_adequate"]["count"], NULL_ADEQUATE_TARGET))
    outclass = summary["out_of_class"]
    right = len(outclass) - summary["targets"]["confident_wrong_out_of_class"]["value"]
    cells.append(("out of class: no confident wrong", right, len(outclass), 1.0))
    return cells


def assisted_truth_figure(rows: list[dict], summary: dict, path: str | Path) -> None:
    """Left: per route and tier (columns) the hidden records named per candidate, the nulls called adequate and the
    out-of-class records without a confident wrong answer, each shaded by whether its target holds. Right: each
    record's calibrated weighted error in noise floors, by kind, the tiers apart, against the diagnosis's
    adequate_rms_factor."""
    from ..diagnose.settings import DEFAULT_SETTINGS

    columns = [(route, tier) for route, tiers in summary["routes"].items() for tier in tiers]
    labels: list[str] = []
    for route, tier in columns:
        for label, *_ in _cells(summary["routes"][route][tier]):
            if label not in labels:
                labels.append(label)
    fig, axes = new_figure(7.4, 0.34 * max(len(labels), 4) + 1.5, ncols=2,
                           gridspec_kw={"width_ratios": [0.5 + 0.35 * len(columns), 1.8]})
    ax = axes[0]
    for j, (route, tier) in enumerate(columns):
        by_label = {c[0]: c for c in _cells(summary["routes"][route][tier])}
        for i, label in enumerate(labels):
            if label not in by_label:
                continue
            _, k, n, target = by_label[label]
            ax.add_patch(grid_cell(j, i, VARIATION_SHADES[None if n == 0 else k / n >= target]))
            ax.text(j, i, f"{k}/{n}" if n else "-", ha="center", va="center", fontsize=7)
    ax.set_xlim(-0.5, len(columns) - 0.5)
    ax.set_ylim(len(labels) - 0.5, -0.5)
    multi = len(summary["routes"]) > 1
    ax.set_xticks(range(len(columns)), [TIER_LABELS.get(t, t) + (f"\n{r}" if multi else "") for r, t in columns],
                  fontsize=7)
    ax.xaxis.tick_top()
    ax.set_yticks(np.arange(len(labels)), labels, fontsize=7)
    ax.grid(False)
    ax = axes[1]
    kinds = (("null", "nothing hidden"), ("hidden", "candidate hidden"), ("outclass", "out of class"))
    markers = {"rack": "o", "angle": "^"}
    for j, (kind, _label) in enumerate(kinds):
        for t, tier in enumerate(markers):
            values = [r["calibrated_over_floor"] for r in rows if r["kind"] == kind and r["tier"] == tier]
            if values:
                ax.plot(values, [j + (t - 0.5) * 0.25] * len(values), markers[tier], color=COLOURS[t],
                        markersize=5, alpha=0.7, linestyle="none",
                        label=TIER_LABELS[tier] if j == min(i for i, (k, _) in enumerate(kinds)
                                                            if any(r["kind"] == k and r["tier"] == tier
                                                                   for r in rows)) else None)
    adequate = DEFAULT_SETTINGS.adequate_rms_factor
    ax.axvline(adequate, color="black", linestyle="--", linewidth=1.0, label=f"adequate_rms_factor {adequate:g}")
    ax.set_yticks(range(len(kinds)), [k[1] for k in kinds], fontsize=7)
    ax.set_ylim(len(kinds) - 0.5, -0.5)
    ax.set_xscale("log")
    top = max(r["calibrated_over_floor"] for r in rows) * 1.2
    ticks = [t for t in (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0) if t <= max(top, 1.6)]
    ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
    ax.set_xticks([], minor=True)
    ax.set_xlabel("calibrated weighted RMS error / noise floor\n(torsion-bar torque and current)", fontsize=8)
    ax.legend(fontsize=6.5, loc="upper right")
    fig.tight_layout()
    save_svg(fig, path)


def gather_assisted_truth_figure(batches, names: list[str], section: dict | None, vehicle: str | Path,
                                 svg: str | Path, csv: str | Path, json_path: str | Path) -> dict:
    """figures/diag_assisted_truth.svg, its CSV (one row per record and route) and results/diag_assisted_truth.json
    (the targets per route and tier, the misses, the truth's description; no machine times) from the rows the jobs
    of rule diag_assisted_truth_batch wrote into the folders `batches`, the cases `names` in the design's order."""
    from ..reporting.report import MACHINE_TIME_KEYS, without_machine_times
    from ..experiments.assisted_truth import design_from_config, read_rows, summarise
    from ..tables import write_csv, write_json

    rows = read_rows(batches, list(names))
    summary = summarise(rows, design_from_config(section))
    assisted_truth_figure(rows, summary, svg)
    fields = ["name", "route", "tier", "kind", "variation", "hidden", "floors_requested", "floors", "strength",
              "torque_step_Nm", "verdict", "effect", "indistinguishable", "named", "covered", "relation",
              "bic_margin", "confident", "confident_wrong", "calibrated_over_floor"]

    def cell(value):
        if value is None:
            return ""
        return ("yes" if value else "no") if isinstance(value, bool) else value

    columns = {n: [cell(r.get(n)) for r in rows] for n in fields if n not in MACHINE_TIME_KEYS}
    write_csv(csv, columns, {"figure": "diag_assisted_truth: one row per record and route of the assisted "
                                       "benchmark on an independent truth",
                             "vehicle": Path(vehicle).name,
                             "floors": "hidden size reached, noise floors of torsion-bar torque RMS",
                             "named": "hidden candidate named (or in the reported group); rack friction: adequate",
                             "covered": "rack friction: the calibrated interval holds the true value",
                             "confident": "out of class: a candidate named beyond the BIC band",
                             "confident_wrong": "out of class: an unrelated candidate named beyond the BIC band"})
    write_json(json_path, without_machine_times(summary))
    return summary
