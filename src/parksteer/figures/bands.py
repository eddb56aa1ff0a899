"""Bands on the headline numbers: each number the paper quotes, over the reconstructed inputs.

The model's headline numbers rest on inputs the source does not give and this project reconstructed or chose (the
parameter file says which). Each such input (the Hooke joint's phase, the handwheel lock angle, the wheel radius,
each steering assembly's mass centre, the axis of the tyre's friction moment, the saw-tooth rounding) is moved one
at a time over its plausible range through the parameter registry's overrides (values only: the compiled model is
the figures' own, nothing is derived again), and every headline number (plateau and near-lock torque, rise,
reversal step, shares, offset effect, A1 against the simulation (:func:`a1_deviation`), part-laden rise, ground
scrub radius) is recomputed from the simulated cycles. The ranges and the numbers' definitions: docs/model.md,
"Bands over the reconstructed inputs".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.patches import Patch

from .. import portable as pm
from ..geometry import lifting_torque_a1, steer_axis
from ..parameters import Parameters, load_parameters
from ..plotting import COLOURS, new_figure, save_svg
from ..sweep.merit import braked_columns
from ..tables import write_csv, write_json
from .model import PLATEAU_RACK_M, cycle_summary, plateau_mask
from ..names import TORQUE

HOOKE_PHASES = 8  # phases evaluated over a full column turn


@dataclass(frozen=True)
class BandInput:
    """A reconstructed input and the settings (override dicts, each with a label) it is moved over.

    `tyre_moment_about_steer_axis`: instead of overrides, apply the tyre's friction moment about the steer axis
    rather than the ground normal (:func:`tyre_moment_about_steer_axis`)."""

    name: str
    label: str
    settings: tuple[tuple[str, dict[str, float]], ...]
    tyre_moment_about_steer_axis: bool = False


def band_inputs(params: Parameters) -> tuple[BandInput, ...]:
    """The reconstructed inputs and their ranges, from the parameter file's nominal values."""
    lock = params["input.handwheel_lock_angle"]
    centre_z = params["geometry.wheel_centre_z"]
    rig_radius = params["rig.rolling_radius"]
    d_m = steer_axis(params, "unladen", "left").offset_d_m
    rounding = params["input.reversal_rounding_time"]
    phases = [2 * math.pi * k / HOOKE_PHASES for k in range(HOOKE_PHASES)]
    return (
        BandInput("hooke_phase", "Hooke joint phase, full turn", tuple(
            (f"{p:.3f} rad", {"steering.hooke_joint_phase": p}) for p in phases)),
        BandInput("lock_angle", "lock angle +-10 %", (
            (f"{0.9 * lock:.2f} rad", {"input.handwheel_lock_angle": 0.9 * lock}),
            (f"{1.1 * lock:.2f} rad", {"input.handwheel_lock_angle": 1.1 * lock}))),
        BandInput("wheel_radius", "wheel radius 0.263-0.30 m", (
            (f"{rig_radius:.3f} m", {"geometry.ground_z": centre_z + rig_radius,
                                     "vehicle.roll_axis_z": centre_z + rig_radius}),)),
        BandInput("assembly_cg", "assembly mass centre, axis to wheel centre", (
            (f"{1000 * d_m:.1f} mm", {"steering.steering_assembly_cg_outboard": d_m}),)),
        BandInput("tyre_moment_axis", "tyre moment about the steer axis", (("steer axis", {}),),
                  tyre_moment_about_steer_axis=True),
        BandInput("rounding", "saw-tooth rounding 0.2-0.8 s", (
            (f"{0.5 * rounding:.1f} s", {"input.reversal_rounding_time": 0.5 * rounding}),
            (f"{2.0 * rounding:.1f} s", {"input.reversal_rounding_time": 2.0 * rounding}))),
    )


# (key, label, unit) of each headline number, in the table's order.
NUMBERS = (
    ("plateau_Nm", "plateau torque", "N m"),
    ("near_lock_Nm", "torque near lock", "N m"),
    ("rise_toward_lock_Nm", "rise toward lock", "N m"),
    ("reversal_step_Nm", "reversal step (rack friction)", "N m"),
    ("tyre_share_Nm", "tyre friction share", "N m"),
    ("rack_share_Nm", "rack friction share", "N m"),
    ("lifting_share_Nm", "lifting share", "N m"),
    ("lifting_near_lock_Nm", "lifting share near lock", "N m"),
    ("offset_effect_pct", "68.5 mm spacer: plateau change", "%"),
    ("a1_deviation_pct", "model lifting against A1", "%"),
    ("air_bearing_above_a1_Nm", "air-bearing torque above A1", "N m"),
    ("part_laden_rise_pct", "part laden: plateau change", "%"),
    ("ground_scrub_mm", "ground scrub (straight ahead)", "mm"),
)


