"""A diagnosis as JSON (documented by workflow/schemas/diagnosis.schema.json), as markdown, and as one
self-contained HTML page (figures inlined as SVG, no external reference)."""

from __future__ import annotations

import html
import math
import re
from pathlib import Path

import numpy as np

from ..measure.phases import PHASES
from ..resources import data_file
from ..tables import atomic_path
from .state import Candidate, Diagnosis

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


def _ranking_entry(diagnosis: Diagnosis, candidate: Candidate, before: dict) -> dict:
    after = diagnosis.statistics(candidate_predictions(diagnosis, candidate))
    if candidate.refit is None:
        # the linear estimate: the sum of squares the score test says the strength removes
        rss = diagnosis.calibration.rss - candidate.score.removed_rss
        after["weighted_rms_Nm"] = before["weighted_rms_Nm"] * math.sqrt(max(rss, 0.0) / diagnosis.calibration.rss)
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
    calibrated_parameters = {
        key: {**entry, "default": defaults[key]} for key, entry in diagnosis.calibration.intervals(problem).items()
    }
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
    if "signature" in diagnosis.outputs:  # the residual's signature (stages/signature.py)
        out["signature"] = diagnosis.outputs["signature"].as_dict()
    return _json_safe(out)


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


def _interval(ci, digits: int = 4) -> str:
    return "-" if ci is None else f"{_n(ci[0], digits)} to {_n(ci[1], digits)}"


def _n(x, digits: int = 3) -> str:
    if x is None:
        return "-"
    return f"{x:.{digits}g}" if abs(x) < 1e4 else f"{x:.3e}"


def _nearest(result: dict) -> str:
    """For an unexplained verdict: the strongly evidenced candidate that was still not the whole story, if any."""
    thresholds = result["selection"]["thresholds"]
    top = result["ranking"][0] if result["ranking"] else None
    if top is None or top["delta_bic"] is None or top["delta_bic"] <= thresholds["bic_missing"]:
        return ""
    floor = result["noise_floor_Nm"]
    after = top["weighted_rms_after_Nm"] / floor if floor > 0 else float("nan")
    lead = f" The nearest candidate, {top['effect']}, is strongly evidenced (BIC gain {_n(top['delta_bic'])}) but "
    if after > thresholds["missing_rms_ceiling"]:
        return (lead + f"leaves the weighted error at {_n(after)} noise floors, above the "
                f"{_n(thresholds['missing_rms_ceiling'])} that records with nothing hidden reach: it may be the closest "
                "form the library has to what is at work, not the effect itself.")
    # below the ceiling, a name also needs the error within the adequate factor or most of the excess removed
    explained = result["selection"]["explained_fraction"]
    removed = f"removes {_n(100 * explained)} % of the error above the floor" if explained is not None else (
        "removes too little of the error above the floor")
    return (lead + f"leaves the weighted error at {_n(after)} noise floors (a name needs "
            f"{_n(thresholds['adequate_rms_factor'])}) and {removed} (a name needs "
            f"{_n(100 * thresholds['explained_fraction_missing'])} %): it may be part of what is at work, most of it "
            "taken up by the calibrated parameters it is confounded with (below).")


def _angle_change(result: dict) -> str:
    """', and the angle's from ... to ... rad against ...' when the angle is fitted (the verdict's sentence)."""
    stats = result["statistics"]
    if not result.get("angle") or not stats.get("with_effect"):
        return ""
    before, after = stats["calibrated"]["angle"], stats["with_effect"]["angle"]
    return (f"; the handwheel angle's from {_n(before['weighted_rms_rad'])} rad to {_n(after['weighted_rms_rad'])} "
            f"rad against {_n(result['angle']['noise_floor_rad'])} rad")


