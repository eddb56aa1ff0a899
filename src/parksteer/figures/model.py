"""Figs. 12-16 and the contribution figure: the multibody model's cycle (paper section 4).

Each simulation of the figures is one CSV, results/sim/<case>__<variant>.csv, written by
:func:`write_simulation`; the figures read those files, so figures that share a run share
its file. A variant is a set of effects and a surface; the variants and each figure's runs
are the pipeline's configuration (config/config.yaml: ``models``, ``variants``,
``model_figures``), read by :meth:`FigureDesign.from_config`:

- full: the paper's five effects, tyres on the ground;
- no_rack_friction, no_tyre_friction, no_friction: Fig. 14's ablations (effects switched off);
- air_bearing: the five effects, tyres on air bearings (no tyre-to-ground friction), Fig. 16.

The key numbers of each figure (plateau torque, torque near lock, drop at a reversal, the
shares of the mechanisms, the offset sensitivity) go to results/<figure>.json.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import portable as pm
from ..errors import UsageError
from ..geometry import steer_axis
from ..parameters import Parameters, load_parameters
from ..tables import read_csv, write_csv, write_json
from ..names import TORQUE

Run = tuple[str, str]  # (case, variant)


@dataclass(frozen=True)
class Variant:
    """A variant of the figures' runs: its compiled model (a name and an effects spec), surface and legend label
    (None: the run is labelled by its case)."""

    model: str
    effects: str | list | None
    surface: str
    label: str | None = None


@dataclass(frozen=True)
class FigureDesign:
    """The variants and each figure's runs (in legend order)."""

    variants: dict[str, Variant]
    figures: dict[str, tuple[Run, ...]]

    @classmethod
    def from_config(cls, config: dict) -> FigureDesign:
        """From the configuration's ``models``, ``variants`` and ``model_figures``; a name that is not defined
        is refused in one line naming its key."""
        for name, v in config["variants"].items():
            if v["model"] not in config["models"]:
                raise UsageError(f"config variants.{name}.model: no model {v['model']!r} under models")
        for name, runs in config["model_figures"].items():
            for case, variant in runs:
                if variant not in config["variants"]:
                    raise UsageError(f"config model_figures.{name}: no variant {variant!r} under variants")
        variants = {name: Variant(v["model"], config["models"][v["model"]], v["surface"], v.get("label"))
                    for name, v in config["variants"].items()}
        figures = {name: tuple((str(c), str(v)) for c, v in runs) for name, runs in config["model_figures"].items()}
        return cls(variants, figures)

    def all_simulations(self) -> list[Run]:
        """Every (case, variant) run of the figures, once each."""
        return list(dict.fromkeys(run for runs in self.figures.values() for run in runs))


OFFSET_CASES = ("unladen", "offset_12_7mm", "offset_44_5mm", "offset_68_5mm")
# The plateau: the first steer towards right lock, rack between these positions (m), after the carcass wind-up
PLATEAU_RACK_M = (0.02, 0.06)

EFFECT_LABELS = {
    "tyre_friction": "tyre friction",
    "rack_friction": "rack friction",
    "lifting": "lifting",
    "carcass_compliance": "carcass compliance",
    "hooke_joint": "Hooke joint",
    "inertia": "inertia",
}


def simulation_path(case: str, variant: str, directory: str | Path = "results/sim") -> Path:
    return Path(directory) / f"{case}__{variant}.csv"


def run_simulation(params: Parameters, case: str, effects, surface: str):
    from ..model.numeric.simulate import simulate

    return simulate(case, effects=effects, surface=surface, params=params)


def write_simulation(parameters_path: str | Path, case: str, variant: str, effects, surface: str,
                     csv_path: str | Path) -> None:
    """Simulate one (case, variant) run of the figures (the variant's effects spec and surface), write its CSV."""
    result = run_simulation(load_parameters(parameters_path), case, effects, surface)
    result.header["variant"] = variant
    result.write_csv(csv_path)