def hooke_speed_ratio(params: Parameters, column_angle_rad) -> np.ndarray:
    """d(pinion)/d(column) of the Hooke joint, cos a / (cos^2 a cos^2 psi + sin^2 psi), psi = column - phase:
    the factor by which the joint carries a pinion torque to the column (1/cos a at psi = 0)."""
    a = params["steering.hooke_joint_angle"]
    psi = np.asarray(column_angle_rad, dtype=float) - params["steering.hooke_joint_phase"]
    return pm.cos(a) / (pm.cos(a) ** 2 * pm.cos(psi) ** 2 + pm.sin(psi) ** 2)


def a1_deviation(columns: dict, params: Parameters, case: str) -> dict:
    """The model's lifting share against equation (A1) over the plateau window of one cycle.

    A1 is the handwheel torque of the fixed body's lifting through a straight column; the model's share passes
    the Hooke joint, so A1 is multiplied by the joint's speed ratio at the column angle of each sample. Returns
    the relative deviation of the lifting share and the mean total torque above A1 (as plotted, Fig. A3 has no
    joint and no rack friction).
    """
    window = plateau_mask(columns, params)
    steer = 0.5 * (np.asarray(columns["steer_left_rad"]) + np.asarray(columns["steer_right_rad"]))
    a1 = lifting_torque_a1(params, case, steer)
    through_joint = a1 * hooke_speed_ratio(params, columns["column_angle_rad"])
    lifting = np.asarray(columns["contrib_lifting_Nm"], dtype=float)
    torque = np.asarray(columns[TORQUE], dtype=float)
    return {
        "deviation": float(np.mean(lifting[window]) / np.mean(through_joint[window]) - 1.0),
        "torque_above_a1_Nm": float(np.mean(torque[window] - a1[window])),
    }


def tyre_moment_about_steer_axis(columns: dict, params: Parameters, case: str) -> dict:
    """The cycle with the tread's friction moment acting about the steer axis instead of the ground normal.

    The model applies the patch's moment M about the ground normal; the tread ring turns about the steer axis,
    so its generalized force is M times the axis's vertical component n_z = cos(castor) cos(king-pin
    inclination) nearly. Where the moment acts is a reconstruction (the source says neither); about the axis the
    tyre share is larger by 1/n_z, so the torque gains (1/n_z - 1) times the tyre share.
    """
    n_z = abs(float(steer_axis(params, case, "left").direction[2]))
    return braked_columns(columns, 1.0 / n_z)


def headline_numbers(params: Parameters, simulate=None, about_steer_axis: bool = False) -> dict[str, float]:
    """Every headline number (see the module docstring) for one parameter set: four simulated cycles (with the
    tyre moment about the steer axis when `about_steer_axis`)."""
    if simulate is None:
        from ..model.numeric.simulate import simulate
    run = {
        (case, surface): simulate(case, params=params, surface=surface).columns
        for case, surface in (("unladen", "ground"), ("unladen", "air_bearing"), ("offset_68_5mm", "ground"),
                              ("part_laden", "ground"))
    }
    if about_steer_axis:
        run = {key: tyre_moment_about_steer_axis(c, params, key[0]) for key, c in run.items()}
    unladen = cycle_summary(run[("unladen", "ground")], params)
    shares = unladen["contributions"]
    plateau = unladen["plateau_torque_Nm"]
    offset = cycle_summary(run[("offset_68_5mm", "ground")], params)["plateau_torque_Nm"]
    laden = cycle_summary(run[("part_laden", "ground")], params)["plateau_torque_Nm"]
    air = a1_deviation(run[("unladen", "air_bearing")], params, "unladen")
    return {
        "plateau_Nm": plateau,
        "near_lock_Nm": unladen["torque_near_right_lock_Nm"],
        "rise_toward_lock_Nm": unladen["torque_near_right_lock_Nm"] - plateau,
        "reversal_step_Nm": unladen["reversal_step_at_right_lock_Nm"],
        "tyre_share_Nm": shares["tyre_friction"]["plateau_Nm"],
        "rack_share_Nm": shares["rack_friction"]["plateau_Nm"],
        "lifting_share_Nm": shares["lifting"]["plateau_Nm"],
        "lifting_near_lock_Nm": shares["lifting"]["near_right_lock_Nm"],
        "offset_effect_pct": 100.0 * (offset / plateau - 1.0),
        "a1_deviation_pct": 100.0 * air["deviation"],
        "air_bearing_above_a1_Nm": air["torque_above_a1_Nm"],
        "part_laden_rise_pct": 100.0 * (laden / plateau - 1.0),
        "ground_scrub_mm": 1000.0 * steer_axis(params, "unladen", "left").scrub_radius_m(),
    }


