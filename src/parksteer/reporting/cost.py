"""The cost line of a diagnosis report: its replays and seconds, in all and by stage."""

from __future__ import annotations


def cost_line(cost: dict) -> str:
    """The replays and the seconds of the diagnosis, in all and by stage (the stages that replayed or took a
    hundredth of a second), from the result's ``cost``: where a diagnosis spends its time."""
    timings = cost.get("timings_s", {})
    by_stage = cost.get("replays_by_stage", {})  # the replays run when each stage ended
    parts, before = [], 0
    for stage, seconds in timings.items():
        replays = by_stage.get(stage, before) - before
        before = by_stage.get(stage, before)
        if replays or seconds >= 0.01:
            parts.append(f"{stage.replace('_', ' ')}: {replays} replays, {seconds:.2f} s")
    total = sum(timings.values())
    line = f"Cost: {cost['replays']} replays"
    return line + (f", {total:.2f} s ({'; '.join(parts)})." if timings else ".")
