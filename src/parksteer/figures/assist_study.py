"""Today's steering on the paper's car: what power assistance and creeping change in the source's conclusions.

The paper's car (the pipeline's parameter file) runs the source's lock-to-lock cycle, unladen on the ground, with
the tyre rolling (the turn_slip effect), without assistance and with the column electric and the hydraulic assist at
their assumed defaults (each default with its range and source in the effect's file, copied into the JSON). It
gives each mechanism's share of the road torque over the plateau and before the right-lock reversal, the driver's
share against 1 / (1 + G); the spread (N m and relative) of the plateau and peak torque over the paper's four wheel
offsets; the peak rack force (N) and the plateau's shares at 0, 1, 3 and 5 km/h, and over the turn-slip slope band
SPIN_SLOPE_BAND; the standstill peak rack force over the tyre-ground friction band
(parksteer.sweep.assist_sizing.FRICTION_BAND) against the published class range
(PUBLISHED_STANDSTILL_RACK_FORCE_N there); and the column assist sized for the pipeline's assist.target_torque
against the model's load and the range's ends (class_load). The shares' definition and what the study finds:
docs/assist.md, "The paper's car: what assistance and creeping change".

Numbers on this path reach a checksummed figure: elementwise arithmetic, means and extrema only.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..model.numeric.simulate import SimulationResult, simulate
from ..model.symbolic.components import discover_effects, with_effect_quantities
from ..parameters import Parameters, load_parameters
from ..sweep.assist_sizing import (FRICTION_BAND, PUBLISHED_STANDSTILL_RACK_FORCE_N, SPEEDS_KMH, published_loads,
                                   rack_force_without_rack_friction_N, size_for_rack_force)
from ..tables import write_csv, write_json
from ..vehicle import ASSIST_EFFECTS, ASSISTED_EFFECTS, CREEPING_EFFECTS, creeping_overrides
from .assist_gear import back_driven, gear_numbers
from .model import OFFSET_CASES, _at, _times, plateau_mask, until_hand_stops
from ..names import TORQUE

CASE = "unladen"
ASSISTS = ("column", "hydraulic")  # the kinds studied besides the car without assistance
# The assumed values the paper quotes, by assist kind (each effect's own quantities, with their sources).
QUOTED = {
    "column": ("gain", "dead_band", "torsion_bar_stiffness", "reduction_ratio", "efficiency", "back_efficiency",
               "motor_torque_limit", "torque_constant"),
    "hydraulic": ("valve_slope", "dead_band", "torsion_bar_stiffness", "piston_area", "relief_pressure"),
}
# The rolling tyre's assumed coefficients the paper quotes (MF 6.1 defaults, in the turn_slip effect's file).
TURN_SLIP_QUOTED = ("spin_slope_coefficient", "camber_reduction")
# The band of |q_Dz8| (turn_slip.spin_slope_coefficient) the creeping result is shown over, car without assist: the
# assumed band's ends and the one passenger-car tyre found inside it (published_loads.toml, [spin_slope]). The larger
# q_Dz8, the more of its standstill moment the rolling tyre keeps.
_SPIN = published_loads()["spin_slope"]
SPIN_SLOPE_BAND = (_SPIN["band"][0], _SPIN["passenger_car"], _SPIN["band"][1])
SPIN_SLOPE_KEY = "turn_slip.spin_slope_coefficient"


def _effects(kind: str | None) -> str:
    return CREEPING_EFFECTS if kind is None else ASSISTED_EFFECTS[kind]


def _defaults(effect: str, keys: tuple[str, ...]) -> dict:
    """The effect's quantities `keys` at their defaults: {key: {value, unit, source}}."""
    quantities = {q.name: q for q in discover_effects()[effect].quantities}
    return {key: {"value": float(quantities[key].default), "unit": quantities[key].unit,
                  "source": quantities[key].source} for key in keys}


def assumed_values(kind: str) -> dict:
    """The assist's quoted quantities at their defaults: {key: {value, unit, source}}."""
    return _defaults(ASSIST_EFFECTS[kind], QUOTED[kind])


def turn_slip_values() -> dict:
    """The rolling tyre's quoted coefficients at their defaults: {key: {value, unit, source}}."""
    return _defaults("turn_slip", TURN_SLIP_QUOTED)