def compute_bands(params: Parameters, simulate=None) -> dict:
    """The nominal headline numbers, each input's range of them, and the band over all inputs.

    Returns {"nominal": {number: value}, "inputs": {input: {"label", "settings", "values": {number: [..]}}},
    "band": {number: [low, high]}}; the band spans the nominal value and every one-at-a-time setting.
    """
    nominal = headline_numbers(params, simulate)
    inputs = {}
    band = {k: [v, v] for k, v in nominal.items()}
    for item in band_inputs(params):
        values: dict[str, list[float]] = {k: [] for k in nominal}
        for _, overrides in item.settings:
            numbers = headline_numbers(params.with_overrides(overrides), simulate, item.tyre_moment_about_steer_axis)
            for k, v in numbers.items():
                values[k].append(v)
                band[k] = [min(band[k][0], v), max(band[k][1], v)]
        inputs[item.name] = {"label": item.label, "settings": [s for s, _ in item.settings], "values": values}
    return {"nominal": nominal, "inputs": inputs, "input_order": list(inputs), "band": band,
            "plateau_rack_range_m": list(PLATEAU_RACK_M)}


def band_table(bands: dict) -> dict[str, list]:
    """The band table's columns: one row per headline number, with each input's low and high."""
    rows: dict[str, list] = {"number": [], "label": [], "unit": [], "nominal": [], "band_low": [], "band_high": []}
    for name in bands["input_order"]:
        rows[f"{name}_low"] = []
        rows[f"{name}_high"] = []
    for key, label, unit in NUMBERS:
        rows["number"].append(key)
        rows["label"].append(label.replace(",", ";"))
        rows["unit"].append(unit.replace(" ", "_"))
        rows["nominal"].append(bands["nominal"][key])
        rows["band_low"].append(bands["band"][key][0])
        rows["band_high"].append(bands["band"][key][1])
        for name in bands["input_order"]:
            values = bands["inputs"][name]["values"][key] + [bands["nominal"][key]]
            rows[f"{name}_low"].append(min(values))
            rows[f"{name}_high"].append(max(values))
    return rows


def plot_tornado(bands: dict):
    """One tornado panel per headline number: each input's range about the nominal value."""
    n = len(NUMBERS)
    ncols = 3
    nrows = math.ceil(n / ncols)
    fig, axes = new_figure(7.2, 1.55 * nrows + 0.6, nrows=nrows, ncols=ncols)
    names = bands["input_order"]
    labels = [bands["inputs"][k]["label"] for k in names]
    for ax, (key, label, unit) in zip(axes.flat, NUMBERS):
        nominal = bands["nominal"][key]
        for row, name in enumerate(names):
            values = bands["inputs"][name]["values"][key] + [nominal]
            low, high = min(values), max(values)
            ax.barh(row, high - low, left=low, height=0.6, color=COLOURS[row % len(COLOURS)])
        ax.axvline(nominal, color="k", linewidth=0.8)
        ax.set_yticks(range(len(names)))
        ax.set_yticklabels([])
        ax.invert_yaxis()
        ax.set_title(f"{label} ({unit})", fontsize=7)
        ax.tick_params(labelsize=6)
        span = bands["band"][key]
        pad = 0.08 * max(span[1] - span[0], 1e-9)
        ax.set_xlim(span[0] - pad, span[1] + pad)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    handles = [Patch(color=COLOURS[i % len(COLOURS)]) for i in range(len(labels))]
    fig.legend(handles=handles, labels=labels, loc="lower right", fontsize=6.5, frameon=False,
               bbox_to_anchor=(0.98, 0.02))
    fig.suptitle("Headline numbers over the reconstructed inputs (black line: nominal)", fontsize=8)
    fig.tight_layout()
    return fig


def make_bands(parameters_path: str | Path, svg_path: str | Path, csv_path: str | Path,
               json_path: str | Path) -> None:
    """Write the tornado figure (SVG), the band table (CSV) and the bands (JSON) from a parameter file."""
    params = load_parameters(parameters_path)
    bands = compute_bands(params)
    header = {
        "table": "headline numbers: nominal, band over the reconstructed inputs, and each input's low and high",
        "inputs": "; ".join(f"{k}: {v['label']} ({', '.join(v['settings'])})" for k, v in bands["inputs"].items()),
        "units": "column unit; N_m is N m at the handwheel",
    }
    fig = plot_tornado(bands)
    write_csv(csv_path, band_table(bands), header)
    write_json(json_path, bands)
    save_svg(fig, svg_path)
