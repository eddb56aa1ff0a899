"""A diagnosis's JSON (:func:`parksteer.diagnose.report.diagnosis_dict`) as markdown, and as one self-contained
HTML page (figures inlined as SVG, no external reference)."""

from __future__ import annotations

import html
import re
from pathlib import Path

from ..tables import atomic_path
from .report import (confound_separates, html_table, interval_text, num, separating, shown_unit, signature_lines,
                     strength_text, tie_headline)
from .user_effect_pages import user_effect_html, user_effect_markdown


def _interval(ci, digits: int = 4, unit: str = "") -> str:
    return interval_text(ci, unit, digits)


def _unit(result: dict, key: str) -> str:
    return result.get("units", {}).get(key, "")


def _value_unit(result: dict, key: str) -> str:
    unit = shown_unit(_unit(result, key))
    return f" {unit}" if unit else ""


def _missing_headline(result: dict) -> tuple[str, str]:
    """The verdict's sentence for a named effect, (head, body): the tie first where candidates lie within the
    information criterion's threshold of it (:func:`parksteer.diagnose.report.tie_headline`)."""
    stats, floor = result["statistics"], result["noise_floor_Nm"]
    tied = tie_headline(result)
    if tied is not None:
        return f"Verdict: missing effect, {tied[0]}.", tied[1]
    return (f"Verdict: missing effect `{result['effect']}`.", "Adding it takes the weighted RMS error from "
            f"{num(stats['calibrated']['weighted_rms_Nm'])} N m to {num(stats['with_effect']['weighted_rms_Nm'])} "
            f"N m, against a noise floor of {num(floor)} N m{_angle_change(result)}.")


_MOTOR_UNITS = {"motor_current_A": "A", "motor_torque_Nm": "N m"}


def _motor_rows(result: dict) -> tuple[str, str, list[list[str]]] | None:
    """An assisted car's motor channel, where fitted: (its column, unit, rows of model, RMS, weighted RMS, peak)."""
    stats = result["statistics"]
    motor = (stats.get("calibrated") or {}).get("motor")
    if not motor:
        return None
    unit = _MOTOR_UNITS.get(motor["column"], "")
    rows = []
    for label, key in (("nominal parameters", "nominal"), ("calibrated", "calibrated"),
                       (f"with {result['effect']}", "with_effect")):
        m = (stats.get(key) or {}).get("motor")
        if m:
            rows.append([label, num(m["rms"]), num(m["weighted_rms"]), num(m["peak"])])
    return motor["column"], unit, rows


def _motor_markdown(result: dict) -> list[str]:
    found = _motor_rows(result)
    if found is None:
        return []
    column, unit, rows = found
    floor = result["statistics"]["calibrated"]["motor"]["noise_floor"]
    return (["## Motor channel", "", f"The assisted car's `{column}`, fitted beside the torque (noise floor "
             f"{num(floor)} {unit}; measured, fitted and residual drawn beside the torque in the figure).", "",
             f"| model | residual RMS ({unit}) | weighted RMS ({unit}) | peak ({unit}) |", "|---|---|---|---|"]
            + [f"| {' | '.join(r)} |" for r in rows] + [""])


def _motor_html(result: dict) -> list[str]:
    found = _motor_rows(result)
    if found is None:
        return []
    column, unit, rows = found
    floor = result["statistics"]["calibrated"]["motor"]["noise_floor"]
    return (["<h2>Motor channel</h2>", f"<p>The assisted car's {html.escape(column)}, fitted beside the torque "
             f"(noise floor {html.escape(num(floor))} {html.escape(unit)}).</p>"]
            + html_table(["model", f"residual RMS ({unit})", f"weighted RMS ({unit})", f"peak ({unit})"], rows))


