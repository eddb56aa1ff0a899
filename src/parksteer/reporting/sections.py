"""The sections of a diagnosis's report, one structure that both pages render (:mod:`parksteer.reporting.pages`: the
markdown report and the HTML page): each section a title and its parts (:mod:`parksteer.reporting.parts`: a
paragraph, a list, a table or a figure's place), from the diagnosis's JSON (:func:`parksteer.reporting.report.diagnosis_dict`) and, where the caller computed
them, the residual by phase (:func:`parksteer.reporting.report.phase_residuals`) and the error ladder
(:meth:`parksteer.reporting.ladder.Ladder.as_dict`). Text is written once, with markdown's backticks around names;
the HTML page drops them."""

from __future__ import annotations

from .report import (confound_separates, interval_text, num, separating, shown_unit, signature_lines,
                     strength_text, tie_headline)
from .cost import cost_line
from .parts import Bullets, FigurePlace, Paragraph, Section, table
from .relative_text import relative_sentence
from .user_effect_pages import user_effect_intervals, user_effect_sentence, user_effect_tables


def _interval(ci, digits: int = 4, unit: str = "") -> str:
    return interval_text(ci, unit, digits)


def _unit(result: dict, key: str) -> str:
    return result.get("units", {}).get(key, "")


def _value_unit(result: dict, key: str) -> str:
    unit = shown_unit(_unit(result, key))
    return f" {unit}" if unit else ""


def _missing_headline(result: dict) -> tuple[str, str]:
    """The verdict's sentence for a named effect, (head, body): the tie first where candidates lie within the
    information criterion's threshold of it (:func:`parksteer.reporting.report.tie_headline`)."""
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


def _with_strengths(result: dict, key: str) -> str:
    """With a user's free strengths whose signatures make most of `key`'s: the condition its interval holds on."""
    share = ((result.get("user_effect") or {}).get("not_made_by_strengths") or {}).get(key)
    if share is None or share >= result["selection"]["thresholds"]["confounded_fraction"]:
        return ""
    return (f", with your effect's strengths held at their fit: only {num(100 * share, 2)} % of its signature is "
            "not also made by them")


def _identification_lines(result: dict) -> list[str]:
    """One sentence per calibrated (or calibratable) parameter: fixed by these data, or which test would fix it."""
    lines = []
    for row in result.get("identification", []):
        key, test = row["parameter"], row["fixed_by"]
        if row["status"] == "fixed":
            lines.append(f"{key}: fixed by these data ({num(row['value'], 4)}{_value_unit(result, key)}, "
                         f"95 % interval {_interval(row['ci95'], unit=_unit(result, key))}"
                         f"{_with_strengths(result, key)}).")
        elif row["status"] == "not calibrated" and test is None:
            lines.append(f"{key}: not fixed by these data, and no record of this car fixes it: it shows only in the "
                         "handwheel angle, which the diagnosis of an assisted car does not replay.")
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


# What `parksteer assist identify` measures (diagnose.identify.assist_identify): the product k_t eta N (written as
# the torque constant, so it also fixes the efficiency and the reduction as a product), the motor's friction and
# inertia, the back-driven efficiency.
_IDENTIFIED = ("torque_constant", "motor_friction_torque", "motor_inertia", "back_efficiency")
_PRODUCT_FACTORS = ("efficiency", "reduction_ratio")


def _identify_measures(quantity: str, rows: list[dict]) -> bool:
    """Whether `parksteer assist identify` would measure the assumed `quantity`: one it identifies, or a factor of the
    product while the product (the torque constant) is still assumed (once identified, only a data sheet helps)."""
    name, _, key = quantity.rpartition(".")
    if key in _IDENTIFIED:
        return True
    return key in _PRODUCT_FACTORS and any(r["quantity"] == f"{name}.torque_constant" for r in rows)


def _assumed_parts(assumed: dict) -> list:
    """The assist's assumed values, each at its band's ends: the calibrated fit's RMS over the floor and the verdict
    there (parksteer.diagnose.stages.assumed)."""
    nominal = assumed["nominal"]
    rows = assumed["quantities"]
    if not rows:
        return [Paragraph("The vehicle file assumes none of the assist's values the model uses.")]
    deciding = [r["quantity"] for r in rows if r["decides"]]
    measurable = [q for q in deciding if _identify_measures(q, rows)]
    factors = any(q.rpartition(".")[2] in _PRODUCT_FACTORS for q in measurable)
    where = "a data sheet" + (f"; `parksteer assist identify` on a baseline record fixes "
                              f"{', '.join(f'`{q}`' for q in measurable)}"
                              + (", the efficiency and the reduction through their product with the torque "
                                 "constant" if factors else "") if measurable else "")
    text = (f"Each value the vehicle file takes as assumed, replayed at the ends of its band (the calibrated fit "
            f"refitted to first order; as it stands {num(nominal['calibrated_over_floor'])} noise floors, verdict "
            f"{nominal['verdict']}). "
            + (f"The verdict depends on {', '.join(f'`{q}`' for q in deciding)}: give "
               f"{'its value' if len(deciding) == 1 else 'their values'} ({where}) before trusting it."
               if deciding else "No end of any band changes the verdict."))
    body = [[r["quantity"], num(r["value"], 4), f"{num(r['band'][0], 4)} to {num(r['band'][1], 4)}",
             f"{num(r['ends'][0]['calibrated_over_floor'])}, {num(r['ends'][1]['calibrated_over_floor'])}",
             f"{r['ends'][0]['verdict']}, {r['ends'][1]['verdict']}{' (decides)' if r['decides'] else ''}"]
            for r in rows]
    # why an end is not adequate, by the headline's rule (older results carry no reason)
    why = tuple(f"`{r['quantity']}` at {num(e['value'], 4)}: {e['verdict']}: {e['why']}."
                for r in rows for e in r["ends"] if e["verdict"] != "adequate" and e.get("why"))
    return [Paragraph(text), table(["quantity", "value", "band", "over floor at its ends", "verdict at its ends"],
                                   body)] + ([Paragraph("Where an end is not adequate, why:"), Bullets(why)] if why else [])


