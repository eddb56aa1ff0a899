"""The signature benchmark in the pipeline: out-of-library records diagnosed, the residual's signature and the
suggested effect scored per signature class (figures/diag_signature, results/diag_signature.json).

The records and their diagnoses are :mod:`parksteer.experiments.outoflibrary`'s (its default grid:
:class:`~parksteer.experiments.outoflibrary.SignatureDesign`). :func:`run_case` adapts its ``run_case`` to the
benchmark jobs' interface (:func:`parksteer.experiments.benchmark.run_batch`): each case's truth and its scored row go
to their own files, the row's wall times under ``timings_s`` (a machine time, kept out of the figure, its table
and the paper). :func:`aggregate` scores the rows again from their numbers alone:

- the class is right when the class the signature named is the truth form's class;
- a suggestion is *within* when the weighted error with the suggested effect, fitted with the calibrated
  parameters, is at most :data:`~parksteer.experiments.outoflibrary.AFTER_LIMIT` noise floors;
- a null fails when the diagnosis would write a suggestion for it (an ``unexplained`` verdict with a class).

Every number written is the diagnosis's (portable arithmetic) or a count; the likelihood-ratio p-values of the
signature's axes are not written (the diagnosis rounds them to three digits).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from ..experiments.outoflibrary import AFTER_LIMIT, CLASS_TARGET, SUGGESTION_TARGET, SignatureDesign
from ..diagnose.signature import CLASSES
from ..errors import UsageError
NULL_COLOUR = "#777777"
TIME_KEYS = ("diagnosis_s", "signature_s", "suggestion_s")
ROW_KEYS = ("name", "form", "class", "variation", "steps", "said_class", "class_right", "class_in_group",
            "indistinguishable", "verdict", "named", "calibrated_over_floor", "after_over_floor",
            "suggestion_written", "sentence")


def design_dict(design: SignatureDesign) -> dict:
    return {"steps": list(design.steps), "nulls": design.nulls, "variations": design.variations,
            "seed": design.seed, "first_variation": design.first_variation, "combined_forms": list(design.combined)}


def method_dict() -> dict:
    """The signature's bases and thresholds as the benchmark's diagnoses use them (the paper quotes them)."""
    from ..experiments.benchmark import BENCHMARK_SETTINGS

    sig = BENCHMARK_SETTINGS.signature
    return {"position_knots": list(sig.position_knots), "speed_knots": sig.speed_knots,
            "column_orders": [list(o) for o in sig.column_orders], "mesh_order": sig.mesh_order,
            "combined_orders": [list(o) for o in sig.combined_orders],
            "significance": sig.significance, "bic_missing_threshold": BENCHMARK_SETTINGS.bic_missing_threshold,
            "bic_indistinguishable": BENCHMARK_SETTINGS.bic_indistinguishable, "after_limit": AFTER_LIMIT}


def forms_dict(names=None) -> dict:
    """Each truth form (of `names`, if given: the forms the rows hold): its class, what it is, the mechanism it
    stands for."""
    from ..synthetic.outoflibrary import ALL_FORMS

    return {f.effect.name: {"class": f.signature_class, "description": f.effect.description, "why": f.effect.why}
            for f in ALL_FORMS if names is None or f.effect.name in names}


def run_case(parameters_path: str | Path, design: SignatureDesign, name: str, folder: str | Path,
             truth_path: str | Path, row_path: str | Path) -> dict:
    """Make, write, diagnose and score case `name` (:func:`parksteer.experiments.outoflibrary.run_case`); write its
    truth and its row (the wall times under ``timings_s``)."""
    from ..experiments.outoflibrary import run_case as run_one
    from ..parameters import load_parameters
    from ..tables import write_json

    cases = {c.name: c for c in design.cases()}
    if name not in cases:
        raise UsageError(f"signature benchmark: no case {name!r} (the cases: {', '.join(cases)})")
    start = time.perf_counter()
    row = run_one(load_parameters(parameters_path), cases[name], design, folder)
    truth = {k: row[k] for k in ("name", "form", "class", "variation", "steps", "strength") if k in row}
    out = {k: row[k] for k in ROW_KEYS}
    out["timings_s"] = {**{k: row[k] for k in TIME_KEYS}, "case_s": time.perf_counter() - start}
    write_json(truth_path, truth)
    write_json(row_path, out)
    return out


def aggregate(rows: list[dict]) -> dict:
    """The scores of the signature benchmark's `rows` (module docstring): per truth class, the records, the class
    right (or in the group the signature reported), the suggestions within AFTER_LIMIT floors; the nulls and any
    suggestion on them; the class confusion; the three targets."""
    for r in rows:
        missing = [k for k in ("name", "form", "class", "said_class", "calibrated_over_floor", "after_over_floor",
                               "suggestion_written") if k not in r]
        if missing:
            raise UsageError(f"signature benchmark: row {r.get('name', '?')!r} has no {', '.join(missing)}")
    hidden = [r for r in rows if r["form"] is not None]
    nulls = [r for r in rows if r["form"] is None]

    def within(r: dict) -> bool:
        return r["after_over_floor"] is not None and r["after_over_floor"] <= AFTER_LIMIT

    table = {}
    for cls in [c for c in CLASSES if any(r["class"] == c for r in hidden)]:
        rs = [r for r in hidden if r["class"] == cls]
        table[cls] = {"records": len(rs),
                      "class_right": sum(r["said_class"] == cls for r in rs),
                      "class_in_group": sum(r["said_class"] == cls or cls in r.get("indistinguishable", ())
                                            for r in rs),
                      "within": sum(within(r) for r in rs),
                      "forms": sorted({r["form"] for r in rs})}
    said_labels = [*CLASSES, "none"]
    confusion = {cls: {s: sum((r["said_class"] or "none") == s for r in hidden if r["class"] == cls)
                       for s in said_labels} for cls in table}
    confusion["null"] = {s: sum((r["said_class"] or "none") == s for r in nulls) for s in said_labels}
    right = sum(t["class_right"] for t in table.values())
    inside = sum(t["within"] for t in table.values())
    on_nulls = [r["name"] for r in nulls if r["suggestion_written"]]
    after = [r["after_over_floor"] for r in hidden if r["after_over_floor"] is not None]
    before = [r["calibrated_over_floor"] for r in hidden]
    return {
        "records": len(rows), "out_of_library": len(hidden), "nulls": len(nulls),
        "classes": list(table), "table": table, "confusion": confusion,
        "all": {"records": len(hidden), "class_right": right, "class_in_group":
                sum(t["class_in_group"] for t in table.values()), "within": inside},
        "targets": {
            "class": {"target": CLASS_TARGET, "count": [right, len(hidden)],
                      "value": right / len(hidden) if hidden else None,
                      "met": bool(hidden) and right / len(hidden) >= CLASS_TARGET},
            "suggestion": {"target": SUGGESTION_TARGET, "count": [inside, len(hidden)],
                           "value": inside / len(hidden) if hidden else None,
                           "met": bool(hidden) and inside / len(hidden) >= SUGGESTION_TARGET},
            "nulls": {"count": [len(nulls) - len(on_nulls), len(nulls)], "suggested_on": on_nulls,
                      "met": not on_nulls},
        },
        "after_limit": AFTER_LIMIT,
        "before_over_floor": {"min": min(before), "max": max(before)} if before else None,
        "after_over_floor": {"min": min(after), "max": max(after)} if after else None,
        "null_over_floor": [r["calibrated_over_floor"] for r in nulls],
        "verdicts": {v: sum(r["verdict"] == v for r in hidden) for v in sorted({r["verdict"] for r in hidden})}
        if all("verdict" in r for r in hidden) else {},
        "named_missing": [{"name": r["name"], "class": r["class"], "named": r.get("named")}
                          for r in hidden if r.get("verdict") == "missing"],
        "misses": [{"name": r["name"], "class": r["class"], "said": r["said_class"] or "none",
                    "in_group": r["class"] in r.get("indistinguishable", ()),
                    "after_over_floor": r["after_over_floor"]}
                   for r in hidden if r["said_class"] != r["class"] or not within(r)],
    }


def signature_figure(rows: list[dict], summary: dict, path: str | Path) -> None:
    """Left: each record's weighted error in noise floors, calibrated base model (open circle) to with the
    suggested effect (filled), coloured by the truth form's class, against the AFTER_LIMIT line; nulls in grey,
    a cross where a suggestion would be written. Right: the class confusion, truth class against the class
    named."""
    from ..plotting import COLOURS, new_figure, save_svg  # here: the batch jobs import this module

    class_colours = {cls: COLOURS[k] for k, cls in enumerate(CLASSES)}
    order = sorted(range(len(rows)), key=lambda i: (rows[i]["form"] is None,
                                                    CLASSES.index(rows[i]["class"]) if rows[i]["class"] else 0,
                                                    rows[i]["name"]))
    fig, axes = new_figure(7.6, 0.3 * len(rows) + 1.9, ncols=2, gridspec_kw={"width_ratios": [1.7, 1.0]})
    ax = axes[0]
    for y, i in enumerate(order):
        r = rows[i]
        colour = class_colours[r["class"]] if r["class"] else NULL_COLOUR
        before, after = r["calibrated_over_floor"], r["after_over_floor"]
        if after is not None:
            ax.annotate("", xy=(after, y), xytext=(before, y),
                        arrowprops={"arrowstyle": "->", "color": colour, "linewidth": 1.2})
            ax.plot([after], [y], "o", color=colour, markersize=5)
        ax.plot([before], [y], "o", markerfacecolor="white", markeredgecolor=colour, markersize=5)
        if r["form"] is None:
            if r["suggestion_written"]:
                ax.plot([before], [y], "x", color="#e41a1c", markersize=8)
            note = "suggestion written" if r["suggestion_written"] else "no suggestion"
            if r["said_class"]:
                note += f" (signature: {r['said_class']})"
            ax.text(before * 1.08, y, note, va="center", fontsize=6, color=NULL_COLOUR)
        if r["form"] is not None and r["said_class"] != r["class"]:
            ax.text(before * 1.08, y, f"named {r['said_class'] or 'none'}", va="center", fontsize=6)
    ax.axvline(AFTER_LIMIT, color="black", linestyle="--", linewidth=1.0)
    ax.text(AFTER_LIMIT, 1.005, f"{AFTER_LIMIT:g} floors", fontsize=6.5, ha="center", va="bottom",
            transform=ax.get_xaxis_transform())
    ax.set_xscale("log")
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

    values = [v for r in rows for v in (r["calibrated_over_floor"], r["after_over_floor"]) if v is not None]
    ticks = [t for t in (0.8, 1.0, AFTER_LIMIT, 2.0, 3.0, 5.0, 10.0, 20.0, 50.0, 100.0)
             if min(values + [1.0]) / 1.3 <= t <= max(values) * 1.3]
    ax.xaxis.set_major_locator(FixedLocator(ticks))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xticks(ticks, [f"{t:g}" for t in ticks], fontsize=7)
    ax.set_ylim(len(rows) - 0.5, -0.5)
    labels = [rows[i]["name"].removeprefix("oolib_").rsplit("_", 1)[0].replace("_", " ")
              if rows[i]["form"] is not None else rows[i]["name"].replace("_", " ") for i in order]
    ax.set_yticks(np.arange(len(rows)), labels, fontsize=7)
    ax.set_xlabel("weighted RMS error, noise floors\n(open: calibrated model; filled: with the suggested effect)",
                  fontsize=8)
    ax.grid(True, axis="x", which="both", alpha=0.3)
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], marker="o", linestyle="", color=class_colours[c], label=c) for c in summary["table"]]
    handles.append(Line2D([], [], marker="o", linestyle="", markerfacecolor="white", markeredgecolor=NULL_COLOUR,
                          label="nothing hidden"))
    if summary["targets"]["nulls"]["suggested_on"]:
        handles.append(Line2D([], [], marker="x", linestyle="", color="#e41a1c", label="suggestion on a null"))
    ax.legend(handles=handles, fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3,
              frameon=False)
    ax = axes[1]
    truth_labels = list(summary["confusion"])
    said_labels = [s for s in [*CLASSES, "none"]
                   if s in CLASSES or any(summary["confusion"][t][s] for t in truth_labels)]
    counts = np.array([[summary["confusion"][t][s] for s in said_labels] for t in truth_labels], dtype=float)
    ax.imshow(counts, cmap="Blues", aspect="auto", vmin=0.0, vmax=max(float(counts.max()), 1.0))
    for i in range(counts.shape[0]):
        for j in range(counts.shape[1]):
            if counts[i, j]:
                ax.text(j, i, f"{counts[i, j]:g}", ha="center", va="center", fontsize=7,
                        color="white" if counts[i, j] > counts.max() / 2 else "black")
    ax.set_xticks(np.arange(len(said_labels)), said_labels, rotation=50, ha="right", fontsize=7)
    ax.set_yticks(np.arange(len(truth_labels)), ["nothing" if t == "null" else t for t in truth_labels], fontsize=7)
    ax.set_xlabel("class the signature named", fontsize=8)
    ax.set_ylabel("class of the hidden form", fontsize=8)
    ax.grid(False)
    fig.tight_layout()
    save_svg(fig, path)


def csv_columns(rows: list[dict]) -> dict[str, list]:
    """One row per record: truth form and class, the class named, the verdict, before and after (empty: no
    suggestion fitted), within the limit, and whether the diagnosis would write the suggestion."""
    yes = lambda b: "yes" if b else "no"  # noqa: E731
    return {
        "record": [r["name"] for r in rows],
        "truth_form": [r["form"] or "nothing" for r in rows],
        "truth_class": [r["class"] or "" for r in rows],
        "variation": [r["variation"] for r in rows],
        "steps": [r["steps"] for r in rows],
        "class_named": [r["said_class"] or "none" for r in rows],
        "class_right": ["" if r["form"] is None else yes(r["said_class"] == r["class"]) for r in rows],
        "indistinguishable": [" ".join(r.get("indistinguishable", ())) for r in rows],
        "verdict": [r["verdict"] + (f" {r['named']}" if r.get("named") else "") for r in rows],
        "before_over_floor": [r["calibrated_over_floor"] for r in rows],
        "after_over_floor": ["" if r["after_over_floor"] is None else r["after_over_floor"] for r in rows],
        "within": ["" if r["form"] is None else yes(r["after_over_floor"] is not None
                                                     and r["after_over_floor"] <= AFTER_LIMIT) for r in rows],
        "suggestion_written": [yes(r["suggestion_written"]) for r in rows],
    }


def make_signature_figure(row_paths, svg: str | Path, csv: str | Path, json_path: str | Path,
                          design: SignatureDesign | None = None) -> dict:
    """figures/diag_signature.svg and .csv, results/diag_signature.json from the rows the jobs wrote (in any
    order; sorted by record name)."""
    from ..reporting.report import without_machine_times
    from ..tables import write_csv, write_json

    rows = []
    for path in sorted(map(str, row_paths), key=lambda p: Path(p).name):
        try:
            rows.append(json.loads(Path(path).read_text(encoding="utf-8")))
        except (OSError, ValueError) as error:
            raise UsageError(f"{path}: not a signature benchmark row ({error})") from None
    if not rows:
        raise UsageError("signature benchmark: no rows")
    summary = aggregate(rows)
    signature_figure(rows, summary, svg)
    columns = csv_columns(rows)
    write_csv(csv, {k: v for k, v in columns.items()},
              {"figure": "diag_signature: one row per record of the signature benchmark",
               "steps": "truth form's size, converter steps of clean torque change RMS",
               "before_over_floor": "calibrated base model's weighted RMS error, noise floors",
               "after_over_floor": "with the suggested effect fitted with the calibrated parameters, noise floors",
               "within": f"after_over_floor at most {AFTER_LIMIT:g}",
               "suggestion_written": "the diagnosis would write the effect (verdict unexplained and a class)"})
    times = [r.get("timings_s", {}) for r in rows]
    summary["settings"] = design_dict(design) if design is not None else None
    summary["method"] = method_dict()
    summary["forms"] = forms_dict({r["form"] for r in rows if r["form"] is not None})
    summary["sentences"] = {r["name"]: r["sentence"] for r in rows}
    summary["timings_s"] = {k: float(np.median([t[k] for t in times])) for k in (*TIME_KEYS, "case_s")
                            if times and all(k in t for t in times)}
    write_json(json_path, without_machine_times(summary))  # the times: benchmarks/bench_signature.py
    return summary