def _separation_lines(result: dict) -> list[str]:
    """The candidates the data cannot tell from the named one, each with the measurement that would separate
    them if one predicts a difference above the threshold, else that none of this kind does."""
    lines = []
    threshold = result["selection"]["thresholds"].get("separating_over_floor", 1.0)
    for s in result["indistinguishable"]:
        m = s["separating_measurement"]
        where = (f"the `{m['case']}` case on `{m['surface'].replace('_', ' ')}`, where the two fitted models differ "
                 f"by {num(m['predicted_difference_rms_Nm'])} N m RMS ({num(m['over_noise_floor'])} noise floors)")
        if separating(m, result):
            lines.append(f"`{s['effect']}` (ΔBIC {num(s['delta_bic'])}): measure {where}.")
        else:
            lines.append(f"`{s['effect']}` (ΔBIC {num(s['delta_bic'])}): no test of this kind separates them; the "
                         f"most any load case or surface the data lack shows is {where}, below the "
                         f"{num(threshold)} noise floor{'s' if threshold != 1 else ''} a test needs.")
    return lines


def _nearest(result: dict) -> str:
    """For an unexplained verdict: the strongly evidenced candidate that was still not the whole story, if any."""
    thresholds = result["selection"]["thresholds"]
    top = result["ranking"][0] if result["ranking"] else None
    if top is None or top["delta_bic"] is None or top["delta_bic"] <= thresholds["bic_missing"]:
        return ""
    floor = result["noise_floor_Nm"]
    after = top["weighted_rms_after_Nm"] / floor if floor > 0 else float("nan")
    lead = f" The nearest candidate, {top['effect']}, is strongly evidenced (BIC gain {num(top['delta_bic'])}) but "
    if after > thresholds["missing_rms_ceiling"]:
        return (lead + f"leaves the weighted error at {num(after)} noise floors, above the "
                f"{num(thresholds['missing_rms_ceiling'])} that records with nothing hidden reach: "
                "it may be the closest "
                "form the library has to what is at work, not the effect itself.")
    # below the ceiling, a name also needs the error within the adequate factor or most of the excess removed
    explained = result["selection"]["explained_fraction"]
    removed = f"removes {num(100 * explained)} % of the error above the floor" if explained is not None else (
        "removes too little of the error above the floor")
    return (lead + f"leaves the weighted error at {num(after)} noise floors (a name needs "
            f"{num(thresholds['adequate_rms_factor'])}) and {removed} (a name needs "
            f"{num(100 * thresholds['explained_fraction_missing'])} %): it may be part of what is at work, most of it "
            "taken up by the calibrated parameters it is confounded with (below).")


def _angle_change(result: dict) -> str:
    """', and the angle's from ... to ... rad against ...' when the angle is fitted (the verdict's sentence)."""
    stats = result["statistics"]
    if not result.get("angle") or not stats.get("with_effect"):
        return ""
    before, after = stats["calibrated"]["angle"], stats["with_effect"]["angle"]
    return (f"; the handwheel angle's from {num(before['weighted_rms_rad'])} rad to {num(after['weighted_rms_rad'])} "
            f"rad against {num(result['angle']['noise_floor_rad'])} rad")


def _identification_lines(result: dict) -> list[str]:
    """One sentence per calibrated (or calibratable) parameter: fixed by these data, or which test would fix it."""
    lines = []
    for row in result.get("identification", []):
        key, test = row["parameter"], row["fixed_by"]
        if row["status"] == "fixed":
            lines.append(f"{key}: fixed by these data ({num(row['value'], 4)}{_value_unit(result, key)}, "
                         f"95 % interval {_interval(row['ci95'], unit=_unit(result, key))}).")
        elif row["status"] == "not calibrated":
            lines.append(f"{key}: not fixed by these data; {test} would fix it.")
        elif isinstance(test, dict) and not separating(test, result):
            lines.append(f"{key}: not fixed by these data (95 % interval "
                         f"{_interval(row['ci95'], unit=_unit(result, key))}); no test of this kind fixes it (the "
                         f"most its interval's ends differ under a load case or surface left to measure is "
                         f"{num(test['predicted_difference_rms_Nm'])} N m RMS, {num(test['over_noise_floor'])} "
                         "noise floors).")
        elif isinstance(test, dict):
            lines.append(f"{key}: not fixed by these data (95 % interval "
                         f"{_interval(row['ci95'], unit=_unit(result, key))}); the "
                         f"{test['case']} case on {test['surface'].replace('_', ' ')} "
                         "would fix it: its interval's ends differ there by "
                         f"{num(test['predicted_difference_rms_Nm'])} "
                         f"N m RMS ({num(test['over_noise_floor'])} noise floors).")
        else:
            lines.append(f"{key}: not fixed by these data, and no load case or surface left to measure fixes it.")
    return lines


