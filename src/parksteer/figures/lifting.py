"""Fig. A3: handwheel torque from lifting the body, equation (A1), over the lock range.

Equation (A1) is the virtual work of the static wheel loads on the heights of the two
contact points as the wheels steer about their king-pin axes with the body held fixed
(Appendix A). It is evaluated here for the standard car and the three wheel spacers
(Table B1 cases), from full left lock to full right lock. The paper's reading of it:
the torque is proportional to d, the perpendicular distance from wheel centre to steer
axis, and the first term of (A1), (W_r - W_l) sin(castor) cos(steer), is negligible.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import portable as pm
from ..geometry import lifting_torque_a1, lock_steer_angle, steering_ratio, steer_axis
from ..parameters import Parameters, load_parameters
from ..plotting import COLOURS, new_figure, save_svg
from ..tables import write_csv, write_json

# The standard car and the three spacers of Fig. A3, in the caption's order.
FIGA3_CASES = ("unladen", "offset_12_7mm", "offset_44_5mm", "offset_68_5mm")

# Odd, so that straight ahead (rack = 0) is a sample.
N_POINTS = 201


def torque_column(case: str) -> str:
    """CSV column name of the Fig. A3 torque of `case`."""
    return f"torque_{case}_Nm"


def first_term_a1_Nm(params: Parameters, case: str, steer_rad: float | np.ndarray) -> float | np.ndarray:
    """The first term of (A1) alone, d (W_r - W_l) sin(castor) cos(steer) / G: the handwheel torque (N m)
    from the side-to-side load difference, the only part that survives at zero steer."""
    c = params.case(case)
    d_m = steer_axis(params, case, "left").offset_d_m
    castor_rad = params["geometry.castor_angle"]
    load_difference_N = c["load_right"] - c["load_left"]
    return d_m * load_difference_N * pm.sin(castor_rad) * pm.cos(steer_rad) / steering_ratio(params)


def lifting_curves(params: Parameters, cases: tuple[str, ...] = FIGA3_CASES, n_points: int = N_POINTS) -> dict:
    """Columns of Fig. A3: steer_rad, rack_m and one (A1) torque column per case, lock to lock."""
    steer_per_rack = params["steering.roadwheel_to_rack_ratio"]
    lock_rack_m = lock_steer_angle(params) / steer_per_rack
    rack_m = np.linspace(-lock_rack_m, lock_rack_m, n_points)
    steer_rad = steer_per_rack * rack_m
    columns = {"steer_rad": steer_rad, "rack_m": rack_m}
    for case in cases:
        columns[torque_column(case)] = lifting_torque_a1(params, case, steer_rad)
    return columns


def lifting_summary(params: Parameters, cases: tuple[str, ...] = FIGA3_CASES) -> dict:
    """The numbers the paper quotes about Fig. A3, per case and at full lock."""
    lock_rad = lock_steer_angle(params)
    per_case = {}
    for case in cases:
        axis = steer_axis(params, case, "left")
        at_right_lock_Nm = float(lifting_torque_a1(params, case, lock_rad))
        at_left_lock_Nm = float(lifting_torque_a1(params, case, -lock_rad))
        per_case[case] = {
            "extra_offset_m": params.case(case)["extra_offset"],
            "offset_d_m": axis.offset_d_m,
            "scrub_radius_m": axis.scrub_radius_m(),
            "torque_at_right_lock_Nm": at_right_lock_Nm,
            "torque_at_left_lock_Nm": at_left_lock_Nm,
            "torque_straight_ahead_Nm": float(lifting_torque_a1(params, case, 0.0)),
            "first_term_share_at_right_lock": float(first_term_a1_Nm(params, case, lock_rad)) / at_right_lock_Nm,
            "torque_at_right_lock_per_offset_d_N": at_right_lock_Nm / axis.offset_d_m,
        }
    return {
        "equation": "A1",
        "cases": per_case,
        "lock_steer_rad": lock_rad,
        "lock_rack_m": lock_rad / params["steering.roadwheel_to_rack_ratio"],
        "lock_handwheel_rad": params["input.handwheel_lock_angle"],
        "steering_ratio": steering_ratio(params),
        "castor_angle_rad": params["geometry.castor_angle"],
        "kingpin_inclination_rad": params["geometry.kingpin_inclination"],
    }


def _case_label(params: Parameters, case: str) -> str:
    offset_mm = 1000.0 * params.case(case)["extra_offset"]
    d_mm = 1000.0 * steer_axis(params, case, "left").offset_d_m
    name = "standard car" if offset_mm == 0.0 else f"{offset_mm:.1f} mm spacer"
    return f"{name} (d = {d_mm:.1f} mm)"


def plot_figA3(params: Parameters, columns: dict, cases: tuple[str, ...] = FIGA3_CASES):
    """Handwheel torque against rack displacement (mm), road-wheel steer angle on the top axis."""
    steer_per_rack = params["steering.roadwheel_to_rack_ratio"]
    fig, ax = new_figure(6.5, 4.0)
    rack_mm = 1000.0 * columns["rack_m"]
    for colour, case in zip(COLOURS, cases):
        ax.plot(rack_mm, columns[torque_column(case)], color=colour, label=_case_label(params, case))
    ax.axhline(0.0, color="0.5", linewidth=0.6)
    ax.axvline(0.0, color="0.5", linewidth=0.6)
    ax.set_xlim(rack_mm[0], rack_mm[-1])
    ax.set_xlabel("rack displacement (mm), positive steering right")
    ax.set_ylabel("handwheel torque from lifting, eq. (A1) (N m)")
    top = ax.secondary_xaxis(
        "top",
        functions=(lambda mm: steer_per_rack * mm / 1000.0, lambda rad: 1000.0 * rad / steer_per_rack),
    )
    top.set_xlabel("road-wheel steer angle (rad)")
    ax.legend(loc="upper left")
    fig.tight_layout()
    return fig


def make_figA3(parameters_path: str | Path, svg_path: str | Path, csv_path: str | Path, json_path: str | Path) -> None:
    """Write figures/figA3.svg, its plotted data (CSV) and its key numbers (JSON) from a parameter file."""
    params = load_parameters(parameters_path)
    columns = lifting_curves(params)
    header = {
        "figure": "Fig. A3, handwheel torque from lifting the body, equation (A1)",
        "cases": ", ".join(FIGA3_CASES),
        "units": "steer in rad, rack in m, torque at the handwheel in N m",
    }
    summary = lifting_summary(params)
    fig = plot_figA3(params, columns)
    write_csv(csv_path, columns, header)
    write_json(json_path, summary)
    save_svg(fig, svg_path)