def equivalent_gain(kind: str, params: Parameters) -> float:
    """The boost gain G of the assist at its defaults: the gain itself (electric), A k_v / G_hr (hydraulic)."""
    values = {k: v["value"] for k, v in assumed_values(kind).items()}
    if kind == "hydraulic":
        return values["piston_area"] * values["valve_slope"] / float(params["steering.handwheel_to_rack_ratio"])
    return values["gain"]


def assist_columns(columns: dict) -> list[str]:
    """The contribution columns of an assist (the gear's own push), by the effects' names."""
    return [f"contrib_{name}_Nm" for name in ASSIST_EFFECTS.values() if f"contrib_{name}_Nm" in columns]


def shares(columns: dict, params: Parameters) -> dict:
    """Each mechanism's term of the handwheel torque and its share of the road torque, over the plateau and just
    before the right-lock reversal; the driver's and the assist's shares of the road torque (module docstring)."""
    plateau = plateau_mask(columns, params)
    t = _times(params)
    before_right = t["right_lock"] - t["half_rounding"]
    assists = assist_columns(columns)
    mechanisms = [k for k in columns if k.startswith("contrib_") and k.endswith("_Nm") and k not in assists]
    out = {}
    for where, value in (("plateau", lambda name: float(np.mean(columns[name][plateau]))),
                         ("near_right_lock", lambda name: _at(columns, name, before_right))):
        terms = {k[len("contrib_"):-len("_Nm")]: value(k) for k in mechanisms}
        road = sum(terms.values())
        assist = -sum(value(k) for k in assists)
        driver = value(TORQUE)
        out[where] = {
            "road_torque_Nm": road,
            "driver_torque_Nm": driver,
            "assist_torque_Nm": assist,
            "driver_share": driver / road,
            "assist_share": assist / road,
            "mechanisms_Nm": terms,
            "mechanism_shares": {name: term / road for name, term in terms.items()},
        }
    return out


def peak_rack_force_N(result: SimulationResult) -> float:
    """The peak force on the rack over the cycle: with an assist the simulation's rack_force_N (pinion and assist
    together), without one the handwheel torque through the gear."""
    c = result.columns
    if "rack_force_N" in c:
        force = c["rack_force_N"]
    else:
        per_rack = result.outputs()["column_angle_per_rack_rad_per_m"]
        force = c[TORQUE] * per_rack
    return float(np.max(np.abs(force)))


def _plateau_by_speed(plateaus: list[dict]) -> dict:
    """The plateau's road and driver torque and the mechanisms' shares at each speed; the tyre's share is its
    friction moment with the turn-slip factor applied (turn_slip's own term is the moment the rolling removes)."""
    out = {"plateau_road_torque_Nm": [p["road_torque_Nm"] for p in plateaus],
           "plateau_driver_torque_Nm": [p["driver_torque_Nm"] for p in plateaus]}
    share = {name: [] for name in ("tyre", "rack_friction", "lifting")}
    for p in plateaus:
        m = p["mechanism_shares"]
        share["tyre"].append(m["tyre_friction"] + m.get("turn_slip", 0.0))
        share["rack_friction"].append(m["rack_friction"])
        share["lifting"].append(m["lifting"])
    out["plateau_shares"] = share
    return out


def _tyre_term(result: SimulationResult, params: Parameters) -> float:
    """The tyre's term of the plateau's handwheel torque: its friction moment with the turn-slip factor applied."""
    terms = shares(result.columns, params)["plateau"]["mechanisms_Nm"]
    return terms["tyre_friction"] + terms.get("turn_slip", 0.0)


