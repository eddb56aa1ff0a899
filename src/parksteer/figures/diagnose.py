"""Figures of the model-against-measurement work: comparison, diagnosis, error ladder, benchmark.

Every figure draws with :func:`parksteer.plotting.new_figure` and saves with
:func:`parksteer.plotting.save_svg` (byte-deterministic SVG).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..names import SURFACES
from ..measure.phases import PHASES
from ..plotting import COLOURS, new_figure, save_svg

MEASURED = "#999999"


def _phase_bars(ax, comparisons, labels, floors) -> None:
    width = 0.8 / max(len(comparisons), 1)
    x = np.arange(len(PHASES))
    for k, (c, label) in enumerate(zip(comparisons, labels)):
        rms = [c.by_phase[p].rms if p in c.by_phase else 0.0 for p in PHASES]
        ax.bar(x + (k - (len(comparisons) - 1) / 2) * width, rms, width, color=COLOURS[k % len(COLOURS)], label=label)
    for k, floor in enumerate(floors):
        ax.axhline(floor, color=COLOURS[k % len(COLOURS)], linestyle=":", linewidth=1.0)
    ax.set_xticks(x, [p.replace("_", " ") for p in PHASES])
    ax.set_ylabel("RMS error (N m)")
    ax.set_title("error by phase (dotted: noise floor)", fontsize=9)


def shown_files(files, limit: int = 2) -> list[int]:
    """Indices of the files a figure overlays: the first on the ground and the first on air bearings."""
    picked = []
    for surface in SURFACES:
        picked += [i for i, f in enumerate(files) if f.surface == surface][:1]
    return (picked or list(range(len(files))))[:limit]


def compare_figure(result, path: str | Path, shown: list[int] | None = None) -> None:
    """Torque against rack (measured and model), residual against rack, RMS error by phase (for the files `shown`)."""
    shown = shown if shown is not None else list(range(min(len(result.files), 4)))
    # an assisted car's motor channel, where fitted, gets a panel of its own below the three
    motor = any(result.files[i].uses_motor for i in shown)
    fig, axes = new_figure(7.0, 10.5 if motor else 8.0, nrows=4 if motor else 3)
    for k, i in enumerate(shown):
        f, prediction = result.files[i], result.predictions[i]
        m = f.torque_part(prediction)
        colour = COLOURS[k % len(COLOURS)]
        label = f"{f.label} ({f.case}, {f.surface.replace('_', ' ')})"
        axes[0].plot(f.rack_m * 1000, f.torque_Nm, ".", color=colour, markersize=1.5, alpha=0.35)
        axes[0].plot(f.rack_m * 1000, m, color=colour, linewidth=1.0, label=label)
        axes[1].plot(f.rack_m * 1000, f.torque_Nm - m, ".", color=colour, markersize=1.5)
        if f.uses_motor:
            axes[3].plot(f.rack_m * 1000, f.motor, ".", color=colour, markersize=1.5, alpha=0.35)
            axes[3].plot(f.rack_m * 1000, f.motor_part(prediction), color=colour, linewidth=1.0)
    if motor:
        axes[3].set_ylabel("motor channel (A or N m)")
        axes[3].set_xlabel("rack displacement (mm)")
        axes[3].set_title("assisted car's motor: measured (dots) and model (lines)", fontsize=9)
    axes[0].set_ylabel("handwheel torque (N m)")
    axes[0].set_title("measured (dots) and model (lines)", fontsize=9)
    axes[0].legend(fontsize=7)
    axes[1].set_ylabel("measured - model (N m)")
    axes[1].set_xlabel("rack displacement (mm)")
    _phase_bars(axes[2], [result.comparisons[i] for i in shown], [result.files[i].label for i in shown],
                [result.files[i].noise.total_rms for i in shown])
    axes[2].legend(fontsize=7)
    fig.tight_layout()
    save_svg(fig, path)


def make_compare_figure(parameters: str | Path, files: list[str | Path], svg: str | Path, csv: str | Path,
                        json_path: str | Path, effects=None) -> dict:
    """figures/diag_compare: the model with its own parameter values against measurement files."""
    from ..diagnose.compare import compare_files
    from ..diagnose.problem import load_files
    from ..parameters import load_parameters
    from ..tables import write_csv, write_json

    params = load_parameters(parameters)
    result = compare_files(load_files(list(files), params), params, effects)
    shown = shown_files(result.files)
    compare_figure(result, svg, shown)
    columns = {"file": [], "time_s": [], "rack_m": [], "measured_Nm": [], "model_Nm": []}
    for i in shown:
        f, m = result.files[i], result.predictions[i]
        columns["file"] += [f.label] * f.n
        columns["time_s"] += list(f.time_s)
        columns["rack_m"] += list(f.rack_m)
        columns["measured_Nm"] += list(f.torque_Nm)
        columns["model_Nm"] += list(m)
    write_csv(csv, columns, {"figure": "diag_compare: measured and replayed handwheel torque of the files shown",
                             "model": ", ".join(e.name for e in result.effects) + " at the parameter file's values"})
    summary = result.as_dict()
    summary["shown"] = [result.files[i].label for i in shown]
    write_json(json_path, summary)
    return summary


def diagnosis_figure(diagnosis, path: str | Path) -> None:
    """First file: torque and residual against rack for the calibrated model and with the best candidate; for an
    assisted car whose motor channel is fitted, that channel measured and fitted, and its residual, beside the
    torque's; ranking."""
    from ..reporting.report import candidate_predictions, candidate_statistics

    f = diagnosis.problem.files[0]
    fig, axes = new_figure(7.0, 12.0 if f.uses_motor else 8.0, nrows=5 if f.uses_motor else 3)
    if f.uses_motor:
        _motor_panels(diagnosis, axes[2], axes[3])
        axes = [axes[0], axes[1], axes[4]]
    rack_mm = f.rack_m * 1000
    calibrated = f.torque_part(diagnosis.calibration.predictions[0])
    axes[0].plot(rack_mm, f.torque_Nm, ".", color=MEASURED, markersize=1.5, label=f"measured ({f.label})")
    axes[0].plot(rack_mm, calibrated, color=COLOURS[0], linewidth=1.0, label="calibrated model")
    axes[1].plot(rack_mm, f.torque_Nm - calibrated, ".", color=COLOURS[0], markersize=1.5, label="calibrated model")
    if diagnosis.best is not None:
        with_best = f.torque_part(candidate_predictions(diagnosis, diagnosis.best)[0])
        label = f"+ {diagnosis.best.name}"
        axes[0].plot(rack_mm, with_best, color=COLOURS[1], linewidth=1.0, label=label)
        axes[1].plot(rack_mm, f.torque_Nm - with_best, ".", color=COLOURS[1], markersize=1.5, label=label)
    axes[0].set_ylabel("handwheel torque (N m)")
    axes[0].legend(fontsize=7)
    axes[1].set_ylabel("measured - model (N m)")
    axes[1].set_xlabel("rack displacement (mm)")
    axes[1].legend(fontsize=7)
    ranked = diagnosis.ranked
    names = [c.name for c in ranked]
    stats = diagnosis.statistics(diagnosis.calibration.predictions)
    after = [candidate_statistics(diagnosis, c, stats)["weighted_rms_Nm"] for c in ranked]  # the report's numbers
    y = np.arange(len(names))
    axes[2].barh(y, after, color=[COLOURS[1] if c is diagnosis.best else COLOURS[5] for c in ranked])
    axes[2].axvline(stats["weighted_rms_Nm"], color=COLOURS[0], linestyle="--", linewidth=1.0, label="calibrated model")
    axes[2].axvline(stats["noise_floor_Nm"], color="black", linestyle=":", linewidth=1.0, label="noise floor")
    axes[2].set_yticks(y, names)
    axes[2].invert_yaxis()
    axes[2].set_xlabel("weighted RMS error with the candidate (N m)")
    axes[2].legend(fontsize=7)
    axes[2].set_title(f"verdict: {diagnosis.verdict}", fontsize=9)
    fig.tight_layout()
    save_svg(fig, path)


