"""The figure of a user's own effect in a diagnosis (:mod:`parksteer.diagnose.stages.user_effect`): the error
ladder without it and with it, the record with both models and their residuals, the residual by phase before and
after, and the error falling as its strengths grow from 0 to their fitted values."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..measure.phases import PHASES
from ..plotting import COLOURS, new_figure, save_svg

MEASURED = "#999999"
BEFORE, AFTER = COLOURS[0], COLOURS[1]


def user_effect_figure(diagnosis, path: str | Path) -> None:
    """Five panels from the diagnosis's ``user_effect`` output (module docstring); the record is the first file."""
    found = diagnosis.outputs["user_effect"]
    names = ", ".join(found.effects)
    fig, axes = new_figure(7.0, 13.0, nrows=5, gridspec_kw={"height_ratios": [1.0, 1.3, 1.0, 1.0, 1.1]})
    _ladder(axes[0], found)
    f = diagnosis.problem.files[0]
    t = f.time_s - f.time_s[0]
    before = f.torque_part(found.without.predictions[0])
    after = f.torque_part(diagnosis.calibration.predictions[0])
    _record(axes[1], f, t, before, after, names)
    _residuals(axes[2], f, t, before, after)
    _residual_by_phase(axes[3], found)
    _strength_sweep(axes[4], found, names)
    fig.tight_layout()
    save_svg(fig, path)


def _ladder(ax, found) -> None:
    """The error ladder: measured floor, the calibrated model without the effect, with it."""
    x = np.arange(len(found.rungs))
    ax.bar(x, [r["over_floor"] for r in found.rungs], color=[MEASURED, BEFORE, AFTER][: len(found.rungs)])
    ax.axhline(1.0, color="black", linestyle=":", linewidth=1.0, label="noise floor")
    ax.set_xticks(x, [r["label"] for r in found.rungs], fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("weighted RMS / floor")
    ax.set_title("the error ladder: the paper's model, calibrated, with your effect", fontsize=9)
    ax.legend(fontsize=7)


def _record(ax, f, t, before, after, names: str) -> None:
    """The record's torque with both models', its rack on a second axis."""
    ax.plot(t, f.torque_Nm, ".", color=MEASURED, markersize=1.5, label=f"measured ({f.label})")
    ax.plot(t, before, color=BEFORE, linewidth=1.0, label="calibrated, without it")
    ax.plot(t, after, color=AFTER, linewidth=1.0, label=f"with {names}")
    ax.set_ylabel("handwheel torque (N m)")
    ax.legend(fontsize=7)
    twin = ax.twinx()
    twin.plot(t, f.rack_m * 1000, color=COLOURS[2], linewidth=0.6, alpha=0.5)
    twin.set_ylabel("rack (mm)", color=COLOURS[2])


def _residuals(ax, f, t, before, after) -> None:
    """Both models' residuals over the record, its phases shaded."""
    for k, phase in enumerate(PHASES):
        mask = f.phases.mask(phase)
        if mask.any():
            ax.fill_between(t, 0, 1, where=mask, color=COLOURS[(k + 3) % len(COLOURS)], alpha=0.12, linewidth=0,
                            transform=ax.get_xaxis_transform(), label=phase.replace("_", " "))
    ax.plot(t, f.torque_Nm - before, ".", color=BEFORE, markersize=1.2, label="without it")
    ax.plot(t, f.torque_Nm - after, ".", color=AFTER, markersize=1.2, label="with it")
    # the few samples at reversals where the rack cannot fix the instant friction turns over are left off the scale
    limit = float(np.percentile(np.abs(np.concatenate([f.torque_Nm - before, f.torque_Nm - after])), 99.0))
    ax.set_ylim(-1.3 * limit, 1.3 * limit)
    ax.set_ylabel("measured - model (N m)")
    ax.set_xlabel("time (s)")
    ax.legend(fontsize=6, ncol=4)


def _residual_by_phase(ax, found) -> None:
    """The RMS residual of each phase, pooled over the files, without and with the effect."""
    present = [p for p in PHASES if any(r["phase"] == p for r in found.phases)]
    xp = np.arange(len(present))
    for k, (label, key, colour) in enumerate((("without it", "without_rms_Nm", BEFORE),
                                              ("with it", "with_rms_Nm", AFTER))):
        pooled = []
        for p in present:
            rows = [r for r in found.phases if r["phase"] == p]
            count = sum(r["samples"] for r in rows)
            pooled.append(float(np.sqrt(sum(r["samples"] * r[key] ** 2 for r in rows) / count)))
        ax.bar(xp + (k - 0.5) * 0.4, pooled, 0.4, color=colour, label=label)
    ax.axhline(float(np.median([r["noise_floor_Nm"] for r in found.phases])), color="black", linestyle=":",
               linewidth=1.0, label="noise floor")
    ax.set_xticks(xp, [p.replace("_", " ") for p in present], fontsize=8)
    ax.set_ylabel("RMS residual (N m)")
    ax.set_title("the residual by phase of the cycle, all files", fontsize=9)
    ax.legend(fontsize=7)


def _strength_sweep(ax, found, names: str) -> None:
    """The error as the fitted strengths grow from 0 to their values (one strength, or their common fraction)."""
    sweep = found.sweep
    keys = sweep["keys"]
    if len(keys) == 1:
        q = found.strengths[keys[0]]
        xs, label = sweep["values"][keys[0]], f"{keys[0]} ({q['unit']})"
    else:
        xs, label = sweep["fractions"], f"fraction of the {len(keys)} fitted strengths of {names}"
    ax.plot(xs, sweep["over_floor"], "o-", color=AFTER)
    ax.axhline(1.0, color="black", linestyle=":", linewidth=1.0, label="noise floor")
    ax.set_yscale("log")
    ax.set_xlabel(label)
    ax.set_ylabel("weighted RMS / floor")
    ax.set_title(f"the error as the strength grows from 0 to its fitted value (floor {found.noise_floor_Nm:.3g} N m)",
                 fontsize=9)
    ax.legend(fontsize=7)


def user_effect_path(plot: str | Path) -> Path:
    """Where ``--plot OUT.svg`` writes the user effect's figure: ``OUT-user_effect.svg`` beside it."""
    plot = Path(plot)
    return plot.with_name(f"{plot.stem}-user_effect.svg")
