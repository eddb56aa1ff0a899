"""The assist sizing study's outputs: its table, handwheel torque against rack with and without the assist, and the
peak rack force against speed (:mod:`parksteer.sweep.assist_sizing`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import COLOURS, new_figure, save_svg
from ..sweep.assist_sizing import SizingStudy
from ..tables import write_csv
from ..names import TORQUE

TABLE = "sizing.csv"
TORQUE_FIGURE = "torque_against_rack.svg"
FORCE_FIGURE = "rack_force_against_speed.svg"


def write_sizing(study: SizingStudy, out_dir: str | Path, vehicle: str) -> list[Path]:
    """Write the table and both figures of `study` into `out_dir` under their usual names; return their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / TABLE, out / TORQUE_FIGURE, out / FORCE_FIGURE]
    write_sizing_files(study, vehicle, *paths)
    return paths


def write_sizing_files(study: SizingStudy, vehicle: str, table: str | Path, torque_svg: str | Path,
                       force_svg: str | Path) -> None:
    """Write the table (CSV), the handwheel torque against rack and the peak rack force against speed (SVG)."""
    header = {"vehicle": vehicle, "case": study.case, "assist": study.assist,
              "target_torque_Nm": f"{study.target_torque_Nm:g}",
              "demand": "peak assist at its point of action: N m at column or pinion, N at the rack",
              "check": "peak_handwheel_assisted_Nm: the cycle run again with the assist sized (gain, limit x 1.1)"}
    write_csv(table, study.columns(), header)

    fig, ax = new_figure(6.0, 4.0)
    for label, result, colour in (("without assist", study.standstill_manual, COLOURS[0]),
                                  (f"with {study.assist}", study.standstill_assisted, COLOURS[1])):
        c = result.columns
        ax.plot(c["rack_m"] * 1000.0, c[TORQUE], color=colour, label=label)
    for sign in (-1, 1):
        ax.axhline(sign * study.target_torque_Nm, color=COLOURS[7], linewidth=0.8, linestyle="--")
    ax.set_xlabel("rack travel (mm)")
    ax.set_ylabel("handwheel torque (N m)")
    ax.set_title(f"{vehicle}, {study.case}: lock to lock at standstill, target \u00b1{study.target_torque_Nm:g} N m")
    ax.legend(loc="upper left")
    save_svg(fig, torque_svg)

    columns = study.columns()
    fig, ax = new_figure(6.0, 4.0)
    ax.plot(columns["speed_kmh"], columns["peak_rack_force_N"] / 1000.0, marker="o", color=COLOURS[0])
    ax.set_xlabel("vehicle speed (km/h)")
    ax.set_ylabel("peak rack force (kN)")
    ax.set_ylim(0.0, 1.1 * float(np.max(columns["peak_rack_force_N"])) / 1000.0)
    ax.set_title(f"{vehicle}, {study.case}: peak rack force over the lock-to-lock cycle")
    save_svg(fig, force_svg)