def class_load(standstill: SimulationResult, params: Parameters, target_torque_Nm: float) -> dict:
    """The column assist at its defaults sized, quasi-statically, to leave the driver `target_torque_Nm` against
    the model's standstill peak rack force and against the ends of the published class range, through the car's gear
    at the standstill peak (parksteer.sweep.assist_sizing.size_for_rack_force); with the defaults' motor limit."""
    name = ASSIST_EFFECTS["column"]
    c = standstill.columns
    per_rack = standstill.outputs()["column_angle_per_rack_rad_per_m"]
    force = c[TORQUE] * per_rack
    peak = int(np.argmax(np.abs(force)))
    at_peak = float(np.abs(per_rack[peak]))
    rows = [size_for_rack_force(name, params, f, at_peak, target_torque_Nm)
            for f in (float(np.abs(force[peak])), *PUBLISHED_STANDSTILL_RACK_FORCE_N)]
    return {"target_torque_Nm": target_torque_Nm, "rack_force_N": [r.rack_force_N for r in rows],
            "motor_torque_Nm": [r.motor_torque_Nm for r in rows],
            "motor_current_A": [r.motor_current_A for r in rows],
            "motor_torque_limit_Nm": assumed_values("column")["motor_torque_limit"]["value"]}


def _spread(values: dict) -> float:
    return max(values.values()) - min(values.values())


def assist_study(params: Parameters, target_torque_Nm: float, run=simulate, progress=None) -> dict:
    """Every run of the study and the numbers the paper quotes (module docstring); `target_torque_Nm` is the driver's
    torque the class-load sizing keeps (the pipeline's config, assist.target_torque). `run` is the simulation
    (simulate's signature); `progress`, if given, is called with a line per run."""
    params = with_effect_quantities(params)  # the assists' own quantities, with their assumed defaults
    results = _study_runs(params, run, progress or (lambda line: None))
    numbers: dict = {"case": CASE, "surface": "ground", "speeds_kmh": list(SPEEDS_KMH), "offset_cases": list(OFFSET_CASES),
                     "turn_slip": turn_slip_values(), "assists": {}, "runs": {}}
    for kind in ASSISTS:
        gain = equivalent_gain(kind, params)
        numbers["assists"][kind] = {"effect": ASSIST_EFFECTS[kind], "assumed": assumed_values(kind),
                                    "gain": gain, "driver_share_limit": 1.0 / (1.0 + gain)}
    for kind in (None, *ASSISTS):
        numbers["runs"][kind or "none"] = _assist_numbers(kind, results, params)
    force = numbers["runs"]["none"]["speeds"]["peak_rack_force_N"]
    numbers["rack_force_fall_at_5_kmh"] = 1.0 - force[-1] / force[0]
    numbers["friction_band"] = _friction_band(results, params)
    numbers["class_load"] = class_load(results[(None, CASE, 0.0)], params, target_torque_Nm)
    numbers["spin_slope_band"] = _spin_slope_band(results, params, force[0])
    numbers["back_driven"] = back_driven(results[("column", CASE, 0.0)], params)
    numbers["gear"] = gear_numbers()
    numbers["_results"] = results
    return numbers


def _study_runs(params: Parameters, run, progress) -> dict:
    """The study's simulations by key: (assist kind or None, case, speed in km/h) for each assist's offsets and
    speeds, ("friction", coefficient) over the friction band, ("spin_slope", q_Dz8, speed) over the spin-slope band."""
    results: dict = {}
    for kind in (None, *ASSISTS):
        for case, speed in [(case, 0.0) for case in OFFSET_CASES] + [(CASE, speed) for speed in SPEEDS_KMH[1:]]:
            progress(f"assist {kind or 'none'}, {case}, {speed:g} km/h")
            results[(kind, case, speed)] = run(case, effects=_effects(kind), overrides=creeping_overrides(speed),
                                               params=params)
    for friction in FRICTION_BAND:
        progress(f"assist none, {CASE}, 0 km/h, tyre friction {friction:g}")
        results[("friction", friction)] = run(CASE, effects=_effects(None), params=params, overrides={
            **creeping_overrides(0.0), "tyre.friction_coefficient": friction})
    for q in SPIN_SLOPE_BAND:
        for speed in SPEEDS_KMH[1:]:
            progress(f"assist none, {CASE}, {speed:g} km/h, q_Dz8 {q:g}")
            results[("spin_slope", q, speed)] = run(CASE, effects=_effects(None), params=params, overrides={
                **creeping_overrides(speed), SPIN_SLOPE_KEY: q})
    return results