# -- key numbers --------------------------------------------------------------------------
def _times(params: Parameters) -> dict[str, float]:
    t_right = params["input.time_to_right_lock"]
    t_left = t_right + params["input.time_right_to_left_lock"]
    return {"right_lock": t_right, "left_lock": t_left, "half_rounding": params["input.reversal_rounding_time"] / 2}


def _at(columns: dict, name: str, t_s: float) -> float:
    return float(np.interp(t_s, columns["time_s"], columns[name]))


def plateau_mask(columns: dict, params: Parameters) -> np.ndarray:
    t_right = _times(params)["right_lock"]
    rack = columns["rack_m"]
    return (columns["time_s"] < t_right) & (rack >= PLATEAU_RACK_M[0]) & (rack <= PLATEAU_RACK_M[1])


STEP_LEVEL = 0.99  # tanh(beta v) of the rack speed at the two ends of the rack-friction step


def _crossing_time(t: np.ndarray, x: np.ndarray, level: float, start: int) -> float:
    """The first time from index `start` on at which x passes `level`, linearly interpolated."""
    above = x[start:] >= level
    k = start + int(np.flatnonzero(above[1:] != above[0])[0])
    return float(t[k] + (level - x[k]) * (t[k + 1] - t[k]) / (x[k + 1] - x[k]))


def reversal_step(columns: dict, params: Parameters) -> dict:
    """The handwheel torque step at right lock while the rack friction reverses, measured where it happens.

    The rack friction is F tanh(beta v); its step is taken between the instants at which tanh(beta v) passes
    +0.99 and -0.99 (the rack speed's zero crossing at right lock), so the carcasses' unwinding over the rounded
    reversal stays out of it. Returns the step, its window and (when the run has rack friction) the rack friction
    share's own step.
    """
    t = np.asarray(columns["time_s"], dtype=float)
    level = pm.tanh(params["steering.friction_smoothing"] * np.asarray(columns["rack_speed_m_s"], dtype=float))
    i_lock = int(np.argmax(columns["rack_m"]))
    start = int(np.flatnonzero((level[:i_lock] >= STEP_LEVEL))[-1])
    t0 = _crossing_time(t, level, STEP_LEVEL, start)
    t1 = _crossing_time(t, level, -STEP_LEVEL, start)
    torque = np.asarray(columns[TORQUE], dtype=float)
    out = {"step_Nm": float(np.interp(t0, t, torque) - np.interp(t1, t, torque)), "window_s": [t0, t1]}
    if "contrib_rack_friction_Nm" in columns:
        rack = np.asarray(columns["contrib_rack_friction_Nm"], dtype=float)
        out["rack_friction_step_Nm"] = float(np.interp(t0, t, rack) - np.interp(t1, t, rack))
    return out


def cycle_summary(columns: dict, params: Parameters) -> dict:
    """Key numbers of one cycle: plateau, near lock, reversal drops, peak, loads, contribution shares."""
    t = _times(params)
    before_right = t["right_lock"] - t["half_rounding"]
    after_right = t["right_lock"] + t["half_rounding"]
    before_left = t["left_lock"] - t["half_rounding"]
    after_left = t["left_lock"] + t["half_rounding"]
    torque = columns[TORQUE]
    plateau = plateau_mask(columns, params)
    out = {
        "plateau_torque_Nm": float(np.mean(torque[plateau])),
        "plateau_rack_range_m": list(PLATEAU_RACK_M),
        "torque_near_right_lock_Nm": _at(columns, TORQUE, before_right),
        "rack_near_right_lock_m": _at(columns, "rack_m", before_right),
        "torque_near_left_lock_Nm": _at(columns, TORQUE, before_left),
        "drop_at_right_lock_reversal_Nm": _at(columns, TORQUE, before_right)
        - _at(columns, TORQUE, after_right),
        "reversal_step_at_right_lock_Nm": reversal_step(columns, params)["step_Nm"],
        "rise_at_left_lock_reversal_Nm": _at(columns, TORQUE, after_left)
        - _at(columns, TORQUE, before_left),
        "peak_torque_Nm": float(np.max(np.abs(torque))),
        "max_rack_m": float(np.max(columns["rack_m"])),
        "min_rack_m": float(np.min(columns["rack_m"])),
        "load_left_range_N": [float(np.min(columns["load_left_N"])), float(np.max(columns["load_left_N"]))],
        "load_right_range_N": [float(np.min(columns["load_right_N"])), float(np.max(columns["load_right_N"]))],
        "load_left_near_right_lock_N": _at(columns, "load_left_N", before_right),
        "load_right_near_right_lock_N": _at(columns, "load_right_N", before_right),
    }
    shares = {}
    for name in columns:
        if name.startswith("contrib_") and name.endswith("_Nm"):
            effect = name[len("contrib_"):-len("_Nm")]
            shares[effect] = {
                "plateau_Nm": float(np.mean(columns[name][plateau])),
                "near_right_lock_Nm": _at(columns, name, before_right),
            }
    out["contributions"] = shares
    return out


