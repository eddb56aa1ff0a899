"""A design sweep's table, key numbers and torque maps (figures/sweep_<name>.*, results/sweep_<name>.json).

Top row: the map quantity over the map's x and y axes, one panel per value of the panel
axis, the other axes held; the assistance threshold drawn as a contour and the test car's
design point marked. Bottom row: the plateau torque against each swept key with every
other key at the design point, wheels free to roll (solid) and braked (dashed: simulated
with the sweep's braked effect, or estimated by rig theory, as the sweep declares).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..parameters import Parameters, load_parameters
from ..plotting import COLOURS, new_figure, save_svg
from ..sweep.aggregate import MapSlice, axis_values, design_values, map_held, matching, summarise
from ..sweep.gathering import gather_points
from ..sweep.records import point_quantity
from ..sweep.totals import Totals
from ..sweep.declaration import Sweep, load_sweep
from ..sweep.keys import parameter_bounds
from ..tables import write_json

# How each SI unit is shown on an axis: (factor, label).
DISPLAY_UNITS = {"Pa": (1.0e-5, "bar"), "N": (1.0e-3, "kN"), "m": (1.0e3, "mm"), "rad": (180.0 / math.pi, "deg"),
                 "1": (1.0, "")}
LABELS = {"design.front_axle_load": "front axle load", "design.extra_offset": "spacer offset",
          "design.steering_ratio": "overall steering ratio", "design.castor_angle": "castor angle",
          "tyre.tyre_pressure": "tyre pressure", "geometry.kingpin_inclination": "king-pin inclination"}
QUANTITY_LABELS = {"peak_torque_Nm": "peak handwheel torque", "plateau_torque_Nm": "plateau torque",
                   "lock_torque_Nm": "torque at lock", "reversal_drop_Nm": "drop at reversal",
                   "plateau_torque_braked_Nm": "plateau torque, wheels braked",
                   "peak_torque_braked_Nm": "peak torque, wheels braked"}
CONTOUR_STEP_NM = 2.0
MAX_MAP_PANELS = 4
MAP_MARGIN = 0.06  # of the plotted range, around the torque map's points and the test car


def display(key: str) -> tuple[float, str]:
    """(factor, axis label) to show values of `key`."""
    unit = parameter_bounds(key)[3]
    factor, shown = DISPLAY_UNITS.get(unit, (1.0, unit))
    label = LABELS.get(key, key.partition(".")[2].replace("_", " "))
    return factor, f"{label} ({shown})" if shown else label


def _format_value(key: str, value: float) -> str:
    factor, label = display(key)
    unit = label[label.rfind("(") + 1: -1] if label.endswith(")") else ""
    return f"{value * factor:.4g}{' ' + unit if unit else ''}"


def _draw_map(ax, sweep: Sweep, map_slice: MapSlice, panel, levels, threshold, mark_design, design):
    spec = sweep.map
    fx, xlabel = display(spec.x)
    fy, ylabel = display(spec.y)
    sel = map_slice.panel == panel if spec.panels else np.ones(len(map_slice.x), dtype=bool)
    xs = map_slice.x[sel] * fx
    ys = map_slice.y[sel] * fy
    qs = map_slice.quantities[spec.quantity][sel]
    ux, uy = np.unique(xs), np.unique(ys)
    filled = None
    if len(ux) >= 2 and len(uy) >= 2 and len(qs) == len(ux) * len(uy):
        grid = np.full((len(uy), len(ux)), np.nan)
        for x, y, q in zip(xs, ys, qs):
            grid[np.searchsorted(uy, y), np.searchsorted(ux, x)] = q
        filled = ax.contourf(ux, uy, grid, levels=levels, cmap="viridis", extend="both")
        if threshold is not None and np.nanmin(grid) < threshold < np.nanmax(grid):
            line = ax.contour(ux, uy, grid, levels=[threshold], colors="white", linewidths=1.8, linestyles="--")
            ax.clabel(line, fmt=lambda v: f"{v:.1f} N m", fontsize=7)
    elif len(qs) >= 3:
        filled = ax.tricontourf(xs, ys, qs, levels=levels, cmap="viridis", extend="both")
    ax.scatter(xs, ys, s=6, color="black", zorder=3, label="sweep points", clip_on=False)
    shown_x, shown_y = list(xs), list(ys)
    if mark_design:
        star = design[spec.x]["base"] * fx, design[spec.y]["base"] * fy
        ax.plot(*star, marker="*", markersize=13, color=COLOURS[4], markeredgecolor="black", linestyle="none",
                zorder=5, clip_on=False, label="test car")
        shown_x.append(star[0])
        shown_y.append(star[1])
        ax.legend(loc="lower right", fontsize=7, handlelength=1.0, framealpha=0.8, frameon=True)
    # the grid's edge points and the test car (often on an edge) drawn whole, not cut by the axes frame
    for values, set_limits in ((shown_x, ax.set_xlim), (shown_y, ax.set_ylim)):
        low, high = min(values), max(values)
        pad = MAP_MARGIN * ((high - low) or abs(high) or 1.0)
        set_limits(low - pad, high + pad)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(False)
    return filled


def _draw_sensitivity(ax, sweep: Sweep, records: list[dict], key: str, design: dict):
    factor, label = display(key)
    held = {k: d["nearest"] for k, d in design.items() if k != key}
    line = sorted(matching(records, held), key=lambda r: r["values"][key])
    xs = np.array([r["values"][key] for r in line]) * factor
    ax.plot(xs, [point_quantity(r, "plateau_torque_Nm") for r in line], marker="o", markersize=3,
            color=COLOURS[0], label="free to roll")
    braked = [point_quantity(r, "plateau_torque_braked_Nm") for r in line]
    if not all(math.isnan(b) for b in braked):
        ax.plot(xs, braked, marker="s", markersize=3, linestyle="--", color=COLOURS[1], label="braked")
    ax.axvline(design[key]["base"] * factor, color="grey", linewidth=0.8, linestyle=":")
    ax.set_xlabel(label)


def plot_sweep(sweep: Sweep, params: Parameters, records: list[dict], out_svg: str | Path,
               totals: Totals | None = None, map_slice: MapSlice | None = None) -> None:
    """Draw the maps and sensitivity lines from the sweep's records in the sweep's order (all, or those
    gather_points keeps with its totals and the map's slice)."""
    design = design_values(sweep, params)
    keys = sweep.keys
    spec = sweep.map
    panels = (axis_values(sweep, spec.panels) if spec and spec.panels else [None])[:MAX_MAP_PANELS]
    n_top = len(panels) if spec else 0
    n_bottom = len(keys)
    ncols = max(n_top, n_bottom, 1)
    fig, ax0 = new_figure(max(2.2 * ncols, 6.0), 6.4 if n_top else 3.2)
    ax0.remove()
    grid = fig.add_gridspec(2 if n_top else 1, n_top * n_bottom if n_top else n_bottom, hspace=0.45, wspace=0.6)
    threshold = sweep.assistance.torque_Nm if sweep.assistance else None
    if n_top:
        if totals is None:
            totals = Totals.of(records, threshold, spec.quantity)
        lowest, highest = totals.map_range[spec.quantity]
        low = CONTOUR_STEP_NM * math.floor(lowest / CONTOUR_STEP_NM)
        high = CONTOUR_STEP_NM * math.ceil(highest / CONTOUR_STEP_NM)
        levels = np.arange(low, high + CONTOUR_STEP_NM / 2, CONTOUR_STEP_NM)
        held = map_held(sweep, design)
        if map_slice is None:
            map_slice = MapSlice.of(sweep, records, held, [spec.quantity])
        design_panel = design[spec.panels]["nearest"] if spec.panels else None
        filled = None
        top_axes = []
        for i, panel in enumerate(panels):
            ax = fig.add_subplot(grid[0, i * n_bottom:(i + 1) * n_bottom])
            top_axes.append(ax)
            on_design = all(design[k]["nearest"] == v for k, v in held.items())
            drawn = _draw_map(ax, sweep, map_slice, panel, levels, threshold, on_design and panel == design_panel,
                              design)
            filled = drawn or filled
            if spec.panels:
                ax.set_title(f"{display(spec.panels)[1].split(' (')[0]} {_format_value(spec.panels, panel)}",
                             fontsize=9)
        if filled is not None:
            bar = fig.colorbar(filled, ax=top_axes, shrink=0.9)
            bar.set_label(f"{QUANTITY_LABELS[spec.quantity]} (N m)")
        for ax in top_axes[1:]:
            ax.set_ylabel("")
            ax.tick_params(labelleft=False)
        held_text = ", ".join(f"{display(k)[1].split(' (')[0]} {_format_value(k, v)}" for k, v in held.items())
        fig.suptitle(f"{QUANTITY_LABELS[spec.quantity]}" + (f"; held: {held_text}" if held_text else ""),
                     fontsize=9)
    row = 1 if n_top else 0
    span = n_top if n_top else 1
    for j, key in enumerate(keys):
        ax = fig.add_subplot(grid[row, j * span:(j + 1) * span])
        _draw_sensitivity(ax, sweep, records, key, design)
        if j == 0:
            ax.set_ylabel("plateau torque (N m)")
            ax.legend(fontsize=7)
            ax.set_title("others at the test car's values", fontsize=8, loc="left")
    save_svg(fig, out_svg)


def make_sweep_figure(sweep_path: str | Path, parameters: Parameters | str | Path, point_paths, out_svg: str | Path,
                      out_csv: str | Path, out_json: str | Path, full: bool = False) -> dict:
    """Write the sweep's table (CSV), its key numbers (JSON) and its torque maps (SVG); return the numbers but the
    list of the points above the assistance threshold (in the JSON file only: it can hold most of the points).

    The sweep is read without its expansion and the point files one at a time (gather_points); memory per point:
    an 8-byte offset, and a few numbers per point of the map's slice."""
    params = parameters if isinstance(parameters, Parameters) else load_parameters(parameters)
    sweep = load_sweep(sweep_path, params, full=full, expand=False)
    threshold = sweep.assistance.torque_Nm if sweep.assistance else None

    def header(totals: Totals) -> dict[str, str]:
        lines = {
            "sweep": f"{sweep.name} ({totals.n_points} points{', full' if sweep.full else ''}) from {sweep.path}",
            "description": sweep.description,
            "model": f"case {sweep.base_case}, effects {', '.join(totals.effects)}, surface {sweep.surface}",
            "merits": "see parksteer.sweep.merit: plateau = mean over the sliding part of the right-going stroke, "
                      "whole Hooke-joint ripple periods; shares are of the plateau",
            "braked": totals.braked_method,
        }
        if threshold is not None:
            lines["assistance threshold"] = (f"{threshold:g} N m = {sweep.assistance.rim_force_N:g} N x "
                                             f"{sweep.assistance.rim_radius_m:g} m; needs_assistance = peak above it")
        return lines

    # the table is written as the point files are read; only what the summary and the maps select is kept, and
    # the list of the points above the threshold is written from a scratch file as the summary is encoded
    with gather_points(point_paths, sweep, params, out_csv, header, threshold) as gathered:
        summary = summarise(sweep, params, gathered.records, gathered.totals, gathered.map_slice)
        write_json(out_json, summary)
    if "assistance" in summary:
        del summary["assistance"]["points_above"]
    plot_sweep(sweep, params, gathered.records, out_svg, gathered.totals, gathered.map_slice)
    return summary