def _motor_panels(diagnosis, channel_ax, residual_ax) -> None:
    """The first file's motor channel (an assisted car's current or motor torque): measured, the calibrated model
    and with the best candidate against rack; and the residual of each."""
    from ..reporting.report import candidate_predictions

    f = diagnosis.problem.files[0]
    rack_mm = f.rack_m * 1000
    unit = "A" if f.motor_column == "motor_current_A" else "N m"
    name = f.motor_column.removesuffix("_A").removesuffix("_Nm").replace("_", " ")
    calibrated = f.motor_part(diagnosis.calibration.predictions[0])
    channel_ax.plot(rack_mm, f.motor, ".", color=MEASURED, markersize=1.5, label="measured")
    channel_ax.plot(rack_mm, calibrated, color=COLOURS[0], linewidth=1.0, label="calibrated model")
    residual_ax.plot(rack_mm, f.motor - calibrated, ".", color=COLOURS[0], markersize=1.5, label="calibrated model")
    if diagnosis.best is not None:
        with_best = f.motor_part(candidate_predictions(diagnosis, diagnosis.best)[0])
        label = f"+ {diagnosis.best.name}"
        channel_ax.plot(rack_mm, with_best, color=COLOURS[1], linewidth=1.0, label=label)
        residual_ax.plot(rack_mm, f.motor - with_best, ".", color=COLOURS[1], markersize=1.5, label=label)
    residual_ax.axhline(f.motor_noise.total_rms, color="black", linestyle=":", linewidth=0.8)
    residual_ax.axhline(-f.motor_noise.total_rms, color="black", linestyle=":", linewidth=0.8)
    channel_ax.set_ylabel(f"{name} ({unit})")
    channel_ax.set_title("assisted car's motor channel: measured (dots) and fitted (lines)", fontsize=9)
    channel_ax.legend(fontsize=7)
    residual_ax.set_ylabel(f"measured - model ({unit})")
    residual_ax.set_xlabel("rack displacement (mm)")
    residual_ax.set_title("motor channel residual (dotted: its noise floor RMS)", fontsize=9)
    residual_ax.legend(fontsize=7)