def _identification_lines(result: dict) -> list[str]:
    """One sentence per calibrated (or calibratable) parameter: fixed by these data, or which test would fix it."""
    lines = []
    for row in result.get("identification", []):
        key, test = row["parameter"], row["fixed_by"]
        if row["status"] == "fixed":
            lines.append(f"{key}: fixed by these data ({_n(row['value'], 4)}, 95 % interval {_interval(row['ci95'])}).")
        elif row["status"] == "not calibrated":
            lines.append(f"{key}: not fixed by these data; {test} would fix it.")
        elif isinstance(test, dict):
            lines.append(f"{key}: not fixed by these data (95 % interval {_interval(row['ci95'])}); the "
                         f"{test['case']} case on {test['surface'].replace('_', ' ')} "
                         f"would fix it: its interval's ends differ there by {_n(test['predicted_difference_rms_Nm'])} "
                         f"N m RMS ({_n(test['over_noise_floor'])} noise floors).")
        else:
            lines.append(f"{key}: not fixed by these data, and no load case or surface left to measure fixes it.")
    return lines


def markdown_report(result: dict, figure: str | None = None) -> str:
    """A readable report of the JSON of a diagnosis."""
    lines = ["# Diagnosis: model against measurement", ""]
    verdict = result["verdict"]
    floor = result["noise_floor_Nm"]
    stats = result["statistics"]
    if verdict == "missing":
        lines.append(f"**Verdict: missing effect `{result['effect']}`.** Adding it takes the weighted RMS error from "
                     f"{_n(stats['calibrated']['weighted_rms_Nm'])} N m to {_n(stats['with_effect']['weighted_rms_Nm'])} "
                     f"N m, against a noise floor of {_n(floor)} N m{_angle_change(result)}.")
    elif verdict == "adequate":
        lines.append(f"**Verdict: adequate.** With its calibrated parameters the model's weighted RMS error "
                     f"({_n(stats['calibrated']['weighted_rms_Nm'])} N m) is at the noise floor ({_n(floor)} N m); "
                     "these data show no missing effect.")
    else:
        lines.append(f"**Verdict: unexplained.** The calibrated model leaves a structured error (weighted RMS "
                     f"{_n(stats['calibrated']['weighted_rms_Nm'])} N m against a noise floor of {_n(floor)} N m) "
                     "that no candidate removes for the most part. Something outside the candidate library is at "
                     "work (or in the measurement): look at the residual below." + _nearest(result))
    lines += ["", "## Files", "", "| file | case | surface | samples | noise floor (N m) | replay uncertainty RMS (N m) "
              "| rack knot spacing (s) |", "|---|---|---|---|---|---|---|"]
    for f in result["files"]:
        lines.append(f"| {f['file']} | {f['case']} | {f['surface']} | {f['samples']} | "
                     f"{_n(f['noise_floor']['total_rms'])} | {_n(f['replay_uncertainty_rms_Nm'])} | "
                     f"{_n(f['rack_smoothing']['knot_spacing_s'])} |")
    lines += ["", "## Error", "", "| model | RMS (N m) | weighted RMS (N m) | peak (N m) |", "|---|---|---|---|"]
    for label, key in (("nominal parameters", "nominal"), ("calibrated", "calibrated"),
                       (f"with {result['effect']}", "with_effect")):
        s = stats.get(key)
        if s:
            lines.append(f"| {label} | {_n(s['rms_Nm'])} | {_n(s['weighted_rms_Nm'])} | {_n(s['peak_Nm'])} |")
    lines += ["", f"Noise floor {_n(floor)} N m; attainable floor with the replay's uncertainty "
              f"{_n(result['attainable_floor_Nm'])} N m. The weighted RMS counts each sample by its attainable "
              "error, so it is the noise floor for a perfect model; the plain RMS also holds the few samples at "
              "reversals where the rack data cannot fix the instant the rack friction turns over.", ""]
    if result.get("angle"):
        angle = result["angle"]
        lines += ["## Handwheel angle", "", f"Fitted beside the torque in {', '.join(angle['files'])} (noise floor "
                  f"{_n(angle['noise_floor_rad'])} rad, with the replay's uncertainty "
                  f"{_n(angle['attainable_floor_rad'])} rad).", "",
                  "| model | RMS (rad) | RMS (degrees) | weighted RMS (rad) | peak (rad) |", "|---|---|---|---|---|"]
        for label, key in (("nominal parameters", "nominal"), ("calibrated", "calibrated"),
                           (f"with {result['effect']}", "with_effect")):
            a = (stats.get(key) or {}).get("angle")
            if a:
                lines.append(f"| {label} | {_n(a['rms_rad'])} | {_n(a['rms_deg'])} | {_n(a['weighted_rms_rad'])} | "
                             f"{_n(a['peak_rad'])} |")
        lines.append("")
    lines += ["## Calibrated parameters", "", "| parameter | default | fitted | 95 % interval |", "|---|---|---|---|"]
    for key, entry in result["calibrated"].items():
        ci = entry["ci95"]
        lines.append(f"| {key} | {_n(entry['default'], 4)} | {_n(entry['value'], 4)} | {_interval(ci)} |")
    lines += ["", "## Candidates", "", "| candidate | score | ΔBIC | fitted strength | weighted RMS after (N m) | "
              "identifiable fraction |", "|---|---|---|---|---|---|"]
    for c in result["ranking"]:
        strength = c["parameters"][c["strength_parameter"]]
        ci = strength.get("ci95")
        fitted = _n(strength["value"]) + (f" ({_n(ci[0])} to {_n(ci[1])})" if ci else " (linear estimate)")
        lines.append(f"| {c['effect']} | {_n(c['score'])} | {_n(c['delta_bic'])} | {fitted} | "
                     f"{_n(c['weighted_rms_after_Nm'])} | {_n(c['identifiable_fraction'], 2)} |")
    if result["indistinguishable"]:
        lines += ["", "## Indistinguishable by these data", ""]
        for s in result["indistinguishable"]:
            m = s["separating_measurement"]
            lines.append(f"- `{s['effect']}` (ΔBIC {_n(s['delta_bic'])}): measure the `{m['case']}` case on "
                         f"`{m['surface'].replace('_', ' ')}`, where the two fitted models differ by "
                         f"{_n(m['predicted_difference_rms_Nm'])} N m RMS ({_n(m['over_noise_floor'])} noise floors).")
    if result["confounded"]:
        lines += ["", "## Confounded with the calibrated parameters", ""]
        for c in result["confounded"]:
            line = (f"- `{c['effect']}`: only {_n(100 * c['identifiable_fraction'], 2)} % of its signature is not "
                    f"also made by `{c['confounded_with']}`; these data cannot tell it from a change of that "
                    "parameter, whose calibrated value holds only if it is absent.")
            m = c.get("separating_measurement")
            if m:
                line += (f" At a strength that changes this torque by {_n(m['change_here_rms_Nm'])} N m RMS, the "
                         f"calibrated parameters take up all but {_n(m['left_here_rms_Nm'])} N m "
                         f"({_n(m['left_here_over_noise_floor'])} noise floors) of it; measure the `{m['case']}` "
                         f"case on `{m['surface'].replace('_', ' ')}`, where it would still change the torque by "
                         f"{_n(m['predicted_difference_rms_Nm'])} N m RMS ({_n(m['over_noise_floor'])} noise "
                         f"floors, {_n(100 * m['predicted_difference_rms_Nm'] / m['change_here_rms_Nm'], 2)} % of "
                         "its change here).")
            lines.append(line)
    if result.get("identification"):
        lines += ["", "## What these data fix", ""] + [f"- {line}" for line in _identification_lines(result)]
    if result["unobservable"]:
        lines += ["", f"Unobservable in these data as replayed (even the largest strength moves the replayed torque "
                  f"by less than a tenth of the noise floor): {', '.join(result['unobservable'])}."]
    if result["untestable"]:
        lines += ["", f"Not testable (no strength parameter): {', '.join(result['untestable'])}."]
    if result.get("signature"):
        lines += ["", "## The residual's signature", ""] + [f"- {line}" for line in signature_lines(result)]
    if figure:
        lines += ["", f"![diagnosis]({figure})"]
    lines += ["", f"Cost: {result['cost']['replays']} replays."]
    return "\n".join(lines) + "\n"


