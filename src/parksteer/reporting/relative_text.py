"""The sentence a report gives a diagnosis judged against a car's baseline (``relative_to`` of its JSON)."""

from __future__ import annotations

from .report import num, shown_unit


def relative_sentence(result: dict) -> str | None:
    """What the verdict means against the baseline, and how "as the baseline" was set; None without a baseline."""
    rel = result.get("relative_to")
    if not rel:
        return None
    name = rel["baseline"] or "learnt from " + ", ".join(rel["records"])
    t = rel["threshold"]
    band = result["selection"]["thresholds"]["bic_indistinguishable"]
    held = f"with {rel['form']} held at the baseline's strengths" if rel["form"] else "the healthy records were adequate"
    verdict = result["verdict"]
    if verdict == "adequate":
        said = "As the baseline: nothing changed beyond what healthy records of this car differ by."
    elif verdict == "missing":
        best = next((r for r in result["ranking"] if r["effect"] == result["effect"]), {})
        key = best.get("strength_parameter", "")
        strength = (best.get("parameters") or {}).get(key, {})
        ci = strength.get("ci95")
        unit = shown_unit(result.get("units", {}).get(key, ""))
        unit = f" {unit}" if unit else ""
        before = (rel.get("calibrated") or {}).get(key) if result["effect"].startswith("changed:") else None
        if before is not None:  # a calibrated value that moved (parksteer.diagnose.baseline_changed)
            was = before.get("ci95")
            said = (f"Changed: {key}, from {num(before['value'])}{unit}"
                    + (f" (95 %: {num(was[0])} to {num(was[1])})" if was else "")
                    + f" to {num(strength['value'])}{unit}"
                    + (f" (95 %: {num(ci[0])} to {num(ci[1])}{unit})" if ci else "")
                    + "; a calibrated value of the car, not a library effect.")
        else:
            said = (f"Changed: {result['effect']}" + (f", {num(strength['value'])}{unit}" if "value" in strength
                                                      else "")
                    + (f" (95 %: {num(ci[0])} to {num(ci[1])}{unit})" if ci else "") + ".")
    else:
        said = "Changed, outside the library: see the residual's signature below."
    return (f"{name} (content hash {rel['content_hash']}; {held}). {said} \"As the baseline\" allows up to "
            f"{num(t['over_floor'])} noise floors and a BIC gain of {num(t['bic_per_sample'])} per sample, and a name "
            f"is confident only where it leads the second best by more than {num(band)} (the settings' band, or "
            f"{num(t['lead_per_sample'])} per sample times the record's samples where that is more), from "
            f"{t['method']}.")