# -- figures ------------------------------------------------------------------------------
def _label(params: Parameters, case: str, variant: str, labels: dict[str, str]) -> str:
    c = params.case(case)
    if case == "part_laden":
        name = "part laden"
    elif c["extra_offset"] > 0:
        name = f"{1000 * c['extra_offset']:.1f} mm spacer"
    else:
        name = "unladen (nominal)"
    if case in OFFSET_CASES:
        name += f", d = {1000 * steer_axis(params, case, 'left').offset_d_m:.1f} mm"
    return labels.get(variant) or name


def _run_key(case: str, variant: str) -> str:
    return f"{case}__{variant}"


def until_hand_stops(columns: dict, params: Parameters) -> np.ndarray:
    """The samples of a cycle up to the hand's stop at its end: those after the last reversal's half rounding
    before the end where the rack still moves (|tanh(beta v)| >= 0.99) or before. At rest the smoothed friction
    tanh(beta v) vanishes, so the torque falls (16.7 to 12.8 N m unladen) along a vertical line at rack 0 that
    is the friction model's artefact, not a measurement; the torque-rack figures end their curves before it."""
    t = np.asarray(columns["time_s"], dtype=float)
    level = np.abs(pm.tanh(params["steering.friction_smoothing"] * np.asarray(columns["rack_speed_m_s"])))
    stopping = t > t[-1] - _times(params)["half_rounding"]
    return ~(stopping & (level < STEP_LEVEL))


def _torque_against_rack(params, runs, data, labels, title, ylabel="handwheel torque (N m)"):
    from ..plotting import COLOURS, new_figure  # matplotlib only where a figure is drawn

    fig, ax = new_figure(6.5, 4.2)
    for colour, (case, variant) in zip(COLOURS, runs):
        c = data[(case, variant)]
        keep = until_hand_stops(c, params)
        ax.plot(1000 * c["rack_m"][keep], c[TORQUE][keep], color=colour,
                label=_label(params, case, variant, labels))
    ax.axhline(0.0, color="0.5", linewidth=0.6)
    ax.axvline(0.0, color="0.5", linewidth=0.6)
    ax.set_xlabel("rack displacement (mm), positive steering right")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.legend(loc="upper left", fontsize=8)
    ax.text(0.99, 0.02, "curves end as the hand stops at the cycle's end (at rest the smoothed friction vanishes)",
            transform=ax.transAxes, ha="right", va="bottom", fontsize=6.5, color="0.3")
    fig.tight_layout()
    return fig