def ladder_figure(rungs: list[dict], noise_floor_Nm: float, attainable_floor_Nm: float, path: str | Path,
                  residuals: dict[str, np.ndarray] | None = None) -> None:
    """RMS error as the model grows one step at a time, down to the noise floor; the residual at each rung."""
    series = [key for key in (residuals or {}) if key.startswith("residual_")]
    rows = 1 + len(series)
    ratios = [2.2] + [1.0] * len(series)
    fig, axes = new_figure(6.4, 3.4 + 1.3 * len(series), nrows=rows, gridspec_kw={"height_ratios": ratios})
    axes = np.atleast_1d(axes)
    ax = axes[0]
    x = np.arange(len(rungs))
    ax.plot(x, [r["weighted_rms_Nm"] for r in rungs], "o-", color=COLOURS[0], label="weighted RMS error")
    ax.plot(x, [r["rms_Nm"] for r in rungs], "s--", color=COLOURS[1], markersize=4, label="plain RMS error")
    ax.axhline(noise_floor_Nm, color="black", linestyle=":", label="noise floor")
    ax.axhline(attainable_floor_Nm, color=COLOURS[2], linestyle="-.", linewidth=1.0,
               label="noise floor with replay uncertainty")
    ax.set_xticks(x, [r["label"] for r in rungs], fontsize=8)
    ax.set_xlim(-0.4, len(rungs) - 0.6)
    ax.set_yscale("log")
    ax.set_ylabel("RMS error (N m)")
    ax.legend(fontsize=7)
    if series:
        rack_mm = residuals["rack_m"] * 1000
        limit = max(float(np.max(np.abs(residuals[key]))) for key in series)
        for k, key in enumerate(series):
            label = key[len("residual_"):].replace("_Nm", "").replace("_", " ")
            axes[k + 1].plot(rack_mm, residuals[key], ".", markersize=1.5, color=COLOURS[k % len(COLOURS)])
            axes[k + 1].set_ylim(-1.05 * limit, 1.05 * limit)
            axes[k + 1].set_title(f"measured - {label} (N m)", fontsize=8, loc="left")
            if k < len(series) - 1:
                axes[k + 1].tick_params(labelbottom=False)
        axes[-1].set_xlabel("rack displacement (mm)")
    fig.tight_layout()
    save_svg(fig, path)