def _verdict(result: dict) -> Paragraph:
    verdict, floor, stats = result["verdict"], result["noise_floor_Nm"], result["statistics"]
    if verdict == "missing":
        head, body = _missing_headline(result)
        return Paragraph(body, lead=head)
    if verdict == "adequate":
        return Paragraph(f"With its calibrated parameters the model's weighted RMS error "
                         f"({num(stats['calibrated']['weighted_rms_Nm'])} N m) is at the noise floor ({num(floor)} N m); "
                         "these data show no missing effect.", lead="Verdict: adequate.")
    return Paragraph(f"The calibrated model leaves a structured error (weighted RMS "
                     f"{num(stats['calibrated']['weighted_rms_Nm'])} N m against a noise floor of {num(floor)} N m) "
                     "that no candidate removes for the most part. Something outside the candidate library is at "
                     "work (or in the measurement): look at the residual below." + _nearest(result),
                     lead="Verdict: unexplained.")


def _error_rows(result: dict, part: str, columns: tuple[str, ...]) -> list[list[str]]:
    """The error of the nominal, calibrated and (with a named effect) grown model: `columns` of the statistics,
    or of their `part` (``angle``, ``motor``)."""
    stats, rows = result["statistics"], []
    for label, key in (("nominal parameters", "nominal"), ("calibrated", "calibrated"),
                       (f"with {result['effect']}", "with_effect")):
        s = stats.get(key) or {}
        s = s.get(part) if part else s
        if s:
            rows.append([label, *(num(s[c]) for c in columns)])
    return rows


