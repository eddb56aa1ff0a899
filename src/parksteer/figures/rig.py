"""Section 2, the static tyre rig: Table 1, Fig. 3 (limiting torque against pressure) and
Fig. 4 (limiting torque against pin offset).

The measured curves of Figs 3 and 4 are lost; these figures draw the theory the paper
fits to them (equations (1) and (2)) for the five chosen rig loads, and, for Fig. 4, the
two limits of a patch turning about an offset pin (see :mod:`parksteer.rig`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from .. import rig
from ..parameters import Parameters, load_parameters
from ..plotting import COLOURS, new_figure, save_svg
from ..tables import write_csv, write_json

PA_PER_BAR = 1.0e5
FIG3_POINTS = 201
FIG4_POINTS = 121  # 1 mm steps over the 0-120 mm offset range

# Fig. 4 quotes the offset at which locking the wheel has raised the torque by this fraction.
BRAKED_RISE_QUOTED = 0.10
BRAKED_RISE_KEY = f"offset_for_{round(100 * BRAKED_RISE_QUOTED)}_percent_braked_rise_m"

SCALING_STATEMENT = (
    "The rig's pressure correction (p0/p)^(n-0.5), the ratio of equation (2) to equation (1) at that "
    "pressure, multiplies the spin part only: the free-rolling curve and the braked curve's equation (1) "
    "part; the braked curve's drag part (the uniform-pressure integral minus equation (1), the patch dragged "
    "about the pin) is not scaled, since a pressure distribution cannot raise the net sliding force above "
    "mu W, so the braked torque tends to mu W e; at zero offset both equal equation (2)."
)


def _as_parameters(params: Parameters | str | Path) -> Parameters:
    return params if isinstance(params, Parameters) else load_parameters(params)


def _load_label(load_N: float) -> str:
    return f"W = {load_N / 1000.0:.1f} kN"


def _headline_load_N(params: Parameters) -> float:
    """The rig load closest to the friction-test load, the one the paper's numbers are quoted for."""
    loads = np.array(params["rig.loads"])
    return float(loads[np.argmin(np.abs(loads - params["rig.friction_test_load"]))])


def _style_handles(ax, entries):
    """Black legend handles that explain line styles, independent of the colour per load."""
    return [ax.plot([], [], color="black", label=label, **style)[0] for label, style in entries]


# ---------------------------------------------------------------- Table 1


def make_table1(
    params: Parameters | str | Path,
    printed_csv: str | Path,
    out_csv: str | Path,
    out_json: str | Path,
) -> dict:
    """Write figures/table1.csv (printed and recomputed columns, disagreement flags) and results/table1.json."""
    params = _as_parameters(params)
    rows, printed_header = rig.read_printed_table1(printed_csv)
    columns = rig.table1(params, rows)
    header = {
        "table": "Table 1, test wheel spin and steer angles for different offsets",
        "printed source": printed_header.get("source", "Table 1 of the paper"),
        "rolling radius": f"{params['rig.rolling_radius']} m ({params.source('rig.rolling_radius')})",
        "measured ratio": "percentage_difference uses the printed spin/steer ratio; "
        "percentage_difference_from_quotient uses spin_deg/steer_deg",
        "flags": "*_disagrees = 1 where printed and recomputed differ by more than half a unit in the "
        "printed last digit; spin_steer_ratio_consistent_with_rounding = 1 where the printed ratio, "
        "within its own rounding, meets the range spin_steer_quotient_low to _high that the angles allow "
        "within theirs",
    }
    write_csv(out_csv, columns, header)

    checks = {
        "spin_steer_ratio": ("printed_spin_steer_ratio", "spin_steer_quotient"),
        "pure_rolling_ratio": ("printed_pure_rolling_ratio", "pure_rolling_ratio"),
        "percentage_difference": ("printed_percentage_difference", "percentage_difference"),
    }
    disagreements = []
    for i, offset_mm in enumerate(columns["offset_mm"]):
        for quantity, (printed_name, recomputed_name) in checks.items():
            if columns[f"{quantity}_disagrees"][i]:
                entry = {
                    "offset_mm": offset_mm,
                    "quantity": quantity,
                    "printed": columns[printed_name][i],
                    "recomputed": columns[recomputed_name][i],
                }
                if quantity == "spin_steer_ratio":
                    entry["recomputed_from"] = "spin_deg / steer_deg as printed"
                    entry["explained_by_angle_rounding"] = bool(
                        columns["spin_steer_ratio_consistent_with_rounding"][i]
                    )
                    entry["quotient_range_from_angle_rounding"] = [
                        columns["spin_steer_quotient_low"][i],
                        columns["spin_steer_quotient_high"][i],
                    ]
                disagreements.append(entry)

    summary = {
        "rolling_radius_m": params["rig.rolling_radius"],
        "measured_ratio_used": "printed spin/steer ratio (reproduces the printed percentage differences)",
        "rows": [
            {
                "offset_mm": columns["offset_mm"][i],
                "spin_steer_quotient": columns["spin_steer_quotient"][i],
                "printed_spin_steer_ratio": columns["printed_spin_steer_ratio"][i],
                "pure_rolling_ratio": columns["pure_rolling_ratio"][i],
                "percentage_difference": columns["percentage_difference"][i],
                "percentage_difference_from_quotient": columns["percentage_difference_from_quotient"][i],
            }
            for i in range(len(columns["offset_mm"]))
        ],
        "disagreements": disagreements,
    }
    write_json(out_json, summary)
    return summary


