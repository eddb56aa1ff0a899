"""The diagnosis against its peers (figures/diag_peers.svg, .csv, results/diag_peers.json).

The numbers are :func:`parksteer.experiments.peers.compare`'s: each method on the variation and out-of-class
benchmarks' records, the peers at the setting tuned on records of another seed. Machine times stay out of the
SVG, the CSV and the key numbers (JSON), which are the same on any machine; the paper quotes model replays, and
benchmarks/bench_peers.py prints the times.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import COLOURS, new_figure, save_svg

RATES = (("named_rate", "hidden effects named"), ("null_adequate_rate", "nulls called adequate"),
         ("confident_wrong_rate", "out of class: confident wrong"))


def _rates(row: dict) -> dict[str, float]:
    rivals = row["outclass_rivals"]
    return {"named_rate": row["named_rate"] or 0.0, "null_adequate_rate": row["null_adequate_rate"] or 0.0,
            "confident_wrong_rate": row["confident_wrong"] / rivals if rivals else 0.0}


def peers_figure(comparison: dict, svg: str | Path) -> None:
    """Grouped bars: per measure, one bar per method (the peers at their tuned setting), each labelled k/n."""
    rows = comparison["methods"]
    fig, ax = new_figure(6.5, 4.4)
    width = 0.8 / len(rows)
    x = np.arange(len(RATES))
    for k, row in enumerate(rows):
        rates = _rates(row)
        counts = [row["named"], row["null_adequate"], [row["confident_wrong"], row["outclass_rivals"]]]
        label = row["label"] + (f" ({row['setting']})" if row["setting"] else "")
        bars = ax.bar(x + (k - (len(rows) - 1) / 2) * width, [rates[key] for key, _ in RATES], width,
                      color=COLOURS[k % len(COLOURS)], label=label)
        for bar, (done, total) in zip(bars, counts):
            ax.annotate(f"{done}/{total}", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                        ha="center", va="bottom", fontsize=7)
    ax.set_xticks(x, [label for _, label in RATES])
    ax.set_ylim(0.0, 1.15)
    ax.set_ylabel("fraction of records")
    ax.set_title(f"{comparison['records']['evaluation']} benchmark records; peers tuned on "
                 f"{comparison['records']['tuning']} of another seed", fontsize=9)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=1, frameon=False)
    fig.subplots_adjust(bottom=0.3)
    save_svg(fig, svg)


def make_peers_figure(peer_paths, svg: str | Path, csv: str | Path, json_path: str | Path) -> dict:
    """figures/diag_peers.svg and .csv (one row per method) and results/diag_peers.json (the comparison)."""
    from ..experiments.peer_scoring import compare, read_cases
    from ..reporting.report import without_machine_times
    from ..tables import write_csv, write_json

    comparison = compare(read_cases(peer_paths))
    peers_figure(comparison, svg)
    rows = comparison["methods"]
    columns = {
        "method": [r["label"] for r in rows],
        "setting": [r["setting"] or "" for r in rows],
        "named": [r["named"][0] for r in rows], "hidden": [r["named"][1] for r in rows],
        "null_adequate": [r["null_adequate"][0] for r in rows], "nulls": [r["null_adequate"][1] for r in rows],
        "outclass_closest_or_related": [r["outclass"]["closest or related"] for r in rows],
        "outclass_unrelated": [r["outclass"]["unrelated"] for r in rows],
        "outclass_unexplained": [r["outclass"]["unexplained"] for r in rows],
        "outclass_adequate": [r["outclass"]["adequate"] for r in rows],
        "confident_wrong": [r["confident_wrong"] for r in rows],
    }
    write_csv(csv, columns, {"figure": "diag_peers: the diagnosis and two peers on the same benchmark records",
                             "setting": "the peer's setting tuned on the tuning split (another seed)",
                             "named": "hidden library effects named (the diagnosis: first or in its reported group)",
                             "null_adequate": "records with nothing hidden called adequate",
                             "confident_wrong": "out-of-class rivals answered with an unrelated candidate "
                                                "(the diagnosis: with a BIC margin beyond its band)"})
    write_json(json_path, without_machine_times(comparison))  # the times: benchmarks/bench_peers.py
    return comparison