def _assumed_lines(assumed: dict) -> list[str]:
    """The assist's assumed values, each at its band's ends: the calibrated fit's RMS over the floor and the verdict
    there (parksteer.diagnose.stages.assumed)."""
    nominal = assumed["nominal"]
    rows = assumed["quantities"]
    if not rows:
        return ["The vehicle file assumes none of the assist's values the model uses."]
    deciding = [r["quantity"] for r in rows if r["decides"]]
    lines = [f"Each value the vehicle file takes as assumed, replayed at the ends of its band (the calibrated fit "
             f"refitted to first order; as it stands {num(nominal['calibrated_over_floor'])} noise floors, verdict "
             f"{nominal['verdict']}). "
             + (f"The verdict depends on {', '.join(f'`{q}`' for q in deciding)}: give its value (a data sheet, "
                "`parksteer assist identify`) before trusting it." if deciding else
                "No end of any band changes the verdict."), "",
             "| quantity | value | band | over floor at its ends | verdict at its ends |", "|---|---|---|---|---|"]
    for r in rows:
        ends = r["ends"]
        lines.append(f"| {r['quantity']} | {num(r['value'], 4)} | {num(r['band'][0], 4)} to {num(r['band'][1], 4)} | "
                     f"{num(ends[0]['calibrated_over_floor'])}, {num(ends[1]['calibrated_over_floor'])} | "
                     f"{ends[0]['verdict']}, {ends[1]['verdict']}{' (decides)' if r['decides'] else ''} |")
    # why an end is not adequate, by the headline's rule (older results carry no reason)
    why = [f"- `{r['quantity']}` at {num(e['value'], 4)}: {e['verdict']}: {e['why']}."
           for r in rows for e in r["ends"] if e["verdict"] != "adequate" and e.get("why")]
    if why:
        lines += ["", "Where an end is not adequate, why:", "", *why]
    return lines