# ---------------------------------------------------------------- Fig. 3


def fig3_columns(params: Parameters, n_points: int = FIG3_POINTS) -> dict[str, np.ndarray]:
    """Long-format data of Fig. 3: one row per (load, pressure) with equations (1) and (2)."""
    mu = params["tyre.friction_coefficient"]
    p0, n = params["tyre.reference_pressure"], params["tyre.pressure_index"]
    low_Pa, high_Pa = params["rig.fig3_pressure_range"]
    pressure_Pa = np.linspace(low_Pa, high_Pa, n_points)
    loads = np.array(params["rig.loads"])
    load_N = np.repeat(loads, n_points)
    pressure_Pa = np.tile(pressure_Pa, len(loads))
    return {
        "load_N": load_N,
        "pressure_Pa": pressure_Pa,
        "gough_torque_Nm": rig.gough_torque_Nm(load_N, pressure_Pa, mu),
        "empirical_torque_Nm": rig.empirical_torque_Nm(load_N, pressure_Pa, mu, p0, n),
    }


def fig3_summary(params: Parameters) -> dict:
    """The numbers the paper quotes about Fig. 3."""
    mu = params["tyre.friction_coefficient"]
    p0, n = params["tyre.reference_pressure"], params["tyre.pressure_index"]
    low_Pa, high_Pa = params["rig.fig3_pressure_range"]
    quoted_pressures = sorted({low_Pa, *params["rig.fig4_pressures"], p0, high_Pa})
    loads = [float(w) for w in params["rig.loads"]]
    return {
        "loads_N": loads,
        "loads_source": params.source("rig.loads"),
        "friction_coefficient": mu,
        "friction_coefficient_from_test": params["rig.friction_test_force"] / params["rig.friction_test_load"],
        "reference_pressure_Pa": p0,
        "pressure_index": n,
        "pressure_range_Pa": [low_Pa, high_Pa],
        "pressure_range_source": params.source("rig.fig3_pressure_range"),
        "equation2_over_equation1": [
            {"pressure_Pa": p, "ratio": float(rig.pressure_correction(p, p0, n))} for p in quoted_pressures
        ],
        "torque_drop_over_range": {
            "equation1": float(rig.gough_torque_Nm(1.0, low_Pa, mu) / rig.gough_torque_Nm(1.0, high_Pa, mu)),
            "equation2": float(
                rig.empirical_torque_Nm(1.0, low_Pa, mu, p0, n) / rig.empirical_torque_Nm(1.0, high_Pa, mu, p0, n)
            ),
        },
        "torque_at_reference_pressure_Nm": {
            f"{w:g}": float(rig.empirical_torque_Nm(w, p0, mu, p0, n)) for w in loads
        },
        "equation2_torque_at_range_ends_Nm": {
            f"{w:g}": [float(rig.empirical_torque_Nm(w, p, mu, p0, n)) for p in (low_Pa, high_Pa)] for w in loads
        },
        "car_model_pressure_Pa": params["tyre.tyre_pressure"],
        "equation2_over_equation1_at_car_pressure": float(
            rig.pressure_correction(params["tyre.tyre_pressure"], p0, n)
        ),
    }