# --- the residual's signature and the suggested effect (parksteer.diagnose.signature, parksteer.diagnose.suggest)
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
        excess = f", {_n(100 * a['excess_share'], 2)} % of the part above the noise" \
            if a["excess_share"] is not None else ""
        lines.append(f"{a['axis']}: {_n(100 * a['share'], 2)} % of the weighted residual sum of squares{excess} "
                     f"(likelihood ratio {_n(a['statistic'])} on {a['columns']} columns, p = {_n(a['p_value'], 2)}"
                     f"{', significant' if a['significant'] else ''})")
    suggestion = result.get("suggestion")
    if suggestion:
        where = f" written to {suggestion['path']}" if suggestion.get("path") else ""
        lines.append(f"Suggested effect `{suggestion['effect']}`{where}: fitted with the calibrated parameters it "
                     f"takes the weighted RMS error from {_n(suggestion['before_over_floor'])} to "
                     f"{_n(suggestion['after_over_floor'])} noise floors (ΔBIC {_n(suggestion['delta_bic'])}).")
    return lines


def write_markdown(path: str | Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


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


_SVG_START = re.compile(r"<svg[\s>]")
_METADATA = re.compile(r"<metadata>.*?</metadata>\s*", re.DOTALL)


def inline_svg(text: str, prefix: str) -> str:
    """An SVG file's text as an inline element of a page that holds several: the XML declaration, the DOCTYPE
    (which names an external DTD) and the RDF metadata (which names vocabularies by URL) dropped, so the page
    refers to nothing outside itself, and every id prefixed with `prefix`, so two figures' ids cannot meet."""
    match = _SVG_START.search(text)
    if match is None:
        raise ValueError("not an SVG document")
    svg = _METADATA.sub("", text[match.start():])
    svg = re.sub(r'\bid="([^"]+)"', lambda m: f'id="{prefix}{m[1]}"', svg)
    svg = re.sub(r'href="#([^"]+)"', lambda m: f'href="#{prefix}{m[1]}"', svg)
    return re.sub(r"url\(#([^)]+)\)", lambda m: f"url(#{prefix}{m[1]})", svg)


_STYLE = """body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #bbb;padding:.25em .6em;text-align:right}
th:first-child,td:first-child{text-align:left}figure{margin:1em 0}figure svg{max-width:100%;height:auto}
figcaption{font-size:.9em;color:#555}.verdict{font-size:1.1em;padding:.6em;background:#f3f3f3}"""


def _table(head: list[str], rows: list[list]) -> list[str]:
    out = ["<table>", "<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in head) + "</tr>"]
    out += ["<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>" for row in rows]
    return out + ["</table>"]


def html_report(result: dict, figures: list[tuple[str, str]], phases: list[dict], ladder: dict | None = None,
                title: str | None = None) -> str:
    """One self-contained page: the verdict, the files, the figures (`(caption, svg text)`, inlined), the residual
    by phase (`phases`, from :func:`phase_residuals`), the error ladder (:meth:`parksteer.diagnose.ladder.Ladder.
    as_dict`), the fitted values with their 95 % intervals, the ranking."""
    title = title or "Diagnosis: model against measurement"
    stats, floor = result["statistics"], result["noise_floor_Nm"]
    verdict = result["verdict"]
    if verdict == "missing":
        text = (f"Verdict: missing effect {result['effect']}. Adding it takes the weighted RMS error from "
                f"{_n(stats['calibrated']['weighted_rms_Nm'])} N m to {_n(stats['with_effect']['weighted_rms_Nm'])} "
                f"N m, against a noise floor of {_n(floor)} N m{_angle_change(result)}.")
    elif verdict == "adequate":
        text = (f"Verdict: adequate. The calibrated model's weighted RMS error "
                f"({_n(stats['calibrated']['weighted_rms_Nm'])} N m) is at the noise floor ({_n(floor)} N m).")
    else:
        text = (f"Verdict: unexplained. The calibrated model leaves a structured error (weighted RMS "
                f"{_n(stats['calibrated']['weighted_rms_Nm'])} N m against a noise floor of {_n(floor)} N m) "
                "that no candidate removes." + _nearest(result))
    out = ["<!DOCTYPE html>", '<html lang="en">', "<head>", '<meta charset="utf-8">',
           f"<title>{html.escape(title)}</title>", f"<style>{_STYLE}</style>", "</head>", "<body>",
           f"<h1>{html.escape(title)}</h1>", f'<p class="verdict">{html.escape(text)}</p>',
           f"<p>Model: {html.escape(', '.join(result['model']['effects']))}.</p>", "<h2>Files</h2>"]
    out += _table(["file", "case", "surface", "samples", "noise floor (N m)"],
                  [[f["file"], f["case"], f["surface"], f["samples"], _n(f["noise_floor"]["total_rms"])]
                   for f in result["files"]])
    if result.get("angle"):
        angle = stats["calibrated"]["angle"]
        out.append(f"<p>Handwheel angle fitted beside the torque in {html.escape(', '.join(result['angle']['files']))}:"
                   f" calibrated model's angle residual RMS {html.escape(_n(angle['rms_rad']))} rad "
                   f"({html.escape(_n(angle['rms_deg']))} degrees), noise floor "
                   f"{html.escape(_n(result['angle']['noise_floor_rad']))} rad.</p>")
    for k, (caption, svg) in enumerate(figures):
        out += ["<figure>", inline_svg(svg, f"f{k}-"), f"<figcaption>{html.escape(caption)}</figcaption>", "</figure>"]
    out.append("<h2>Residual by phase</h2>")
    effect = result["effect"] if verdict == "missing" else None
    head = ["file", "phase", "samples", "calibrated RMS (N m)"] + ([f"with {effect} RMS (N m)"] if effect else [])
    out += _table(head + ["noise floor (N m)"],
                  [[r["file"], r["phase"].replace("_", " "), r["samples"], _n(r["calibrated_rms_Nm"])]
                   + ([_n(r["with_effect_rms_Nm"])] if effect else []) + [_n(r["noise_floor_Nm"])] for r in phases])
    if ladder is not None:
        out.append("<h2>Error ladder</h2>")
        out += _table(["rung", "effects", "RMS (N m)", "weighted RMS (N m)", "weighted RMS / noise floor"],
                      [[r["label"], ", ".join(r["effects"]), _n(r["rms_Nm"]), _n(r["weighted_rms_Nm"]),
                        _n(r["over_floor"])] for r in ladder["rungs"]])
        out.append(f"<p>Noise floor {html.escape(_n(ladder['noise_floor_Nm']))} N m; with the replay's uncertainty "
                   f"{html.escape(_n(ladder['attainable_floor_Nm']))} N m.</p>")
    out.append("<h2>Fitted values</h2>")
    rows = [[key, _n(e["default"], 4), _n(e["value"], 4), _interval(e["ci95"])]
            for key, e in result["calibrated"].items()]
    out += _table(["parameter", "default", "fitted", "95 % interval"], rows)
    if result.get("identification"):
        out.append("<h2>What these data fix</h2>")
        out += ["<ul>"] + [f"<li>{html.escape(line)}</li>" for line in _identification_lines(result)] + ["</ul>"]
    if result.get("signature"):
        out.append("<h2>The residual's signature</h2>")
        out += ["<ul>"] + [f"<li>{html.escape(line)}</li>" for line in signature_lines(result)] + ["</ul>"]
    out.append("<h2>Ranking of the candidate effects</h2>")
    rows = []
    for c in result["ranking"]:
        strength = c["parameters"][c["strength_parameter"]]
        ci = strength.get("ci95")
        rows.append([c["effect"], _n(c["score"]), _n(c["delta_bic"]),
                     _n(strength["value"]) + (f" ({_n(ci[0])} to {_n(ci[1])})" if ci else " (linear estimate)"),
                     _n(c["weighted_rms_after_Nm"]), _n(c["identifiable_fraction"], 2)])
    out += _table(["candidate", "score", "ΔBIC", "fitted strength (95 % interval)", "weighted RMS after (N m)",
                   "identifiable fraction"], rows)
    if result["indistinguishable"]:
        out.append("<h2>Indistinguishable by these data</h2>")
        out += _table(["effect", "ΔBIC", "measure case", "on", "difference RMS (N m)"],
                      [[s["effect"], _n(s["delta_bic"]), s["separating_measurement"]["case"],
                        s["separating_measurement"]["surface"].replace("_", " "),
                        _n(s["separating_measurement"]["predicted_difference_rms_Nm"])]
                       for s in result["indistinguishable"]])
    if result["unobservable"]:
        out.append(f"<p>Unobservable in these data: {html.escape(', '.join(result['unobservable']))}.</p>")
    out += [f"<p>Cost: {result['cost']['replays']} replays.</p>", "</body>", "</html>"]
    return "\n".join(out) + "\n"
