"""Rivals of lifting: which of the paper's tests tells each from lifting, and which cannot.

Each rival effect of the library (:mod:`parksteer.model.symbolic.effects`) is matched to lifting's rise toward lock
(near-lock torque less plateau, N m) in the unladen test on the ground by a secant search on its strength within its
bounds, then simulated in the source's four tests (unladen and part laden on the ground, unladen on air bearings,
unladen with the 68.5 mm spacers), added to the paper's model with lifting kept. A rival that does not rise is
reported ``no rise``, one that cannot reach lifting's rise ``at bound``; the test where the rises differ most
separates it from lifting when the difference exceeds one step of the source's 8-bit torque converter (the
parameter file's ``synthetic`` full scale and bits). Why the rise and how the search runs: docs/model.md, "Rivals
of lifting".
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..model.symbolic.components import discover_effects, strength_parameter
from ..model.symbolic.rivals import chosen_rivals
from ..parameters import Parameters, load_parameters
from ..tables import write_csv, write_json
from .model import cycle_summary

# The matched test, then the source's other tests: (key, case, surface, label).
TESTS = (
    ("unladen_ground", "unladen", "ground", "unladen, ground"),
    ("part_laden_ground", "part_laden", "ground", "part laden, ground"),
    ("unladen_air", "unladen", "air_bearing", "unladen, air bearings"),
    ("spacer_68_5_ground", "offset_68_5mm", "ground", "68.5 mm spacers, ground"),
)
MATCH_RELATIVE = 0.01  # the search stops when the matched torque is within 1 % of lifting's
MATCH_STEPS = 6
# A rival whose rise toward lock at its probe strength is below this fraction of lifting's does not rise toward
# lock (its torque is a reversal transient or a uniform offset that the calibration absorbs): it is reported as
# such, not matched.
NO_RISE_FRACTION = 0.05


def _near_and_plateau(columns: dict, params: Parameters, contribution: str | None = None) -> tuple[float, float]:
    summary = cycle_summary(columns, params)
    if contribution is not None:
        share = summary["contributions"][contribution]
        return share["near_right_lock_Nm"], share["plateau_Nm"]
    return summary["torque_near_right_lock_Nm"], summary["plateau_torque_Nm"]


def converter_step_Nm(params: Parameters) -> float:
    """One step of the source's torque converter: full scale +-F over 2^bits levels."""
    return 2.0 * params["synthetic.full_scale_torque"] / 2.0 ** params["synthetic.logger_bits"]


def compare_rivals(params: Parameters, simulate=None, rivals=None, progress=None) -> dict:
    """Lifting's rise toward lock in each test, each rival's matched strength and rise in each test, and the
    separating test (see the module docstring). `rivals` selects effects that declare a rival (every one in name
    order when None); each rival's search starts at its declared probe strength."""
    if simulate is None:
        from ..model.numeric.simulate import simulate
    registry = discover_effects()
    rivals = chosen_rivals(rivals, "rivals", registry)
    base = {key: simulate(case, params=params, surface=surface).columns for key, case, surface, _ in TESTS}
    base_numbers = {key: _near_and_plateau(c, params) for key, c in base.items()}
    lifting = {key: _rise_entry(*_near_and_plateau(c, params, "lifting")) for key, c in base.items()}
    target = lifting["unladen_ground"]["rise_Nm"]
    step = converter_step_Nm(params)

    cycles: dict[tuple[str, str, float], dict] = {}  # each (rival, test, strength) simulated once

    def added(rival, key, strength) -> dict:
        if (rival, key, strength) in cycles:
            return cycles[rival, key, strength]
        _, case, surface, _ = next(t for t in TESTS if t[0] == key)
        quantity = strength_parameter(registry[rival], params)
        columns = simulate(case, effects=f"+{rival}", overrides={quantity.key: strength}, params=params,
                           surface=surface).columns
        near, plateau = _near_and_plateau(columns, params)
        cycles[rival, key, strength] = _rise_entry(near - base_numbers[key][0], plateau - base_numbers[key][1])
        return cycles[rival, key, strength]

    out = {}
    for rival in rivals:
        if progress is not None:
            progress(f"rival {rival}: matching lifting's rise toward lock, {target:.3f} N m")
        quantity = strength_parameter(registry[rival], params)
        strength, status = _matched_strength(lambda s: added(rival, "unladen_ground", s)["rise_Nm"], target,
                                             registry[rival].rival.probe_strength, quantity.upper)
        tests = {key: added(rival, key, strength) for key, *_ in TESTS}
        out[rival] = _rival_numbers(quantity, strength, status, tests, lifting, step)
    matched = [r for r in rivals if out[r]["status"] == "matched"]
    return {
        "tests": [{"key": k, "case": c, "surface": s, "label": label} for k, c, s, label in TESTS],
        "lifting": {"tests": lifting},
        "target_rise_Nm": target,
        "converter_step_Nm": step,
        "shares_unladen_ground_Nm": {name: cycle_summary(base["unladen_ground"], params)["contributions"][name]
                                     ["plateau_Nm"] for name in ("tyre_friction", "rack_friction", "lifting")},
        "rivals": out,
        "order": list(rivals),
        "matched": matched,
        "no_rise": [r for r in rivals if out[r]["status"] == "no rise"],
        "at_bound": [r for r in rivals if out[r]["status"] == "at bound"],
        "told_apart": [r for r in matched if out[r]["told_apart"]],
        "not_told_apart": [r for r in matched if not out[r]["told_apart"]],
    }


