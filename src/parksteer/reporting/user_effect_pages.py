"""The report's section on a user's own effect (:mod:`parksteer.diagnose.stages.user_effect`): the ladder without it
and with it, its fitted strengths with their intervals, the residual by phase before and after, and the sweep of its
strengths from 0 (the section itself: :func:`parksteer.reporting.sections.report_sections`)."""

from __future__ import annotations

from .report import interval_text, num


def user_effect_tables(result: dict) -> list[tuple[str, list[str], list[list]]]:
    """(title, head, rows) of each table of the ``user_effect`` section: the ladder, the fitted strengths, the
    residual by phase, the sweep."""
    found = result["user_effect"]
    ladder = ("The error ladder", ["model", "effects", "RMS (N m)", "weighted RMS (N m)", "weighted RMS / floor"],
              [[r["label"], ", ".join(r["effects"]), num(r["rms_Nm"]), num(r["weighted_rms_Nm"]),
                num(r["over_floor"])] for r in found["rungs"]])
    strengths = ("Fitted strengths (with the calibrated parameters)",
                 ["strength", "fitted", "95 % interval", "unit", "declared bounds"],
                 [[key, num(e["value"], 4), interval_text(e["ci95"], "", 4), e["unit"],
                   interval_text(e["bounds"], "", 4) if e.get("bounds") else "-"] for key, e in found["strengths"].items()])
    phases = ("Residual by phase, without it and with it", ["file", "phase", "samples", "without it, RMS (N m)", "with it, RMS (N m)",
                                    "noise floor (N m)"],
              [[r["file"], r["phase"].replace("_", " "), r["samples"], num(r["without_rms_Nm"]),
                num(r["with_rms_Nm"]), num(r["noise_floor_Nm"])] for r in found["phases"]])
    sweep = found["sweep"]
    one = sweep["keys"][0] if len(sweep["keys"]) == 1 else None
    unit = found["strengths"][one]["unit"] if one else ""
    grow = ("The error as the strengths grow to their fitted values, the other parameters held at the fit",
            ["fraction of the fitted strength" + ("" if one else "s")] + ([f"{one} ({unit})"] if one else [])
            + ["weighted RMS (N m)", "weighted RMS / floor"],
            [[num(f, 2)] + ([num(sweep["values"][one][i], 4)] if one else [])
             + [num(sweep["weighted_rms_Nm"][i]), num(sweep["over_floor"][i])]
             for i, f in enumerate(sweep["fractions"])])
    return [ladder, strengths, phases, grow]


def user_effect_sentence(result: dict) -> str:
    found = result["user_effect"]
    rungs = found["rungs"]
    return (f"With {', '.join(found['effects'])} in the model, its free strengths fitted with the calibrated "
            f"parameters, the weighted RMS error goes from {num(rungs[1]['over_floor'])} noise floors (calibrated "
            f"without it) to {num(rungs[-1]['over_floor'])} (noise floor {num(found['noise_floor_Nm'])} N m); the "
            f"verdict above is on the model with it.")


def user_effect_intervals(result: dict) -> str:
    """What the intervals are: the strengths' (or why they have none), and the car's, held at the strengths' fit,
    naming each car parameter whose signature the strengths mostly make too."""
    found = result["user_effect"]
    reasons = sorted({e["why_not_fixed"] for e in found["strengths"].values() if e.get("why_not_fixed")})
    without = [k for k, e in found["strengths"].items() if e.get("why_not_fixed")]
    text = ""
    if reasons:
        which = "No strength has" if len(without) == len(found["strengths"]) else \
            f"{', '.join(f'`{k}`' for k in without)} {'has' if len(without) == 1 else 'have'}"
        text = f"{which} a 95 % interval: {'; '.join(reasons)}. "
    text += ("The car's calibrated parameters' intervals (below, and what these data fix) are those with the "
             "strengths held at their fitted values.")
    threshold = result["selection"]["thresholds"]["confounded_fraction"]
    shared = {k: v for k, v in found.get("not_made_by_strengths", {}).items() if v < threshold}
    for key, share in shared.items():
        text += (f" Only {num(100 * share, 2)} % of `{key}`'s signature is not also made by the strengths: its value "
                 "holds only with the effect's shape as fitted.")
    return text