def markdown_report(result: dict, figure: str | None = None, user_figure: str | None = None) -> str:
    """A readable report of the JSON of a diagnosis (`figure`: the diagnosis's figure to link; `user_figure`: that of
    a user's effect in the model)."""
    lines = ["# Diagnosis: model against measurement", ""]
    verdict = result["verdict"]
    floor = result["noise_floor_Nm"]
    stats = result["statistics"]
    if verdict == "missing":
        head, body = _missing_headline(result)
        lines.append(f"**{head}** {body}")
    elif verdict == "adequate":
        lines.append(f"**Verdict: adequate.** With its calibrated parameters the model's weighted RMS error "
                     f"({num(stats['calibrated']['weighted_rms_Nm'])} N m) is at the noise floor ({num(floor)} N m); "
                     "these data show no missing effect.")
    else:
        lines.append(f"**Verdict: unexplained.** The calibrated model leaves a structured error (weighted RMS "
                     f"{num(stats['calibrated']['weighted_rms_Nm'])} N m against a noise floor of {num(floor)} N m) "
                     "that no candidate removes for the most part. Something outside the candidate library is at "
                     "work (or in the measurement): look at the residual below." + _nearest(result))
    lines += ["", "## Files", "", "| file | case | surface | samples | noise floor (N m) | replay uncertainty RMS (N m) "
              "| rack knot spacing (s) |", "|---|---|---|---|---|---|---|"]
    for f in result["files"]:
        lines.append(f"| {f['file']} | {f['case']} | {f['surface']} | {f['samples']} | "
                     f"{num(f['noise_floor']['total_rms'])} | {num(f['replay_uncertainty_rms_Nm'])} | "
                     f"{num(f['rack_smoothing']['knot_spacing_s'])} |")
    lines += ["", "## Error", "", "| model | RMS (N m) | weighted RMS (N m) | peak (N m) |", "|---|---|---|---|"]
    for label, key in (("nominal parameters", "nominal"), ("calibrated", "calibrated"),
                       (f"with {result['effect']}", "with_effect")):
        s = stats.get(key)
        if s:
            lines.append(f"| {label} | {num(s['rms_Nm'])} | {num(s['weighted_rms_Nm'])} | {num(s['peak_Nm'])} |")
    lines += ["", f"Noise floor {num(floor)} N m; attainable floor with the replay's uncertainty "
              f"{num(result['attainable_floor_Nm'])} N m. The weighted RMS counts each sample by its attainable "
              "error, so it is the noise floor for a perfect model; the plain RMS also holds the few samples at "
              "reversals where the rack data cannot fix the instant the rack friction turns over.", ""]
    lines += user_effect_markdown(result, user_figure)
    if result.get("angle"):
        angle = result["angle"]
        lines += ["## Handwheel angle", "", f"Fitted beside the torque in {', '.join(angle['files'])} (noise floor "
                  f"{num(angle['noise_floor_rad'])} rad, with the replay's uncertainty "
                  f"{num(angle['attainable_floor_rad'])} rad).", "",
                  "| model | RMS (rad) | RMS (degrees) | weighted RMS (rad) | peak (rad) |", "|---|---|---|---|---|"]
        for label, key in (("nominal parameters", "nominal"), ("calibrated", "calibrated"),
                           (f"with {result['effect']}", "with_effect")):
            a = (stats.get(key) or {}).get("angle")
            if a:
                lines.append(f"| {label} | {num(a['rms_rad'])} | {num(a['rms_deg'])} | {num(a['weighted_rms_rad'])} | "
                             f"{num(a['peak_rad'])} |")
        lines.append("")
    lines += _motor_markdown(result)
    lines += ["## Calibrated parameters", "", "| parameter | unit | default | fitted | 95 % interval |",
              "|---|---|---|---|---|"]
    for key, entry in result["calibrated"].items():
        ci = entry["ci95"]
        lines.append(f"| {key} | {_unit(result, key)} | {num(entry['default'], 4)} | {num(entry['value'], 4)} | "
                     f"{_interval(ci, unit=_unit(result, key))} |")
    lines += ["", "## Candidates", "", "| candidate | score | ΔBIC | fitted strength | weighted RMS after (N m) | "
              "identifiable fraction |", "|---|---|---|---|---|---|"]
    for c in result["ranking"]:
        fitted = strength_text(c, result.get("units", {}))
        lines.append(f"| {c['effect']} | {num(c['score'])} | {num(c['delta_bic'])} | {fitted} | "
                     f"{num(c['weighted_rms_after_Nm'])} | {num(c['identifiable_fraction'], 2)} |")
    if result["indistinguishable"]:
        lines += ["", "## Indistinguishable by these data", ""]
        lines += [f"- {line}" for line in _separation_lines(result)]
    if result["confounded"]:
        lines += ["", "## Confounded with the calibrated parameters", ""]
        for c in result["confounded"]:
            line = (f"- `{c['effect']}`: only {num(100 * c['identifiable_fraction'], 2)} % of its signature is not "
                    f"also made by `{c['confounded_with']}`; these data cannot tell it from a change of that "
                    "parameter, whose calibrated value holds only if it is absent.")
            m = c.get("separating_measurement")
            if m and not confound_separates(m):
                line += (f" No test of this kind separates them: at a strength that changes this torque by "
                         f"{num(m['change_here_rms_Nm'])} N m RMS the calibrated parameters leave "
                         f"{num(m['left_here_rms_Nm'])} N m of it here, and under no load case or surface the data "
                         f"lack would they leave more (at most {num(m['predicted_difference_rms_Nm'])} N m, "
                         f"{num(m['over_noise_floor'])} noise floors, with the `{m['case']}` case on "
                         f"`{m['surface'].replace('_', ' ')}`).")
            elif m:
                line += (f" At a strength that changes this torque by {num(m['change_here_rms_Nm'])} N m RMS, the "
                         f"calibrated parameters take up all but {num(m['left_here_rms_Nm'])} N m "
                         f"({num(m['left_here_over_noise_floor'])} noise floors) of it; measure the `{m['case']}` "
                         f"case on `{m['surface'].replace('_', ' ')}`, where it would still change the torque by "
                         f"{num(m['predicted_difference_rms_Nm'])} N m RMS ({num(m['over_noise_floor'])} noise "
                         f"floors, {num(100 * m['predicted_difference_rms_Nm'] / m['change_here_rms_Nm'], 2)} % of "
                         "its change here).")
            lines.append(line)
    if result.get("identification"):
        lines += ["", "## What these data fix", ""] + [f"- {line}" for line in _identification_lines(result)]
    if result.get("assumed"):
        lines += ["", "## What the verdict owes to the assist's assumed values", ""] + _assumed_lines(result["assumed"])
    if result.get("baseline") is not None:
        b = result["baseline"]
        lo, hi = b["ci95"]
        lines += ["", "## The identified boost table's gain", "",
                  f"This record's gain differs from the table's by {num(100 * b['strength'])} % (95 %: {num(100 * lo)} "
                  f"to {num(100 * hi)} %); the baseline the table was identified from fixes its gain to "
                  f"+-{num(100 * b['gain_uncertainty'])} %. "
                  + ("Within that, the difference is the baseline's own, not an effect of the car: the verdict is "
                     "adequate." if b["within"] else "The difference reaches beyond it: the car's map has changed "
                     "since the baseline, or the baseline was too short to fix it.")]
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