def _loads_against_rack(params, runs, data, labels):
    from ..plotting import COLOURS, new_figure  # matplotlib only where a figure is drawn

    fig, ax = new_figure(6.5, 4.8)
    for colour, (case, variant) in zip(COLOURS, runs):
        c = data[(case, variant)]
        label = _label(params, case, variant, labels)
        ax.plot(1000 * c["rack_m"], c["load_left_N"], color=colour, label=f"left wheel, {label}")
        ax.plot(1000 * c["rack_m"], c["load_right_N"], color=colour, linestyle="--", label=f"right wheel, {label}")
    ax.set_xlabel("rack displacement (mm), positive steering right")
    ax.set_ylabel("road wheel load (N)")
    ax.set_title("Wheel loads against rack displacement (model; the source's Fig. 13)", fontsize=9)
    # below the axes: inside, any corner covers part of a curve that spans the whole rack travel
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=7, frameon=False)
    fig.tight_layout()
    return fig


def _contributions_over_time(params, c):
    from ..plotting import COLOURS, new_figure  # matplotlib only where a figure is drawn

    fig, (top, bottom) = new_figure(6.5, 5.5, nrows=2, sharex=True)
    t = c["time_s"]
    present = [n for n in ("tyre_friction", "rack_friction", "lifting", "carcass_compliance", "hooke_joint", "inertia")
               if f"contrib_{n}_Nm" in c]
    # The Hooke joint and the carcass apply no force to the rack: the joint scales every share, the carcass passes
    # the tyre moment on. Their zero bands are left out of the stack and named in a note.
    names = [n for n in present if np.max(np.abs(c[f"contrib_{n}_Nm"])) > 1e-9]
    silent = [EFFECT_LABELS[n] for n in present if n not in names]
    series = [c[f"contrib_{n}_Nm"] for n in names]
    positive = np.zeros_like(t)
    negative = np.zeros_like(t)
    for colour, name, values in zip(COLOURS, names, series):
        up = np.clip(values, 0, None)
        down = np.clip(values, None, 0)
        top.fill_between(t, positive, positive + up, color=colour, linewidth=0, label=EFFECT_LABELS[name])
        top.fill_between(t, negative, negative + down, color=colour, linewidth=0)
        positive += up
        negative += down
    top.plot(t, c[TORQUE], color="k", linewidth=0.9, label="handwheel torque")
    top.set_ylabel("torque at the handwheel (N m)")
    top.set_title("Contributions of the mechanisms to the handwheel torque (nominal case)", fontsize=9)
    top.legend(loc="lower left", fontsize=7, ncol=2)
    if silent:
        top.text(0.99, 0.02, "no direct share: " + ", ".join(silent), transform=top.transAxes, ha="right",
                 va="bottom", fontsize=7, color="0.3")
    bottom.plot(t, 1000 * c["rack_m"], color=COLOURS[0])
    bottom.set_ylabel("rack (mm)")
    bottom.set_xlabel("time (s)")
    fig.tight_layout()
    return fig


def _figure_columns(name: str, runs: list[Run], data: dict) -> dict:
    """The plotted data of one figure, on the runs' shared time base."""
    first = data[runs[0]]
    cols: dict[str, np.ndarray] = {"time_s": first["time_s"]}
    for case, variant in runs:
        c = data[(case, variant)]
        key = _run_key(case, variant)
        cols[f"rack_{key}_mm"] = 1000 * c["rack_m"]
        if name == "fig13":
            cols[f"load_left_{key}_N"] = c["load_left_N"]
            cols[f"load_right_{key}_N"] = c["load_right_N"]
        elif name == "figContrib":
            cols[TORQUE] = c[TORQUE]
            for col in c:
                if col.startswith("contrib_"):
                    cols[col] = c[col]
        else:
            cols[f"torque_{key}_Nm"] = c[TORQUE]
    return cols


