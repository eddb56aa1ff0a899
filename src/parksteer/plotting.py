"""Matplotlib set-up for byte-reproducible SVG figures.

Same inputs give the same bytes: no date in the metadata, a fixed SVG hash salt, text
drawn as paths with the DejaVu font that ships inside matplotlib (so no system font is
consulted), and the Agg backend.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .tables import atomic_path  # noqa: E402

STYLE = {
    "svg.hashsalt": "parksteer",
    "svg.fonttype": "path",
    "font.family": "DejaVu Sans",
    "font.size": 9.0,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.frameon": False,
    "figure.dpi": 100,
    "lines.linewidth": 1.3,
    "path.simplify": False,
}

# One colour per series, in a fixed order (colour-blind safe, Okabe & Ito).
COLOURS = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000"]


def new_figure(width_in: float = 6.0, height_in: float = 4.0, **subplots_kw):
    """A figure and axes drawn with the project style."""
    plt.rcParams.update(matplotlib.rcParamsDefault)
    plt.rcParams.update(STYLE)
    plt.rcParams["axes.prop_cycle"] = matplotlib.cycler(color=COLOURS)
    return plt.subplots(figsize=(width_in, height_in), **subplots_kw)


def save_svg(fig, path: str | Path) -> None:
    """Save `fig` as a deterministic SVG (atomically) and close it."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="svg", metadata={"Date": None, "Creator": "parksteer"}, bbox_inches=None)
    plt.close(fig)