def _assist_numbers(kind: str | None, results: dict, params: Parameters) -> dict:
    """One assist's (None: without) peak torque, shares, spread over the offsets and numbers at each speed."""
    standstill = {case: results[(kind, case, 0.0)].columns for case in OFFSET_CASES}
    plateau = {case: float(np.mean(c[TORQUE][plateau_mask(c, params)])) for case, c in standstill.items()}
    peak = {case: float(np.max(np.abs(c[TORQUE]))) for case, c in standstill.items()}
    return {
        "peak_torque_Nm": peak[CASE],
        "shares": shares(standstill[CASE], params),
        "offsets": {"plateau_torque_Nm": plateau, "peak_torque_Nm": peak,
                    "plateau_spread_Nm": _spread(plateau), "peak_spread_Nm": _spread(peak),
                    "plateau_spread_relative": _spread(plateau) / plateau[CASE],
                    "peak_spread_relative": _spread(peak) / peak[CASE]},
        "speeds": {
            "peak_rack_force_N": [peak_rack_force_N(results[(kind, CASE, s)]) for s in SPEEDS_KMH],
            "peak_handwheel_torque_Nm": [float(np.max(np.abs(results[(kind, CASE, s)].columns[TORQUE])))
                                         for s in SPEEDS_KMH],
            **_plateau_by_speed([shares(results[(kind, CASE, s)].columns, params)["plateau"] for s in SPEEDS_KMH]),
        },
    }


def _friction_band(results: dict, params: Parameters) -> dict:
    """The standstill peak rack force (with and without the rack's friction) over the friction band, against the
    published class range."""
    band = [peak_rack_force_N(results[("friction", f)]) for f in FRICTION_BAND]
    low, high = PUBLISHED_STANDSTILL_RACK_FORCE_N
    return {
        "friction": list(FRICTION_BAND), "peak_rack_force_N": band,
        "peak_rack_force_without_rack_friction_N": [
            float(np.max(np.abs(rack_force_without_rack_friction_N(results[("friction", f)]))))
            for f in FRICTION_BAND],
        "rack_friction_force_N": float(params["steering.rack_friction_force"]),
        "published_standstill_rack_force_N": [low, high],
        "below_published_at": [f for f, force in zip(FRICTION_BAND, band) if force < low],
        "within_published_at": [f for f, force in zip(FRICTION_BAND, band) if low <= force <= high],
        "above_published_at": [f for f, force in zip(FRICTION_BAND, band) if force > high]}


def _spin_slope_band(results: dict, params: Parameters, standstill_force_N: float) -> dict:
    """The car without assist at each speed over the spin-slope band: peak rack force, the share of its standstill
    tyre moment the rolling tyre keeps, the plateau's shares."""
    standstill_tyre = _tyre_term(results[(None, CASE, 0.0)], params)
    return {
        "q_dz8": list(SPIN_SLOPE_BAND),
        "peak_rack_force_N": {f"{q:g}": [standstill_force_N, *(peak_rack_force_N(results[("spin_slope", q, s)])
                                                               for s in SPEEDS_KMH[1:])] for q in SPIN_SLOPE_BAND},
        "tyre_moment_kept": {f"{q:g}": [1.0, *(_tyre_term(results[("spin_slope", q, s)], params) / standstill_tyre
                                               for s in SPEEDS_KMH[1:])] for q in SPIN_SLOPE_BAND},
        "plateau_shares": {f"{q:g}": _plateau_by_speed(
            [shares(results[(None, CASE, 0.0)].columns, params)["plateau"],
             *(shares(results[("spin_slope", q, s)].columns, params)["plateau"] for s in SPEEDS_KMH[1:])]
        )["plateau_shares"] for q in SPIN_SLOPE_BAND},
    }