def write_markdown(path: str | Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


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




def html_report(result: dict, figures: list[tuple[str, str]], phases: list[dict], ladder: dict | None = None,
                title: str | None = None) -> str:
    """One self-contained page: the verdict, the files, the figures (`(caption, svg text)`, inlined), the residual
    by phase (`phases`, from :func:`phase_residuals`), the error ladder (:meth:`parksteer.diagnose.ladder.Ladder.
    as_dict`), the fitted values with their 95 % intervals, the ranking."""
    title = title or "Diagnosis: model against measurement"
    stats, floor = result["statistics"], result["noise_floor_Nm"]
    verdict = result["verdict"]
    if verdict == "missing":
        text = " ".join(_missing_headline(result)).replace("`", "")
    elif verdict == "adequate":
        text = (f"Verdict: adequate. The calibrated model's weighted RMS error "
                f"({num(stats['calibrated']['weighted_rms_Nm'])} N m) is at the noise floor ({num(floor)} N m).")
    else:
        text = (f"Verdict: unexplained. The calibrated model leaves a structured error (weighted RMS "
                f"{num(stats['calibrated']['weighted_rms_Nm'])} N m against a noise floor of {num(floor)} N m) "
                "that no candidate removes." + _nearest(result))
    out = ["<!DOCTYPE html>", '<html lang="en">', "<head>", '<meta charset="utf-8">',
           f"<title>{html.escape(title)}</title>", f"<style>{_STYLE}</style>", "</head>", "<body>",
           f"<h1>{html.escape(title)}</h1>", f'<p class="verdict">{html.escape(text)}</p>',
           f"<p>Model: {html.escape(', '.join(result['model']['effects']))}.</p>", "<h2>Files</h2>"]
    out += html_table(["file", "case", "surface", "samples", "noise floor (N m)"],
                  [[f["file"], f["case"], f["surface"], f["samples"], num(f["noise_floor"]["total_rms"])]
                   for f in result["files"]])
    if result.get("angle"):
        angle = stats["calibrated"]["angle"]
        out.append(f"<p>Handwheel angle fitted beside the torque in {html.escape(', '.join(result['angle']['files']))}:"
                   f" calibrated model's angle residual RMS {html.escape(num(angle['rms_rad']))} rad "
                   f"({html.escape(num(angle['rms_deg']))} degrees), noise floor "
                   f"{html.escape(num(result['angle']['noise_floor_rad']))} rad.</p>")
    out += user_effect_html(result)
    out += _motor_html(result)
    for k, (caption, svg) in enumerate(figures):
        out += ["<figure>", inline_svg(svg, f"f{k}-"), f"<figcaption>{html.escape(caption)}</figcaption>", "</figure>"]
    out.append("<h2>Residual by phase</h2>")
    effect = result["effect"] if verdict == "missing" else None
    head = ["file", "phase", "samples", "calibrated RMS (N m)"] + ([f"with {effect} RMS (N m)"] if effect else [])
    out += html_table(head + ["noise floor (N m)"],
                  [[r["file"], r["phase"].replace("_", " "), r["samples"], num(r["calibrated_rms_Nm"])]
                   + ([num(r["with_effect_rms_Nm"])] if effect else []) + [num(r["noise_floor_Nm"])] for r in phases])
    if ladder is not None:
        out.append("<h2>Error ladder</h2>")
        out += html_table(["rung", "effects", "RMS (N m)", "weighted RMS (N m)", "weighted RMS / noise floor"],
                      [[r["label"], ", ".join(r["effects"]), num(r["rms_Nm"]), num(r["weighted_rms_Nm"]),
                        num(r["over_floor"])] for r in ladder["rungs"]])
        out.append(f"<p>Noise floor {html.escape(num(ladder['noise_floor_Nm']))} N m; with the replay's uncertainty "
                   f"{html.escape(num(ladder['attainable_floor_Nm']))} N m.</p>")
    out.append("<h2>Fitted values</h2>")
    rows = [[key, _unit(result, key), num(e["default"], 4), num(e["value"], 4),
             _interval(e["ci95"], unit=_unit(result, key))] for key, e in result["calibrated"].items()]
    out += html_table(["parameter", "unit", "default", "fitted", "95 % interval"], rows)
    if result.get("identification"):
        out.append("<h2>What these data fix</h2>")
        out += ["<ul>"] + [f"<li>{html.escape(line)}</li>" for line in _identification_lines(result)] + ["</ul>"]
    if result.get("signature"):
        out.append("<h2>The residual's signature</h2>")
        out += ["<ul>"] + [f"<li>{html.escape(line)}</li>" for line in signature_lines(result)] + ["</ul>"]
    out.append("<h2>Ranking of the candidate effects</h2>")
    rows = []
    for c in result["ranking"]:
        rows.append([c["effect"], num(c["score"]), num(c["delta_bic"]), strength_text(c, result.get("units", {})),
                     num(c["weighted_rms_after_Nm"]), num(c["identifiable_fraction"], 2)])
    out += html_table(["candidate", "score", "ΔBIC", "fitted strength (95 % interval)", "weighted RMS after (N m)",
                   "identifiable fraction"], rows)
    if result["indistinguishable"]:
        out.append("<h2>Indistinguishable by these data</h2>")
        out += ["<ul>"] + [f"<li>{html.escape(line.replace('`', ''))}</li>"
                           for line in _separation_lines(result)] + ["</ul>"]
    if result["unobservable"]:
        out.append(f"<p>Unobservable in these data: {html.escape(', '.join(result['unobservable']))}.</p>")
    out += [f"<p>Cost: {result['cost']['replays']} replays.</p>", "</body>", "</html>"]
    return "\n".join(out) + "\n"
