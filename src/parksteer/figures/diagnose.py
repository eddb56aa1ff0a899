"""Figures of the model-against-measurement work: comparison, diagnosis, error ladder, residual by phase.

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