def _confounded_lines(result: dict) -> list[str]:
    lines = []
    for c in result["confounded"]:
        line = (f"`{c['effect']}`: only {num(100 * c['identifiable_fraction'], 2)} % of its signature is not "
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
    return lines


def user_effect_section(result: dict) -> list[Section]:
    """A user's effect in the model (none without one): the sentence, then its tables, each a section of its own."""
    if not result.get("user_effect"):
        return []
    out = [Section(f"Your effect: {', '.join(result['user_effect']['effects'])}",
                   (Paragraph(user_effect_sentence(result)), FigurePlace("user_effect")))]
    for title, head, rows in user_effect_tables(result):
        parts = [table(head, rows)]
        if title.startswith("Fitted strengths"):
            parts.append(Paragraph(user_effect_intervals(result)))
        out.append(Section(title, tuple(parts), level=3))
    return out


def report_sections(result: dict, phases: list[dict] | None = None, ladder: dict | None = None) -> list[Section]:
    """The report of the JSON `result` of a diagnosis as sections, in the order both pages show them; the residual
    by phase and the error ladder only where given (`phases`, `ladder`: both pages of one run get the same)."""
    floor, stats = result["noise_floor_Nm"], result["statistics"]
    relative = relative_sentence(result)
    out = [Section(None, (_verdict(result),) + ((Paragraph(relative, "Relative to baseline"),) if relative else ()))]
    out.append(Section("Files", (
        Paragraph(f"Model: {', '.join(f'`{e}`' for e in result['model']['effects'])}."),
        table(["file", "case", "surface", "samples", "noise floor (N m)", "replay uncertainty RMS (N m)",
               "rack knot spacing (s)"],
              [[f["file"], f["case"], f["surface"], f["samples"], num(f["noise_floor"]["total_rms"]),
                num(f["replay_uncertainty_rms_Nm"]), num(f["rack_smoothing"]["knot_spacing_s"])]
               for f in result["files"]]))))
    out.append(Section("Error", (
        table(["model", "RMS (N m)", "weighted RMS (N m)", "peak (N m)"],
              _error_rows(result, "", ("rms_Nm", "weighted_rms_Nm", "peak_Nm"))),
        Paragraph(f"Noise floor {num(floor)} N m; attainable floor with the replay's uncertainty "
                  f"{num(result['attainable_floor_Nm'])} N m. The weighted RMS counts each sample by its attainable "
                  "error, so it is the noise floor for a perfect model; the plain RMS also holds the few samples at "
                  "reversals where the rack data cannot fix the instant the rack friction turns over."),
        FigurePlace("diagnosis"))))
    out += user_effect_section(result)
    if result.get("angle"):
        angle = result["angle"]
        out.append(Section("Handwheel angle", (
            Paragraph(f"Handwheel angle fitted beside the torque in {', '.join(angle['files'])} (noise floor "
                      f"{num(angle['noise_floor_rad'])} rad, with the replay's uncertainty "
                      f"{num(angle['attainable_floor_rad'])} rad)."),
            table(["model", "RMS (rad)", "RMS (degrees)", "weighted RMS (rad)", "peak (rad)"],
                  _error_rows(result, "angle", ("rms_rad", "rms_deg", "weighted_rms_rad", "peak_rad"))))))
    motor = (stats.get("calibrated") or {}).get("motor")
    if motor:
        unit = _MOTOR_UNITS.get(motor["column"], "")
        out.append(Section("Motor channel", (
            Paragraph(f"The assisted car's `{motor['column']}`, fitted beside the torque (noise floor "
                      f"{num(motor['noise_floor'])} {unit}; measured, fitted and residual drawn beside the torque in "
                      "the diagnosis's figure)."),
            table(["model", f"residual RMS ({unit})", f"weighted RMS ({unit})", f"peak ({unit})"],
                  _error_rows(result, "motor", ("rms", "weighted_rms", "peak"))))))
    if phases is not None:
        effect = result["effect"] if result["verdict"] == "missing" else None
        head = ["file", "phase", "samples", "calibrated RMS (N m)"] + ([f"with {effect} RMS (N m)"] if effect else [])
        out.append(Section("Residual by phase", (
            table(head + ["noise floor (N m)"],
                  [[r["file"], r["phase"].replace("_", " "), r["samples"], num(r["calibrated_rms_Nm"])]
                   + ([num(r["with_effect_rms_Nm"])] if effect else []) + [num(r["noise_floor_Nm"])]
                   for r in phases]),
            FigurePlace("phases"))))
    if ladder is not None:
        out.append(Section("Error ladder", (
            table(["rung", "effects", "RMS (N m)", "weighted RMS (N m)", "weighted RMS / noise floor"],
                  [[r["label"], ", ".join(r["effects"]), num(r["rms_Nm"]), num(r["weighted_rms_Nm"]),
                    num(r["over_floor"])] for r in ladder["rungs"]]),
            Paragraph(f"Noise floor {num(ladder['noise_floor_Nm'])} N m; with the replay's uncertainty "
                      f"{num(ladder['attainable_floor_Nm'])} N m."),
            FigurePlace("ladder"))))
    out.append(Section("Calibrated parameters", (
        table(["parameter", "unit", "default", "fitted", "95 % interval"],
              [[key, _unit(result, key), num(e["default"], 4), num(e["value"], 4),
                _interval(e["ci95"], unit=_unit(result, key))] for key, e in result["calibrated"].items()]),)))
    out.append(Section("Candidates", (
        table(["candidate", "score", "ΔBIC", "fitted strength", "weighted RMS after (N m)", "identifiable fraction"],
              [[c["effect"], num(c["score"]), num(c["delta_bic"]), strength_text(c, result.get("units", {})),
                num(c["weighted_rms_after_Nm"]), num(c["identifiable_fraction"], 2)] for c in result["ranking"]]),)))
    if result["indistinguishable"]:
        out.append(Section("Indistinguishable by these data", (Bullets(tuple(_separation_lines(result))),)))
    if result["confounded"]:
        out.append(Section("Confounded with the calibrated parameters", (Bullets(tuple(_confounded_lines(result))),)))
    if result.get("identification"):
        out.append(Section("What these data fix", (Bullets(tuple(_identification_lines(result))),)))
    if result.get("assumed"):
        out.append(Section("What the verdict owes to the assist's assumed values",
                           tuple(_assumed_parts(result["assumed"]))))
    if result.get("baseline") is not None:
        b = result["baseline"]
        lo, hi = b["ci95"]
        out.append(Section("The identified boost table's gain", (Paragraph(
            f"This record's gain differs from the table's by {num(100 * b['strength'])} % (95 %: {num(100 * lo)} "
            f"to {num(100 * hi)} %); the baseline the table was identified from fixes its gain to "
            f"+-{num(100 * b['gain_uncertainty'])} %. "
            + ("Within that, the difference is the baseline's own, not an effect of the car: the verdict is "
               "adequate." if b["within"] else "The difference reaches beyond it: the car's map has changed "
               "since the baseline, or the baseline was too short to fix it.")),)))
    notes = []
    if result["unobservable"]:
        notes.append(Paragraph(f"Unobservable in these data as replayed (even the largest strength moves the replayed "
                               f"torque by less than a tenth of the noise floor): {', '.join(result['unobservable'])}."))
    if result["untestable"]:
        notes.append(Paragraph(f"Not testable (no strength parameter): {', '.join(result['untestable'])}."))
    if notes:
        out.append(Section(None, tuple(notes)))
    if result.get("signature"):
        out.append(Section("The residual's signature", (Bullets(tuple(signature_lines(result))),)))
    return out + [Section(None, (Paragraph(cost_line(result["cost"])),))]
