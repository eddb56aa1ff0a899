"""A diagnosis as JSON (documented by parksteer/data/diagnosis.schema.json), and the rows and lines other views
read from it; the pages (markdown and HTML) are :mod:`parksteer.reporting.pages`."""

from __future__ import annotations

import math

import numpy as np

from ..measure.phases import PHASES
from ..resources import data_file
from ..diagnose.calibrate import free_strengths
from ..diagnose.stages.user_effect import conditioned_on_strengths
from ..diagnose.state import Candidate, Diagnosis

SCHEMA_ID = "parksteer.diagnosis/1"
SCHEMA_PATH = data_file("diagnosis.schema.json")


def _finite(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def candidate_predictions(diagnosis: Diagnosis, candidate: Candidate) -> list[np.ndarray]:
    """The candidate's fitted model (refit), or its linear estimate at the calibrated parameters."""
    if candidate.refit is not None:
        return candidate.refit.predictions
    sig = candidate.signature
    strength = max(candidate.score.linear_strength, 0.0)
    return [m + strength * (p - z) / sig.probe
            for m, p, z in zip(diagnosis.calibration.predictions, sig.probed, sig.zero)]


def candidate_statistics(diagnosis: Diagnosis, candidate: Candidate, before: dict | None = None) -> dict:
    """The error statistics with `candidate` (:func:`candidate_predictions`); for a candidate not refitted, its
    weighted RMS is the linear estimate's: the calibrated one (`before`, computed if not given) scaled by the sum
    of squares the score test says the strength removes. The one number the report's table and the figure show."""
    after = diagnosis.statistics(candidate_predictions(diagnosis, candidate))
    if candidate.refit is None:
        before = before if before is not None else diagnosis.statistics(diagnosis.calibration.predictions)
        rss = diagnosis.calibration.rss - candidate.score.removed_rss
        after["weighted_rms_Nm"] = before["weighted_rms_Nm"] * math.sqrt(max(rss, 0.0) / diagnosis.calibration.rss)
    return after


def _ranking_entry(diagnosis: Diagnosis, candidate: Candidate, before: dict) -> dict:
    after = candidate_statistics(diagnosis, candidate, before)
    excess = diagnosis.calibration.rss - diagnosis.problem.n
    removed = diagnosis.calibration.rss - candidate.rss_after(diagnosis.calibration.rss)
    if candidate.refit is not None:
        parameters = candidate.refit.intervals(diagnosis.problem)
    else:
        parameters = {candidate.signature.key: {"value": max(candidate.score.linear_strength, 0.0), "ci95": None,
                                                "standard_error": None}}
    return {
        "effect": candidate.name,
        "strength_parameter": candidate.signature.key,
        "score": candidate.score.statistic,
        "linear_strength": candidate.score.linear_strength,
        "identifiable_fraction": candidate.score.identifiable_fraction,
        "confounded_with": candidate.score.confounded_with,
        "probe_strength": candidate.signature.probe,
        "probe_rms_change_Nm": candidate.signature.rms_change_Nm,
        "refitted": candidate.refit is not None,
        "delta_bic": _finite(candidate.delta_bic),
        "parameters": parameters,
        "rms_before_Nm": before["rms_Nm"],
        "rms_after_Nm": after["rms_Nm"],
        "weighted_rms_before_Nm": before["weighted_rms_Nm"],
        "weighted_rms_after_Nm": after["weighted_rms_Nm"],
        "explained_fraction": _finite(removed / excess) if excess > 0 else None,
    }


# Machine times in a diagnosis or a benchmark summary: they differ from run to run and machine to machine, so the
# pipeline's key-number files (results/<target>.json), which a rebuild must reproduce byte for byte, leave them out.
MACHINE_TIME_KEYS = frozenset({"timings_s", "wall_s", "generation_s", "wall_s_median", "diagnosis_wall_s_median",
                               "diagnosis_wall_s_total", "time_s_median", "time_with_upstream_s_median"})


def without_machine_times(value):
    """`value` (JSON-like) with every MACHINE_TIME_KEYS entry removed, at any depth."""
    if isinstance(value, dict):
        return {k: without_machine_times(v) for k, v in value.items() if k not in MACHINE_TIME_KEYS}
    if isinstance(value, list):
        return [without_machine_times(v) for v in value]
    return value


def diagnosis_dict(diagnosis: Diagnosis) -> dict:
    """The JSON of a diagnosis (see workflow/schemas/diagnosis.schema.json)."""
    problem = diagnosis.problem
    nominal = diagnosis.statistics(diagnosis.nominal_predictions)
    calibrated = diagnosis.statistics(diagnosis.calibration.predictions)
    with_effect = None
    if diagnosis.verdict == "missing":
        with_effect = diagnosis.statistics(diagnosis.best.refit.predictions)
    defaults = {p.key: p.reference for p in diagnosis.calibration.parameters}
    intervals = diagnosis.calibration.intervals(problem, diagnosis.settings.interval_block_s)
    free = [q.key for q in free_strengths(diagnosis.calibration.effects)]
    if free:  # a user's free strengths: the car's intervals with them held at their fit (stages/user_effect.py)
        intervals.update(conditioned_on_strengths(diagnosis.calibration, problem, free,
                                                  diagnosis.settings.interval_block_s))
    calibrated_parameters = {key: {**entry, "default": defaults[key]} for key, entry in intervals.items()}
    files = []
    for f in problem.files:
        delta = f.replay_uncertainty_Nm
        files.append({
            "file": f.label,
            "case": f.case,
            "surface": f.surface,
            "samples": f.n,
            "noise_floor": f.noise.as_dict(),
            "replay_uncertainty_rms_Nm": float(np.sqrt(np.mean(delta**2))) if delta is not None else 0.0,
            "rack_smoothing": f.rack.summary(),
            "torque_lag_s": f.torque_lag_s,
        })
        if f.uses_angle:
            angle_delta = f.replay_uncertainty_rad
            files[-1]["angle"] = {
                "noise_floor": f.angle_noise.as_dict(),
                "replay_uncertainty_rms_rad": (float(np.sqrt(np.mean(angle_delta**2))) if angle_delta is not None
                                               else 0.0),
            }
    out = {
        "schema": SCHEMA_ID,
        "verdict": diagnosis.verdict,
        "effect": diagnosis.effect,
        "indistinguishable": [
            {
                "effect": s.effect,
                "delta_bic": s.delta_bic,
                "separating_measurement": {
                    "case": s.case,
                    "surface": s.surface,
                    "predicted_difference_rms_Nm": s.predicted_difference_rms_Nm,
                    "over_noise_floor": s.over_noise_floor,
                },
                "conditions": s.conditions,
            }
            for s in diagnosis.indistinguishable
        ],
        "confounded": [
            {"effect": c.name, "confounded_with": c.score.confounded_with,
             "identifiable_fraction": c.score.identifiable_fraction,
             # None also where the settings leave the tests off
             "separating_measurement": diagnosis.confound_tests.get(c.name)}
            for c in diagnosis.confounded
        ],
        "ranking": [_ranking_entry(diagnosis, c, calibrated) for c in diagnosis.ranked],
        "untestable": diagnosis.untestable,
        "identification": diagnosis.identification,
        "unobservable": diagnosis.unobservable,
        "noise_floor_Nm": calibrated["noise_floor_Nm"],
        "attainable_floor_Nm": calibrated["attainable_floor_Nm"],
        "calibrated": calibrated_parameters,
        "model": {"effects": [e.name for e in diagnosis.base_effects]},
        "files": files,
        "statistics": {"nominal": nominal, "calibrated": calibrated, "with_effect": with_effect},
        "selection": {
            "criterion": "BIC over the effective sample size: n_eff ln(RSS/n) + k ln(n_eff)",
            "samples": problem.n,
            "effective_samples": diagnosis.n_eff,
            "lag1_autocorrelation": diagnosis.rho,
            "calibrated_over_floor": math.sqrt(diagnosis.calibration.rss / problem.n),
            "explained_fraction": _finite(diagnosis.explained_fraction),
            "thresholds": {
                "adequate_rms_factor": diagnosis.settings.adequate_rms_factor,
                "bic_missing": diagnosis.settings.bic_missing_threshold,
                "explained_fraction_missing": diagnosis.settings.explained_fraction_missing,
                "missing_rms_ceiling": diagnosis.settings.missing_rms_ceiling,
                "missing_ceiling_trim": diagnosis.settings.missing_ceiling_trim,
                "bic_indistinguishable": diagnosis.settings.bic_indistinguishable,
                "confounded_fraction": diagnosis.settings.confounded_fraction,
                "separating_over_floor": diagnosis.settings.separating_over_floor,
            },
        },
        "cost": {"replays": diagnosis.replays, "replays_by_stage": dict(diagnosis.replays_by_stage),
                 "timings_s": diagnosis.timings_s},
    }
    if problem.uses_angle:  # the handwheel angle fitted as a second signal: which files, and its floor
        out["angle"] = {
            "files": [f.label for f in problem.files if f.uses_angle],
            "noise_floor_rad": calibrated["angle"]["noise_floor_rad"],
            "attainable_floor_rad": calibrated["angle"]["attainable_floor_rad"],
            "offset_fitted": diagnosis.settings.angle_offset_fitted,
        }
    if diagnosis.outputs.get("assumed") is not None:  # an assisted car's assumed values (stages/assumed.py)
        out["assumed"] = diagnosis.outputs["assumed"]
    if diagnosis.outputs.get("baseline") is not None:  # a gain error against an identified table (stages/baseline.py)
        out["baseline"] = diagnosis.outputs["baseline"]
    if "relative_to" in diagnosis.outputs:  # judged against a car's baseline (parksteer.diagnose.baseline)
        out["relative_to"] = diagnosis.outputs["relative_to"]
    if "signature" in diagnosis.outputs:  # the residual's signature (stages/signature.py)
        out["signature"] = diagnosis.outputs["signature"].as_dict()
    if "user_effect" in diagnosis.outputs:  # a user's effect with free strengths (stages/user_effect.py)
        out["user_effect"] = diagnosis.outputs["user_effect"].as_dict()
    out["units"] = parameter_units(out, diagnosis.effects)
    return _json_safe(out)


# --------------------------------------------------------------------- how sure the diagnosis is: units, ties
def parameter_units(result: dict, effects=()) -> dict[str, str]:
    """The unit of every parameter the JSON `result` gives a value or an interval of (calibrated, the candidates'
    fitted strengths, what the data fix), from the quantities known with the diagnosis's `effects` (an effect
    loaded from a file declares its own: :func:`parksteer.model.symbolic.components.known_quantities`)."""
    from ..errors import UsageError
    from ..model.symbolic.components import quantity_of

    keys = set(result["calibrated"])
    for c in result["ranking"]:
        keys.update(c["parameters"])
    keys.update(row["parameter"] for row in result.get("identification") or [])
    units = {}
    for k in sorted(keys):
        try:
            units[k] = quantity_of(k, effects).unit
        except UsageError:  # a key none of the effects declares: shown without a unit
            pass
    return units


def separating(measurement: dict | None, result: dict) -> bool:
    """Whether a separating measurement (a dict with ``over_noise_floor``) predicts a difference above the
    threshold of the settings (``separating_over_floor`` noise floors RMS): only then is it offered."""
    if not measurement:
        return False
    threshold = result["selection"]["thresholds"].get("separating_over_floor", 1.0)
    return measurement["over_noise_floor"] >= threshold


def confound_separates(measurement: dict | None) -> bool:
    """Whether the measurement offered for a confounded candidate shows it better than these data do: the torque
    change left there by the calibrated parameters, at the probe strength, larger than the change left here. The
    probe's strength is arbitrary (the data do not fix a confounded candidate's), so the ratio, not a number of
    noise floors, says whether measuring there helps."""
    if not measurement:
        return False
    return measurement["predicted_difference_rms_Nm"] > measurement["left_here_rms_Nm"]


def tie(result: dict) -> dict | None:
    """For a named effect with candidates within the information criterion's threshold of it: the tied effects
    (the named one first), their BIC gains and fitted strengths, and the measurements that would separate the
    named one from each (those above the threshold of :func:`separating` only). None without a tie."""
    if result["verdict"] != "missing" or not result["indistinguishable"]:
        return None
    by_name = {c["effect"]: c for c in result["ranking"]}
    names = [result["effect"], *(s["effect"] for s in result["indistinguishable"])]
    tests = {s["effect"]: s["separating_measurement"] for s in result["indistinguishable"]}
    return {"effects": names,
            "delta_bic": {n: by_name[n]["delta_bic"] if n in by_name else None for n in names},
            "strengths": {n: strength_text(by_name[n], result.get("units", {})) for n in names if n in by_name},
            "tests": {n: m for n, m in tests.items() if separating(m, result)},
            "best_rejected": {n: m for n, m in tests.items() if not separating(m, result)}}


def strength_text(candidate: dict, units: dict[str, str]) -> str:
    """A candidate's fitted strength with its unit and 95 % interval ('0.51 N m (95 %: 0.26 to 0.75 N m)')."""
    key = candidate["strength_parameter"]
    entry = candidate["parameters"][key]
    unit = shown_unit(units.get(key, ""))
    ci = entry.get("ci95")
    text = f"{num(entry['value'])} {unit}".rstrip()
    return text + (f" (95 %: {interval_text(ci, unit, 3)})" if ci else " (linear estimate)")


def shown_unit(unit: str) -> str:
    """A unit as a number is followed by it: none for a ratio (the registry's "1")."""
    return "" if unit == "1" else unit


def interval_text(ci, unit: str = "", digits: int = 4) -> str:
    """'low to high UNIT', or '-' when there is no interval."""
    if ci is None:
        return "-"
    return f"{num(ci[0], digits)} to {num(ci[1], digits)} {shown_unit(unit)}".rstrip()


def tie_headline(result: dict) -> tuple[str, str] | None:
    """The headline of a diagnosis whose named effect ties with others, (head, body): 'A or B: these data cannot
    tell them apart', then each with its BIC gain and strength, the error, and what would separate them or that
    no test of this kind does. None without a tie."""
    t = tie(result)
    if t is None:
        return None
    threshold = result["selection"]["thresholds"]["bic_indistinguishable"]
    stats, floor = result["statistics"], result["noise_floor_Nm"]
    names = " or ".join(f"`{n}`" for n in t["effects"])
    each = "; ".join(f"`{n}` {t['strengths'][n]}, ΔBIC {num(t['delta_bic'][n])}" for n in t["effects"]
                     if n in t["strengths"])
    head = f"{names}: these data cannot tell them apart"
    body = (f"Their BIC gains lie within {num(threshold)} of each other ({each}). Either takes the weighted RMS "
            f"error from {num(stats['calibrated']['weighted_rms_Nm'])} N m to about "
            f"{num(stats['with_effect']['weighted_rms_Nm'])} N m, against a noise floor of {num(floor)} N m.")
    return head, body + " " + separation_text(result, t)


def separation_text(result: dict, t: dict) -> str:
    """What would separate the tied effects: each test above the threshold, or that no test of this kind does."""
    named = t["effects"][0]
    threshold = result["selection"]["thresholds"].get("separating_over_floor", 1.0)
    parts = []
    for other in t["effects"][1:]:
        m = t["tests"].get(other)
        if m:
            parts.append(f"measuring the {m['case']} case on {m['surface'].replace('_', ' ')} would separate "
                         f"`{named}` from `{other}`: the two fitted models differ there by "
                         f"{num(m['predicted_difference_rms_Nm'])} N m RMS ({num(m['over_noise_floor'])} noise floors)")
        else:
            m = t["best_rejected"].get(other)
            best = (f" (the most any load case or surface the data lack would show is "
                    f"{num(m['predicted_difference_rms_Nm'])} N m RMS, {num(m['over_noise_floor'])} noise floors, "
                    f"with the {m['case']} case on {m['surface'].replace('_', ' ')})") if m else ""
            parts.append(f"no test of this kind separates `{named}` from `{other}`: no load case or surface "
                         f"predicts a difference of {num(threshold)} noise floor{'s' if threshold != 1 else ''}"
                         f"{best}")
    text = "; ".join(parts)
    return text[:1].upper() + text[1:] + "." if text else ""


def _json_safe(obj):
    """The result with every value JSON can hold: a number that is not finite (a standard error of a parameter the
    data cannot fix, when the sensitivities are singular) becomes null, and so does an interval holding one."""
    if isinstance(obj, dict):
        return {k: _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        if obj and all(isinstance(v, (int, float)) for v in obj) and not all(math.isfinite(v) for v in obj):
            return None
        return [_json_safe(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def with_suggestion(result: dict, suggestion) -> dict:
    """`result` (the JSON of a diagnosis) with the suggested effect and its error ladder (calibrated, then with the
    suggested effect)."""
    return {**result, "suggestion": _json_safe(suggestion.as_dict())}


def signature_lines(result: dict) -> list[str]:
    """The signature (and the suggestion) as readable lines."""
    sig = result["signature"]
    lines = [f"What kind of effect: {sig['sentence']}."
             + (f" (class {sig['class']}, basis {sig['model']}, at the {sig['where']})" if sig["class"] else "")]
    for a in sig["axes"]:
        excess = f", {num(100 * a['excess_share'], 2)} % of the part above the noise" \
            if a["excess_share"] is not None else ""
        lines.append(f"{a['axis']}: {num(100 * a['share'], 2)} % of the weighted residual sum of squares{excess} "
                     f"(likelihood ratio {num(a['statistic'])} on {a['columns']} columns, p = {num(a['p_value'], 2)}"
                     f"{', significant' if a['significant'] else ''})")
    suggestion = result.get("suggestion")
    if suggestion:
        where = f" written to {suggestion['path']}" if suggestion.get("path") else ""
        lines.append(f"Suggested effect `{suggestion['effect']}`{where}: fitted with the calibrated parameters it "
                     f"takes the weighted RMS error from {num(suggestion['before_over_floor'])} to "
                     f"{num(suggestion['after_over_floor'])} noise floors (ΔBIC {num(suggestion['delta_bic'])}).")
    return lines


# ------------------------------------------------------------------------------------ the HTML report
def phase_residuals(diagnosis: Diagnosis) -> list[dict]:
    """RMS of the residual of the calibrated model, and with the best candidate, in each phase of each file."""
    best = candidate_predictions(diagnosis, diagnosis.best) if diagnosis.best is not None else None
    rows = []
    for i, f in enumerate(diagnosis.problem.files):
        calibrated = f.torque_Nm - f.torque_part(diagnosis.calibration.predictions[i])
        after = f.torque_Nm - f.torque_part(best[i]) if best is not None else None
        for phase in PHASES:
            mask = f.phases.mask(phase)
            if not mask.any():
                continue
            rows.append({
                "file": f.label,
                "phase": phase,
                "samples": int(mask.sum()),
                "calibrated_rms_Nm": float(np.sqrt(np.mean(calibrated[mask] ** 2))),
                "with_effect_rms_Nm": float(np.sqrt(np.mean(after[mask] ** 2))) if after is not None else None,
                "noise_floor_Nm": float(f.noise.total_rms),
            })
    return rows


def num(x, digits: int = 3) -> str:
    if x is None:
        return "-"
    return f"{x:.{digits}g}" if abs(x) < 1e4 else f"{x:.3e}"


def html_table(head: list[str], rows: list[list]) -> list[str]:
    """An HTML table of `head` and `rows`, every cell escaped."""
    import html  # only a page needs it (it loads html.entities), not the JSON

    out = ["<table>", "<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in head) + "</tr>"]
    out += ["<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>" for row in rows]
    return out + ["</table>"]