def make_ladder_figure(case_study_json: str | Path, residuals_csv: str | Path, svg: str | Path, csv: str | Path,
                       json_path: str | Path) -> dict:
    """figures/diag_ladder from the case study's numbers (results/case_study.json) and residuals."""
    import json

    from ..reporting.report import without_machine_times
    from ..tables import read_csv, write_csv, write_json

    study = json.loads(Path(case_study_json).read_text(encoding="utf-8"))
    ladder = study["ladder"]
    columns, header = read_csv(residuals_csv)
    residuals = {key: np.asarray(value, dtype=float) for key, value in columns.items() if key != "time_s"}
    ladder_figure(ladder["rungs"], ladder["noise_floor_Nm"], ladder["attainable_floor_Nm"], svg, residuals)
    rungs = ladder["rungs"]
    write_csv(csv, {"rung": [r["label"] for r in rungs], "rms_Nm": [r["rms_Nm"] for r in rungs],
                    "weighted_rms_Nm": [r["weighted_rms_Nm"] for r in rungs],
                    # the CSV column keeps its checksummed header
                    "weighted_rms_over_noise_floor": [r["over_floor"] for r in rungs]},
              {"figure": "diag_ladder: error as the model grows (synthetic car data set)",
               "noise_floor_Nm": f"{ladder['noise_floor_Nm']:.6g}",
               "attainable_floor_Nm": f"{ladder['attainable_floor_Nm']:.6g}"})
    summary = {key: study[key] for key in ("ladder", "compare", "diagnosis", "reveal", "data")}
    write_json(json_path, without_machine_times(summary))
    return summary


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


def phase_residual_figure(rows: list[dict], path: str | Path) -> None:
    """RMS residual by phase over all files (from :func:`parksteer.reporting.report.phase_residuals`): the calibrated
    model and, when the verdict names one, with the missing effect; the dotted line is the median noise floor."""
    fig, ax = new_figure(7.0, 3.0)
    present = [p for p in PHASES if any(r["phase"] == p for r in rows)]
    series = [("calibrated model", "calibrated_rms_Nm")]
    if rows and rows[0]["with_effect_rms_Nm"] is not None:
        series.append(("with the missing effect", "with_effect_rms_Nm"))
    x = np.arange(len(present))
    width = 0.8 / len(series)
    for k, (label, key) in enumerate(series):
        pooled = []
        for p in present:
            chosen = [r for r in rows if r["phase"] == p]
            n = sum(r["samples"] for r in chosen)
            pooled.append(float(np.sqrt(sum(r["samples"] * r[key] ** 2 for r in chosen) / n)))
        ax.bar(x + (k - (len(series) - 1) / 2) * width, pooled, width, color=COLOURS[k], label=label)
    if rows:
        ax.axhline(float(np.median([r["noise_floor_Nm"] for r in rows])), color="black", linestyle=":",
                   linewidth=1.0, label="noise floor (median of the files)")
    ax.set_xticks(x, [p.replace("_", " ") for p in present])
    ax.set_ylabel("RMS residual (N m)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    save_svg(fig, path)


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
        ax.add_patch(_cell(j, i, OUTCLASS_SHADES[r.relation]))
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


def _cell(x: float, y: float, colour: str):
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
            ax.add_patch(_cell(j, i, VARIATION_SHADES[met]))
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
    from ..experiments.variations import aggregate
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
