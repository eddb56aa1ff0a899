"""Creeping over speed and tyre: how much of its standstill moment the rolling tyre keeps, and whether it or the
rack's friction carries more of the parking torque, over the turn-slip slope q_Dz8 at 1, 3 and 5 km/h.

The paper's car without assist runs the source's cycle, unladen on the ground, with the rolling tyre (turn_slip) at
each creeping speed and each |q_Dz8| of a geometric grid over the quantity's range (0.01 to 1). On the plateau
(parksteer.figures.assist_study.shares) the tyre's term is the tyre_friction and turn_slip terms together, and

    kept(q, v) = tyre term at (q, v) / tyre term at standstill,   share(q, v) = term / road torque.

The tyre's term grows with q_Dz8 at every speed while the rack friction's is constant, so the shares cross once at
most: the crossover q*(v) is found by bisection in log q_Dz8 (a fixed count of halvings), none where the tyre stays
below (or above) over the whole range. The assumed band of q_Dz8 and the one passenger-car tyre in it come from
``parksteer/data/published_loads.toml`` ([spin_slope]); the study reports the shares at those values and their side
of the crossover (docs/assist.md, "Parking while the car creeps").

Numbers on this path reach a checksummed figure: elementwise arithmetic, means, extrema and a bisection of fixed
count only.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import portable as pm
from ..model.numeric.simulate import SimulationResult, simulate
from ..parameters import Parameters, load_parameters
from ..sweep.assist_sizing import published_loads
from ..tables import write_csv, write_json
from ..vehicle import CREEPING_EFFECTS, creeping_overrides
from .assist_study import CASE, SPIN_SLOPE_KEY, peak_rack_force_N, shares

CREEP_SPEEDS_KMH = (1.0, 3.0, 5.0)
Q_RANGE = (0.01, 1.0)  # the grid's and the bisection's ends, inside the quantity's bounds (0, 1]
GRID_POINTS = 25
BISECTIONS = 20  # halvings of log(1 / 0.01): q* to within a factor exp(4.6 / 2^20), 4e-6 of itself


def spin_band() -> dict:
    """The assumed band of |q_Dz8|, the MF default and the passenger-car value, with their sources."""
    return dict(published_loads()["spin_slope"])


def q_grid() -> list[float]:
    """GRID_POINTS values of q_Dz8 evenly spaced in log over Q_RANGE (the portable log and exp: the C library's
    differ in the last bit between processors, and the values are the simulations' inputs)."""
    low, high = (pm.log(float(q)) for q in Q_RANGE)
    inner = [pm.exp(low + (high - low) * i / (GRID_POINTS - 1)) for i in range(1, GRID_POINTS - 1)]
    return [float(Q_RANGE[0]), *inner, float(Q_RANGE[1])]  # the range's ends as written


def plateau_terms(result: SimulationResult, params: Parameters) -> dict:
    """The plateau's tyre term (friction moment with the turn-slip factor) and the tyre's, rack friction's and
    lifting's shares of the road torque."""
    p = shares(result.columns, params)["plateau"]
    terms, road = p["mechanisms_Nm"], p["road_torque_Nm"]
    tyre = terms["tyre_friction"] + terms.get("turn_slip", 0.0)
    return {"tyre_Nm": tyre, "tyre_share": tyre / road, "rack_friction_share": terms["rack_friction"] / road,
            "lifting_share": terms["lifting"] / road}


def creep_study(params: Parameters, case: str = CASE, run=simulate, progress=None) -> dict:
    """Every run of the study and the numbers the paper quotes (module docstring), for the car of `params` in load
    case `case` (the paper's car unladen by default)."""
    def at(q: float, speed: float) -> SimulationResult:
        return run(case, effects=CREEPING_EFFECTS, params=params,
                   overrides={**creeping_overrides(speed), SPIN_SLOPE_KEY: q})

    band = spin_band()
    standstill = plateau_terms(run(case, effects=CREEPING_EFFECTS, overrides=creeping_overrides(0.0), params=params),
                               params)
    grid = q_grid()
    out: dict = {"case": case, "speeds_kmh": list(CREEP_SPEEDS_KMH), "q_dz8": grid,
                 "standstill": {k: v for k, v in standstill.items()},
                 "band": {"q_dz8": list(band["band"]), "mf_default": band["mf_default"],
                          "passenger_car": band["passenger_car"], "passenger_car_tyre": band["passenger_car_tyre"],
                          "passenger_car_source": band["passenger_car_source"],
                          "passenger_car_access": band["passenger_car_access"], "what": band["band_what"]},
                 "kept": {}, "tyre_share": {}, "rack_friction_share": {}, "lifting_share": {},
                 "peak_rack_force_N": {}, "crossover_q_dz8": {}, "at": {}}
    marks = sorted({band["band"][0], band["passenger_car"], band["band"][1]})
    for speed in CREEP_SPEEDS_KMH:
        key = f"{speed:g}"
        if progress:
            progress(f"creeping at {speed:g} km/h over q_Dz8 {Q_RANGE[0]:g}-{Q_RANGE[1]:g}")
        runs = [at(q, speed) for q in grid]
        terms = [plateau_terms(r, params) for r in runs]
        out["kept"][key] = [t["tyre_Nm"] / standstill["tyre_Nm"] for t in terms]
        for name in ("tyre_share", "rack_friction_share", "lifting_share"):
            out[name][key] = [t[name] for t in terms]
        out["peak_rack_force_N"][key] = [peak_rack_force_N(r) for r in runs]
        out["crossover_q_dz8"][key] = crossover(lambda q: _margin(plateau_terms(at(q, speed), params)))
        out["at"][key] = {}
        for q in marks:
            t = plateau_terms(at(q, speed), params)
            out["at"][key][f"{q:g}"] = {"kept": t["tyre_Nm"] / standstill["tyre_Nm"], "tyre_share": t["tyre_share"],
                                        "rack_friction_share": t["rack_friction_share"],
                                        "tyre_below_rack_friction": t["tyre_share"] < t["rack_friction_share"]}
    out["conclusion"] = conclusion(out)
    return out


def _margin(terms: dict) -> float:
    """The tyre's share less the rack friction's: positive where the tyre carries more."""
    return terms["tyre_share"] - terms["rack_friction_share"]


def crossover(margin, low: float = Q_RANGE[0], high: float = Q_RANGE[1], halvings: int = BISECTIONS) -> float | None:
    """The q_Dz8 in [low, high] where `margin` (increasing in q_Dz8) changes sign, by bisection in log q_Dz8 (the
    geometric midpoint of the bracket after `halvings` halvings); None if it has one sign over the whole range."""
    m_low, m_high = margin(low), margin(high)
    if m_low >= 0.0 or m_high <= 0.0:
        return None
    for _ in range(halvings):
        mid = math.sqrt(low * high)
        if margin(mid) < 0.0:
            low = mid
        else:
            high = mid
    return math.sqrt(low * high)


def conclusion(out: dict) -> dict:
    """Per speed, where the assumed band lies against the crossover: "tyre_below" (the whole band below it: rack
    friction carries more), "tyre_above" (the whole band above it), or "conditional" (the crossover inside the
    band); and the side the passenger-car value lies on."""
    low, high = out["band"]["q_dz8"]
    car = out["band"]["passenger_car"]
    result = {}
    for key, q in out["crossover_q_dz8"].items():
        below_at = {k: v["tyre_below_rack_friction"] for k, v in out["at"][key].items()}
        if below_at[f"{low:g}"] and below_at[f"{high:g}"]:
            where = "tyre_below"
        elif not below_at[f"{low:g}"] and not below_at[f"{high:g}"]:
            where = "tyre_above"
        else:
            where = "conditional"
        result[key] = {"band": where, "passenger_car_tyre_below": below_at[f"{car:g}"], "crossover_q_dz8": q}
    return result


def summary_lines(out: dict) -> list[str]:
    """The study as a reader's table: per speed, the kept share and the tyre's and rack friction's shares at the
    band's ends and the passenger-car value, the crossover and the verdict."""
    band = out["band"]
    access = band["passenger_car_access"].split(":")[0]
    lines = [f"creeping without assist over |q_Dz8| (assumed band {band['q_dz8'][0]:g}-{band['q_dz8'][1]:g}; "
             f"a {band['passenger_car_tyre']}: {band['passenger_car']:g}, {access})",
             f"standstill: tyre {100 * out['standstill']['tyre_share']:.1f} %, rack friction "
             f"{100 * out['standstill']['rack_friction_share']:.1f} % of the plateau's road torque",
             "speed km/h  q_Dz8  tyre moment kept %  tyre share %  rack friction share %"]
    for speed in out["speeds_kmh"]:
        for q, row in out["at"][f"{speed:g}"].items():
            lines.append(f"{speed:10g}  {float(q):5.3f}  {100 * row['kept']:18.1f}  {100 * row['tyre_share']:12.1f}  "
                         f"{100 * row['rack_friction_share']:21.1f}")
    words = {"conditional": "conditional on the tyre (the crossover inside the band)",
             "tyre_below": "rack friction above the tyre over the whole band",
             "tyre_above": "the tyre above rack friction over the whole band"}
    for speed in out["speeds_kmh"]:
        key = f"{speed:g}"
        q = out["crossover_q_dz8"][key]
        where = (f"tyre and rack friction carry alike at q_Dz8 {q:.3f}" if q is not None else
                 f"no crossover in {Q_RANGE[0]:g}-{Q_RANGE[1]:g}")
        lines.append(f"{speed:g} km/h: {where}; {words[out['conclusion'][key]['band']]}")
    return lines


def creep_table(out: dict) -> dict[str, list]:
    """One row per speed and q_Dz8 of the grid."""
    rows: dict[str, list] = {"speed_kmh": [], "q_dz8": [], "tyre_moment_kept": [], "tyre_share": [],
                             "rack_friction_share": [], "lifting_share": [], "peak_rack_force_N": []}
    for speed in out["speeds_kmh"]:
        key = f"{speed:g}"
        for i, q in enumerate(out["q_dz8"]):
            rows["speed_kmh"].append(speed)
            rows["q_dz8"].append(q)
            rows["tyre_moment_kept"].append(out["kept"][key][i])
            for name in ("tyre_share", "rack_friction_share", "lifting_share", "peak_rack_force_N"):
                rows[name].append(out[name][key][i])
    return rows


def plot_creep(out: dict):
    from ..plotting import COLOURS, new_figure  # matplotlib only where a figure is drawn

    fig, (left, right) = new_figure(9.0, 3.8, ncols=2)
    q = np.asarray(out["q_dz8"])
    low, high = out["band"]["q_dz8"]
    car = out["band"]["passenger_car"]
    for ax in (left, right):
        ax.axvspan(low, high, color="0.85", linewidth=0.0, zorder=0)
        ax.axvline(car, color="0.4", linewidth=0.8, linestyle=":", zorder=1)
        ax.set_xscale("log")
        ax.set_xlabel("turn-slip slope |q_Dz8|")
        ax.set_xlim(q[0], q[-1])
    for colour, speed in zip(COLOURS, out["speeds_kmh"]):
        key = f"{speed:g}"
        left.plot(q, 100.0 * np.asarray(out["kept"][key]), color=colour, linewidth=1.0, label=f"{speed:g} km/h")
        right.plot(q, 100.0 * np.asarray(out["tyre_share"][key]), color=colour, linewidth=1.0,
                   label=f"tyre, {speed:g} km/h")
        right.plot(q, 100.0 * np.asarray(out["rack_friction_share"][key]), color=colour, linewidth=1.0,
                   linestyle="--", label=f"rack friction, {speed:g} km/h")
        cross = out["crossover_q_dz8"][key]
        if cross is not None:
            at = float(np.interp(pm.log(float(cross)), pm.log(np.asarray(q, dtype=float)),
                                 np.asarray(out["tyre_share"][key])))
            right.plot([cross], [100.0 * at], marker="o", markerfacecolor="none", color=colour, linestyle="none")
    left.set_ylabel("tyre moment kept on the plateau (% of standstill)")
    left.set_ylim(0.0, 100.0)
    left.set_title("(a) tyre moment kept; shaded: assumed band; dotted: a 205/60R15", fontsize=8)
    left.legend(loc="upper left", fontsize=7)
    right.set_ylabel("share of the plateau's road torque (%)")
    right.set_ylim(0.0, 115.0)
    right.set_title("(b) tyre (solid) against rack friction (dashed); o: crossover", fontsize=8)
    right.legend(loc="upper center", fontsize=6, ncol=3)
    fig.tight_layout()
    return fig


def make_assist_creep(parameters_path: str | Path, svg_path: str | Path, csv_path: str | Path,
                      json_path: str | Path, progress=None) -> dict:
    """Write the creeping figure (SVG), its table (CSV) and the numbers the paper quotes (JSON)."""
    from ..plotting import save_svg

    params = load_parameters(parameters_path)
    out = creep_study(params, progress=progress)
    header = {"table": "the paper's car without assist, unladen on the ground, creeping at 1, 3 and 5 km/h over the "
                       "turn-slip slope |q_Dz8|: the share of its standstill plateau moment the rolling tyre keeps and "
                       "the mechanisms' shares of the plateau's road torque",
              "peak_rack_force_N": "handwheel torque through the gear, peak over the cycle"}
    write_csv(csv_path, creep_table(out), header)
    save_svg(plot_creep(out), svg_path)
    write_json(json_path, out)
    return out