def _summary(name: str, runs: list[Run], params: Parameters, data: dict) -> dict:
    summaries = {_run_key(case, variant): cycle_summary(data[(case, variant)], params) for case, variant in runs}
    out: dict = {"figure": name, "runs": summaries, "plateau_rack_range_m": list(PLATEAU_RACK_M)}
    if name == "fig14":
        plateau = {variant: summaries[_run_key("unladen", variant)]["plateau_torque_Nm"] for _, variant in runs}
        out["plateau_torque_Nm"] = plateau
        out["tyre_friction_share_from_ablation_Nm"] = plateau["full"] - plateau["no_tyre_friction"]
        out["rack_friction_share_from_ablation_Nm"] = plateau["full"] - plateau["no_rack_friction"]
        out["lifting_alone_plateau_Nm"] = plateau["no_friction"]
    if name in ("fig15", "fig16"):
        offsets = np.array([params.case(case)["extra_offset"] for case, _ in runs])
        plateau = np.array([summaries[_run_key(c, v)]["plateau_torque_Nm"] for c, v in runs])
        near_lock = np.array([summaries[_run_key(c, v)]["torque_near_right_lock_Nm"] for c, v in runs])
        out["extra_offset_m"] = offsets.tolist()
        out["offset_d_m"] = [steer_axis(params, c, "left").offset_d_m for c, _ in runs]
        out["plateau_torque_Nm"] = plateau.tolist()
        out["torque_near_right_lock_Nm"] = near_lock.tolist()
        line = np.column_stack([offsets, np.ones(len(offsets))])  # torque = slope * offset + intercept
        out["plateau_sensitivity_Nm_per_m_offset"] = float(pm.lstsq(line, plateau)[0])
        out["near_lock_sensitivity_Nm_per_m_offset"] = float(pm.lstsq(line, near_lock)[0])
        out["largest_plateau_change_relative"] = float((plateau.max() - plateau.min()) / plateau[0])
    if name in ("fig12", "fig13"):
        out["plateau_torque_Nm"] = {k: s["plateau_torque_Nm"] for k, s in summaries.items()}
    return out


# figure -> plot(params, runs, data, labels)
PLOTTERS = {
    "fig12": lambda p, r, d, lab: _torque_against_rack(
        p, r, d, lab, "Handwheel torque against rack displacement (model; the source's Fig. 12)"),
    "fig13": lambda p, r, d, lab: _loads_against_rack(p, r, d, lab),
    "fig14": lambda p, r, d, lab: _torque_against_rack(p, r, d, lab, "Mechanisms omitted in turn, unladen (model; the source's Fig. 14)"),
    "fig15": lambda p, r, d, lab: _torque_against_rack(
        p, r, d, lab, "Wheel offset varied by spacers, tyres on the ground (model; the source's Fig. 15)"),
    "fig16": lambda p, r, d, lab: _torque_against_rack(
        p, r, d, lab, "Wheel offset varied by spacers, tyres on air bearings (model; the source's Fig. 16)"),
    "figContrib": lambda p, r, d, lab: _contributions_over_time(p, d[r[0]]),
}


def make_model_figure(name: str, runs: list[Run], labels: dict[str, str], parameters_path: str | Path,
                      simulation_csvs: list[str | Path], svg_path: str | Path, csv_path: str | Path,
                      json_path: str | Path) -> None:
    """Write one figure's SVG, plotted data and key numbers from its simulation CSVs (one per run, in order).

    `labels` maps a variant to its legend label (a variant without one is labelled by its case).
    """
    from ..plotting import save_svg  # matplotlib only where a figure is drawn (the Snakefile imports this module)

    params = load_parameters(parameters_path)
    runs = [(str(case), str(variant)) for case, variant in runs]
    if len(simulation_csvs) != len(runs):
        raise ValueError(f"{name}: expected {len(runs)} simulation files, got {len(simulation_csvs)}")
    data = {run: read_csv(path)[0] for run, path in zip(runs, simulation_csvs)}
    header = {
        "figure": f"{name}: multibody model (section 4)",
        "runs": ", ".join(_run_key(c, v) for c, v in runs),
        "units": "time in s, rack in mm, torque at the handwheel in N m, loads in N",
    }
    fig = PLOTTERS[name](params, runs, data, dict(labels))
    write_csv(csv_path, _figure_columns(name, runs, data), header)
    write_json(json_path, _summary(name, runs, params, data))
    save_svg(fig, svg_path)