def _rise_entry(near: float, plateau: float) -> dict:
    return {"near_lock_Nm": near, "plateau_Nm": plateau, "rise_Nm": near - plateau}


def _matched_strength(rise, target: float, probe: float, upper_bound: float) -> tuple[float, str]:
    """The strength whose added rise toward lock (`rise(strength)`, zero at zero strength) is `target`, by a secant
    search from `probe` kept within [0, upper_bound], and its status: "matched", "at bound", or "no rise" (the
    rise at the probe is below NO_RISE_FRACTION of the target's)."""
    upper = upper_bound if math.isfinite(upper_bound) else math.inf
    s0, f0 = 0.0, -target
    s1 = probe
    first = rise(s1)
    f1 = first - target
    if first * math.copysign(1.0, target) < NO_RISE_FRACTION * abs(target):
        return s1, "no rise"  # its torque does not grow toward lock: it cannot stand in for lifting
    for _ in range(MATCH_STEPS):
        if abs(f1) <= MATCH_RELATIVE * abs(target) or f1 == f0:
            break
        s_next = min(max(s1 - f1 * (s1 - s0) / (f1 - f0), 0.0), upper)
        if s_next == s1 or s_next == 0.0:
            break  # held at a bound
        s0, f0, s1 = s1, f1, s_next
        f1 = rise(s1) - target
    return s1, "matched" if abs(f1) <= MATCH_RELATIVE * abs(target) else "at bound"


def _rival_numbers(quantity, strength: float, status: str, tests: dict, lifting: dict, step: float) -> dict:
    """A rival's strength and added rise in each test, against lifting's: the separating test and whether it tells
    them apart by more than one converter step `step`."""
    differences = {key: tests[key]["rise_Nm"] - lifting[key]["rise_Nm"] for key, *_ in TESTS[1:]}
    separating = max(differences, key=lambda k: abs(differences[k]))
    return {
        "strength_key": quantity.key, "strength": strength, "unit": quantity.unit, "status": status,
        "tests": tests,
        "difference_from_lifting_Nm": differences,
        "separating_test": separating,
        "separating_difference_Nm": differences[separating],
        "told_apart": status == "matched" and abs(differences[separating]) > step,
        "told_apart_by": [k for k in differences if status == "matched" and abs(differences[k]) > step],
    }