def study_table(numbers: dict) -> dict[str, list]:
    """One row per run: assist, case, speed, peak and plateau torque, peak rack force."""
    rows: dict[str, list] = {"assist": [], "case": [], "speed_kmh": [], "plateau_torque_Nm": [],
                             "peak_torque_Nm": [], "peak_rack_force_N": []}
    for kind, run in numbers["runs"].items():
        for case in numbers["offset_cases"]:
            rows["assist"].append(kind)
            rows["case"].append(case)
            rows["speed_kmh"].append(0.0)
            rows["plateau_torque_Nm"].append(run["offsets"]["plateau_torque_Nm"][case])
            rows["peak_torque_Nm"].append(run["offsets"]["peak_torque_Nm"][case])
            rows["peak_rack_force_N"].append(run["speeds"]["peak_rack_force_N"][0] if case == numbers["case"]
                                             else float("nan"))
        for i, speed in enumerate(numbers["speeds_kmh"][1:], start=1):
            rows["assist"].append(kind)
            rows["case"].append(numbers["case"])
            rows["speed_kmh"].append(speed)
            rows["plateau_torque_Nm"].append(float("nan"))
            rows["peak_torque_Nm"].append(run["speeds"]["peak_handwheel_torque_Nm"][i])
            rows["peak_rack_force_N"].append(run["speeds"]["peak_rack_force_N"][i])
    return rows


def plot_study(numbers: dict, params: Parameters):
    from ..plotting import COLOURS, new_figure  # matplotlib only where a figure is drawn

    fig, (left, right) = new_figure(9.0, 3.8, ncols=2)
    names = {"none": "without assist", "column": "column electric assist", "hydraulic": "hydraulic assist"}
    styles = {"none": ("-", "o"), "column": ("--", "s"), "hydraulic": (":", "^")}  # the assisted curves nearly meet
    for colour, kind in zip(COLOURS, (None, *ASSISTS)):
        c = numbers["_results"][(kind, CASE, 0.0)].columns
        keep = until_hand_stops(c, params)
        left.plot(1000 * c["rack_m"][keep], c[TORQUE][keep], color=colour, linewidth=1.0,
                  linestyle=styles[kind or "none"][0], label=names[kind or "none"])
    left.axhline(0.0, color="0.5", linewidth=0.6)
    left.axvline(0.0, color="0.5", linewidth=0.6)
    left.set_xlabel("rack displacement (mm), positive steering right")
    left.set_ylabel("handwheel torque (N m)")
    left.set_title("(a) unladen, on the ground, at standstill", fontsize=9)
    left.legend(loc="upper left", fontsize=7)
    for colour, kind in zip(COLOURS, ("none", *ASSISTS)):
        right.plot(numbers["speeds_kmh"], np.asarray(numbers["runs"][kind]["speeds"]["peak_rack_force_N"]) / 1000.0,
                   marker=styles[kind][1], markerfacecolor="none", linestyle=styles[kind][0], color=colour,
                   linewidth=1.0, label=names[kind])
    spin = numbers["spin_slope_band"]
    low, high = (np.asarray(spin["peak_rack_force_N"][f"{q:g}"]) / 1000.0 for q in (SPIN_SLOPE_BAND[0],
                                                                                   SPIN_SLOPE_BAND[-1]))
    right.fill_between(numbers["speeds_kmh"], low, high, color=COLOURS[0], alpha=0.15, linewidth=0.0,
                       label=f"without assist, q_Dz8 {SPIN_SLOPE_BAND[0]:g}-{SPIN_SLOPE_BAND[-1]:g}")
    right.set_xlabel("vehicle speed (km/h)")
    right.set_ylabel("peak rack force over the cycle (kN)")
    right.set_ylim(bottom=0.0)
    right.set_title("(b) creeping (turn slip, q_Dz8 0.05; shaded 0.05-0.5)", fontsize=9)
    right.legend(loc="lower left", fontsize=7)
    fig.tight_layout()
    return fig


def make_assist_study(parameters_path: str | Path, svg_path: str | Path, csv_path: str | Path,
                      json_path: str | Path, target_torque_Nm: float, progress=None) -> dict:
    """Write the study's figure (SVG), its table (CSV) and the numbers the paper quotes (JSON)."""
    from ..plotting import save_svg

    params = load_parameters(parameters_path)
    numbers = assist_study(params, target_torque_Nm, progress=progress)
    header = {"table": "the paper's car over the lock-to-lock cycle without and with each assist at its assumed "
                       "defaults: the four wheel offsets at standstill, the unladen car at creeping speeds",
              "peak_rack_force_N": "pinion and assist together on the rack; given for the unladen car"}
    write_csv(csv_path, study_table(numbers), header)
    save_svg(plot_study(numbers, params), svg_path)
    quoted = {k: v for k, v in numbers.items() if k != "_results"}
    write_json(json_path, quoted)
    return quoted