def plot_fig3(params: Parameters, columns: dict[str, np.ndarray]):
    """Limiting torque against inflation pressure: equation (2) dashed, equation (1) dotted, per load."""
    fig, ax = new_figure(6.5, 4.2)
    for colour, load_N in zip(COLOURS, params["rig.loads"]):
        rows = columns["load_N"] == load_N
        bar = columns["pressure_Pa"][rows] / PA_PER_BAR
        ax.plot(bar, columns["empirical_torque_Nm"][rows], color=colour, linestyle="--", linewidth=1.6,
                label=_load_label(load_N))
        ax.plot(bar, columns["gough_torque_Nm"][rows], color=colour, linestyle=":", linewidth=1.0)
    p0_bar = params["tyre.reference_pressure"] / PA_PER_BAR
    ax.axvline(p0_bar, color="0.4", linewidth=0.7)
    ax.annotate(f"p0 = {p0_bar:g} bar: (1) = (2)", xy=(p0_bar, 0.03), xycoords=("data", "axes fraction"),
                xytext=(4, 0), textcoords="offset points", va="bottom", fontsize=8, color="0.3")
    low_Pa, high_Pa = params["rig.fig3_pressure_range"]
    ax.set_xlim(low_Pa / PA_PER_BAR, high_Pa / PA_PER_BAR)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("inflation pressure p (bar)")
    ax.set_ylabel("limiting steer torque T (N m)")
    load_legend = ax.legend(loc="upper right", title="rig load")
    ax.add_artist(load_legend)
    n = params["tyre.pressure_index"]
    handles = _style_handles(ax, [
        (rf"eq. (2), $T \propto p^{{-{n:g}}}$", {"linestyle": "--", "linewidth": 1.6}),
        (r"eq. (1) (Gough), $T \propto p^{-0.5}$", {"linestyle": ":", "linewidth": 1.0}),
    ])
    ax.legend(handles=handles, loc="lower left")
    fig.tight_layout()
    return fig


def make_fig3(params: Parameters | str | Path, out_svg: str | Path, out_csv: str | Path, out_json: str | Path) -> dict:
    """Write figures/fig3.svg, figures/fig3.csv and results/fig3.json."""
    params = _as_parameters(params)
    columns = fig3_columns(params)
    header = {
        "figure": "Fig. 3, limiting torque against inflation pressure, equations (1) and (2)",
        "friction coefficient": params["tyre.friction_coefficient"],
        "reference pressure p0 (Pa)": params["tyre.reference_pressure"],
        "pressure index n": params["tyre.pressure_index"],
        "loads": params.source("rig.loads"),
    }
    summary = fig3_summary(params)
    fig = plot_fig3(params, columns)
    write_csv(out_csv, columns, header)
    write_json(out_json, summary)
    save_svg(fig, out_svg)
    return summary


# ---------------------------------------------------------------- Fig. 4


def fig4_columns(params: Parameters, n_points: int = FIG4_POINTS) -> dict[str, np.ndarray]:
    """Long-format data of Fig. 4: one row per (pressure, load, offset), free-rolling and braked."""
    low_m, high_m = params["rig.fig4_offset_range"]
    offsets = np.linspace(low_m, high_m, n_points)
    grid_p, grid_w, grid_e = np.meshgrid(params["rig.fig4_pressures"], params["rig.loads"], offsets, indexing="ij")
    pressure_Pa, load_N, offset_m = grid_p.ravel(), grid_w.ravel(), grid_e.ravel()
    torques = rig.pin_torques_Nm(params, load_N, pressure_Pa, offset_m)
    return {
        "pressure_Pa": pressure_Pa,
        "load_N": load_N,
        "offset_m": offset_m,
        "patch_radius_m": rig.patch_radius_m(load_N, pressure_Pa),
        "free_rolling_torque_Nm": torques.free_rolling_Nm,
        "braked_torque_Nm": torques.braked_Nm,
    }


def braked_rise_offset_m(
    params: Parameters, load_N: float, pressure_Pa: float, rise: float = BRAKED_RISE_QUOTED
) -> float:
    """Pin offset at which the braked torque exceeds the free-rolling torque by the fraction `rise`."""
    free = float(rig.pin_torques_Nm(params, load_N, pressure_Pa, 0.0).free_rolling_Nm)

    def excess(offset_m: float) -> float:
        return float(rig.pin_torques_Nm(params, load_N, pressure_Pa, offset_m).braked_Nm) / free - 1.0 - rise

    radius_m = float(rig.patch_radius_m(load_N, pressure_Pa))
    # braked >= mu W e + (c - 1) (2/3) mu W R (triangle inequality on the drag part, c the pressure
    # correction) and free = c (2/3) mu W R, so at e = (1 + rise) R the excess is positive for c < 1.5
    return brentq(excess, 0.0, (1.0 + rise) * radius_m, xtol=1e-9)