def rivals_table(result: dict) -> dict[str, list]:
    """One row per mechanism (lifting first): strength, added rise toward lock per test, the separating test."""
    keys = [t["key"] for t in result["tests"]]
    rows: dict[str, list] = {"mechanism": ["lifting"], "strength_key": [""], "strength": [float("nan")],
                             "unit": [""]}
    for key in keys:
        rows[f"rise_{key}_Nm"] = [result["lifting"]["tests"][key]["rise_Nm"]]
    rows["plateau_unladen_ground_Nm"] = [result["lifting"]["tests"]["unladen_ground"]["plateau_Nm"]]
    rows.update({"status": ["reference"], "told_apart_by": [""], "separating_test": [""], "separating_difference_Nm": [0.0],
                 "told_apart": [""]})
    for name in result["order"]:
        r = result["rivals"][name]
        rows["mechanism"].append(name)
        rows["strength_key"].append(r["strength_key"])
        rows["strength"].append(r["strength"])
        rows["unit"].append(r["unit"])
        for key in keys:
            rows[f"rise_{key}_Nm"].append(r["tests"][key]["rise_Nm"])
        rows["plateau_unladen_ground_Nm"].append(r["tests"]["unladen_ground"]["plateau_Nm"])
        rows["status"].append(r["status"])
        rows["told_apart_by"].append(" ".join(r["told_apart_by"]))
        rows["separating_test"].append(r["separating_test"])
        rows["separating_difference_Nm"].append(r["separating_difference_Nm"])
        rows["told_apart"].append(("yes" if r["told_apart"] else "no") if r["status"] == "matched" else "")
    return rows


def plot_rivals(result: dict):
    """The rise toward lock that lifting and each rival add in the source's four tests."""
    from ..plotting import COLOURS, new_figure  # matplotlib only where a figure is drawn

    names = ["lifting", *result["order"]]
    tests = result["tests"]
    fig, ax = new_figure(7.0, 3.4)
    width = 0.8 / len(tests)
    x = np.arange(len(names))
    for j, test in enumerate(tests):
        values = [result["lifting"]["tests"][test["key"]]["rise_Nm"]] + \
                 [result["rivals"][n]["tests"][test["key"]]["rise_Nm"] for n in result["order"]]
        ax.bar(x + (j - (len(tests) - 1) / 2) * width, values, width, color=COLOURS[j % len(COLOURS)],
               label=test["label"])
    step = result["converter_step_Nm"]
    notes = {"no rise": "no rise", "at bound": "at its bound"}
    for k, name in enumerate(result["order"], start=1):
        r = result["rivals"][name]
        note = notes.get(r["status"]) or ("told apart" if r["told_apart"] else "not told apart")
        ax.text(k, ax.get_ylim()[1] * 0.97, note, ha="center", va="top", fontsize=6, rotation=90)
    ax.axhline(0.0, color="k", linewidth=0.6)
    ax.set_xticks(x, [n.replace("_", " ") for n in names], rotation=30, ha="right", fontsize=7)
    ax.set_ylabel("added rise toward lock (N m)")
    ax.set_title(f"Each rival matched to lifting's rise in the unladen ground test; converter step {step:.2f} N m",
                 fontsize=8)
    ax.legend(fontsize=6.5, frameon=False)
    fig.tight_layout()
    return fig


def make_rivals(parameters_path: str | Path, svg_path: str | Path, csv_path: str | Path, json_path: str | Path,
                rivals=None, progress=None) -> dict:
    """Write the rivals figure (SVG), its table (CSV) and the numbers the paper quotes (JSON) for `rivals` (a
    selection of the rival effects, every one when None)."""
    from ..plotting import save_svg  # matplotlib only where a figure is drawn (the Snakefile imports this module)

    params = load_parameters(parameters_path)
    result = compare_rivals(params, rivals=rivals, progress=progress)
    header = {
        "table": "lifting and each rival matched to its rise toward lock in the unladen ground test: the rise "
                 "(near right lock minus plateau) each adds in each of the source's tests",
        "told_apart": f"the separating test's difference exceeds one converter step "
                      f"({result['converter_step_Nm']:.4f} N m)",
    }
    write_csv(csv_path, rivals_table(result), header)
    write_json(json_path, result)
    save_svg(plot_rivals(result), svg_path)
    return result
