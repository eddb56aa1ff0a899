"""The report's section on a user's own effect (:mod:`parksteer.diagnose.stages.user_effect`): the ladder without it
and with it, its fitted strengths with their intervals, the residual by phase before and after, and the sweep of its
strengths from 0, as markdown and as HTML."""

from __future__ import annotations

import html

from .report import html_table, interval_text, num




def _user_effect_tables(result: dict) -> list[tuple[str, list[str], list[list]]]:
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
    phases = ("Residual by phase", ["file", "phase", "samples", "without it, RMS (N m)", "with it, RMS (N m)",
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


def _user_effect_sentence(result: dict) -> str:
    found = result["user_effect"]
    rungs = found["rungs"]
    return (f"With {', '.join(found['effects'])} in the model, its free strengths fitted with the calibrated "
            f"parameters, the weighted RMS error goes from {num(rungs[1]['over_floor'])} noise floors (calibrated "
            f"without it) to {num(rungs[-1]['over_floor'])} (noise floor {num(found['noise_floor_Nm'])} N m); the "
            f"verdict above is on the model with it.")


def user_effect_markdown(result: dict, figure: str | None = None) -> list[str]:
    """The markdown section of a user's effect (none when the diagnosis has no ``user_effect``)."""
    if not result.get("user_effect"):
        return []
    lines = [f"## Your effect: {', '.join(result['user_effect']['effects'])}", "", _user_effect_sentence(result)]
    for title, head, rows in _user_effect_tables(result):
        lines += ["", f"### {title}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    if figure:
        lines += ["", f"![your effect: the ladder, the record, the residual by phase, the error falling]({figure})"]
    return lines + [""]


def user_effect_html(result: dict) -> list[str]:
    """The HTML section of a user's effect (none when the diagnosis has no ``user_effect``)."""
    if not result.get("user_effect"):
        return []
    out = [f"<h2>Your effect: {html.escape(', '.join(result['user_effect']['effects']))}</h2>",
           f"<p>{html.escape(_user_effect_sentence(result))}</p>"]
    for title, head, rows in _user_effect_tables(result):
        out.append(f"<h3>{html.escape(title)}</h3>")
        out += html_table(head, rows)
    return out