def fig4_summary(params: Parameters) -> dict:
    """The numbers the paper quotes about Fig. 4."""
    low_m, high_m = params["rig.fig4_offset_range"]
    headline_load = _headline_load_N(params)
    pressures = list(params["rig.fig4_pressures"])
    headline_pressure = pressures[len(pressures) // 2]  # the middle panel (2 bar)
    per_case = []
    for p in pressures:
        for w in params["rig.loads"]:
            at_max = rig.pin_torques_Nm(params, w, p, high_m)
            per_case.append({
                "pressure_Pa": p,
                "load_N": w,
                "patch_radius_m": float(rig.patch_radius_m(w, p)),
                "free_rolling_torque_Nm": float(at_max.free_rolling_Nm),
                "braked_torque_at_max_offset_Nm": float(at_max.braked_Nm),
                "braked_over_free_at_max_offset": float(at_max.braked_Nm / at_max.free_rolling_Nm),
                BRAKED_RISE_KEY: braked_rise_offset_m(params, w, p),
            })
    headline = rig.pin_torques_Nm(params, headline_load, headline_pressure, high_m)
    return {
        "statement": SCALING_STATEMENT,
        "finding": "free-rolling torque is independent of the pin offset (the rig's finding); "
        "a braked wheel's torque grows with offset, as 1 + (3/4)(e/R)^2 for small e and as mu W e for e >> R",
        "loads_N": [float(w) for w in params["rig.loads"]],
        "loads_source": params.source("rig.loads"),
        "pressures_Pa": pressures,
        "offset_range_m": [low_m, high_m],
        "offset_range_source": params.source("rig.fig4_offset_range"),
        "headline": {
            "load_N": headline_load,
            "pressure_Pa": headline_pressure,
            "offset_m": high_m,
            "free_rolling_torque_Nm": float(headline.free_rolling_Nm),
            "braked_torque_Nm": float(headline.braked_Nm),
            "braked_over_free": float(headline.braked_Nm / headline.free_rolling_Nm),
            BRAKED_RISE_KEY: braked_rise_offset_m(params, headline_load, headline_pressure),
        },
        "cases": per_case,
    }


def plot_fig4(params: Parameters, columns: dict[str, np.ndarray]):
    """Small multiples, one panel per pressure: free-rolling solid, braked dashed, per load."""
    pressures = params["rig.fig4_pressures"]
    fig, axes = new_figure(7.0, 4.2, ncols=len(pressures), sharex=True, sharey=True)
    axes = np.atleast_1d(axes)
    for ax, p in zip(axes, pressures):
        for colour, w in zip(COLOURS, params["rig.loads"]):
            rows = (columns["pressure_Pa"] == p) & (columns["load_N"] == w)
            offset_mm = 1000.0 * columns["offset_m"][rows]
            ax.plot(offset_mm, columns["free_rolling_torque_Nm"][rows], color=colour, linestyle="-",
                    label=_load_label(w))
            ax.plot(offset_mm, columns["braked_torque_Nm"][rows], color=colour, linestyle="--")
            radius_m = float(rig.patch_radius_m(w, p))
            edge = rig.pin_torques_Nm(params, w, p, radius_m).braked_Nm
            ax.plot([1000.0 * radius_m], [float(edge)], marker="o", markersize=3.5, color=colour, linestyle="none")
        ax.set_title(f"p = {p / PA_PER_BAR:g} bar", fontsize=9)
        ax.set_xlabel("pin offset e (mm)")
    low_m, high_m = params["rig.fig4_offset_range"]
    axes[0].set_xlim(1000.0 * low_m, 1000.0 * high_m)
    axes[0].set_ylim(bottom=0.0)
    axes[0].set_ylabel("limiting steer torque about the pin (N m)")
    load_handles, load_labels = axes[0].get_legend_handles_labels()
    style_handles = _style_handles(axes[0], [
        ("wheel free to roll", {"linestyle": "-"}),
        ("wheel braked", {"linestyle": "--"}),
        ("pin at patch edge, e = R", {"linestyle": "none", "marker": "o", "markersize": 3.5}),
    ])
    # legends below the panels, where they cannot hide a curve
    fig.legend(load_handles, load_labels, loc="lower center", ncol=len(load_handles), bbox_to_anchor=(0.5, 0.07))
    fig.legend(handles=style_handles, loc="lower center", ncol=len(style_handles), bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout(rect=(0.0, 0.14, 1.0, 1.0))
    return fig


def make_fig4(params: Parameters | str | Path, out_svg: str | Path, out_csv: str | Path, out_json: str | Path) -> dict:
    """Write figures/fig4.svg, figures/fig4.csv and results/fig4.json."""
    params = _as_parameters(params)
    columns = fig4_columns(params)
    header = {
        "figure": "Fig. 4, limiting torque about an offset pin, wheel free to roll and wheel braked",
        "scaling": SCALING_STATEMENT,
        "loads": params.source("rig.loads"),
        "offset range": params.source("rig.fig4_offset_range"),
    }
    summary = fig4_summary(params)
    fig = plot_fig4(params, columns)
    write_csv(out_csv, columns, header)
    write_json(out_json, summary)
    save_svg(fig, out_svg)
    return summary
