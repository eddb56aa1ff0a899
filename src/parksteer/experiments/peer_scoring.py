"""Scoring the diagnosis and its peers on the same cases: each method's verdicts against the truth
(:func:`score_method`), a peer's setting tuned on the tuning split (:func:`tune`), and the comparison the figure and
the paper quote (:func:`compare`)."""

from __future__ import annotations

import numpy as np

from .peer_methods import FROLS_SETTINGS, METHOD_LABELS, METHODS, STLSQ_SETTINGS, settings_of


def answer_of(case: dict, method: str, setting: str | None) -> tuple[str, str | None]:
    if method == "diagnose":
        return case["diagnosis"]["verdict"], case["diagnosis"]["effect"]
    entry = case[method][setting]
    return entry["verdict"], entry["effect"]


def _named(case: dict, method: str, verdict: str, effect: str | None) -> bool:
    hidden = case["truth"]["hidden"]
    if method == "diagnose":  # the variation benchmark's own count: named first or in the reported group
        return bool(case["diagnosis"]["outcome"].get("named"))
    return verdict == "missing" and effect == hidden


def score_method(cases: list[dict], method: str, setting: str | None = None) -> dict:
    """One method's numbers over `cases`: hidden library effects named (of those of at least NAMED_MIN_STEPS),
    nulls called adequate, and on the out-of-class rivals what it said (closest or related candidate, unrelated
    candidate, unexplained, adequate). A peer's unrelated candidate is a confident wrong answer (a peer reports no
    doubt beside it); the diagnosis's is confident when its BIC margin is beyond its indistinguishable band
    (:func:`parksteer.experiments.outclass.outcome`)."""
    from .variations import NAMED_MIN_STEPS

    hidden = [c for c in cases if c["benchmark"] == "variations" and c["truth"]["hidden"] is not None
              and (c["truth"]["steps_requested"] or 0.0) >= NAMED_MIN_STEPS]
    nulls = [c for c in cases if (c["benchmark"] == "variations" and c["truth"]["hidden"] is None)
             or (c["benchmark"] == "outclass" and c["truth"]["kind"] == "null")]
    rivals = [c for c in cases if c["benchmark"] == "outclass" and c["truth"]["kind"] == "rival"]
    named = sum(_named(c, method, *answer_of(c, method, setting)) for c in hidden)
    adequate = sum(answer_of(c, method, setting)[0] == "adequate" for c in nulls)
    relations = {"closest or related": 0, "unrelated": 0, "unexplained": 0, "adequate": 0}
    confident_wrong = 0
    for c in rivals:
        verdict, effect = answer_of(c, method, setting)
        related = {c["truth"].get("closest")} | set(c["truth"].get("related") or ())
        if verdict != "missing":
            relations[verdict] += 1
        elif effect in related:
            relations["closest or related"] += 1
        else:
            relations["unrelated"] += 1
            confident_wrong += 1 if method != "diagnose" else int(bool(c["diagnosis"]["outcome"]["confident_wrong"]))
    times = [c["time_s"]["diagnose"] if method == "diagnose" else c["time_s"][method] for c in cases]
    upstream = [c["time_s"]["upstream"] for c in cases]
    replays = [c["replays"]["diagnose"] if method == "diagnose" else 0 for c in cases]
    replays_upstream = [c["replays"]["diagnose" if method == "diagnose" else "upstream"] for c in cases]
    return {
        "method": method, "label": METHOD_LABELS[method], "setting": setting,
        "named": [named, len(hidden)], "named_rate": named / len(hidden) if hidden else None,
        "null_adequate": [adequate, len(nulls)], "null_adequate_rate": adequate / len(nulls) if nulls else None,
        "outclass": relations, "outclass_rivals": len(rivals), "confident_wrong": confident_wrong,
        # model replays a record (the same on any machine): a peer's own are none, it regresses what it is given
        "replays_median": _median_count(replays), "replays_with_upstream_median": _median_count(replays_upstream),
        # machine times (benchmarks/bench_peers.py prints them; the paper quotes the replays)
        "time_s_median": float(np.median(times)) if times else None,
        # a peer needs the calibrated residual and the signatures: the diagnosis's own steps up to its scores
        "time_with_upstream_s_median": (float(np.median(np.add(times, upstream))) if method != "diagnose"
                                        else (float(np.median(times)) if times else None)),
    }


def _median_count(counts: list[int]) -> int | float | None:
    """The median of whole counts: whole, or a half where it falls between two."""
    if not counts:
        return None
    median = float(np.median(counts))
    return int(median) if median.is_integer() else median


def tuning_score(numbers: dict) -> float:
    """What a setting is tuned for: the mean of the named rate and the nulls' adequate rate (each counted where
    the split has cases of its kind)."""
    rates = [r for r in (numbers["named_rate"], numbers["null_adequate_rate"]) if r is not None]
    return float(np.mean(rates)) if rates else 0.0


def tune(cases: list[dict], method: str) -> tuple[str, list[dict]]:
    """The setting of `method`'s grid that scores best on the tuning `cases` (:func:`tuning_score`; among equals,
    the most conservative: the largest threshold and ridge, the largest ERR tolerance, BIC before AIC), and every
    setting's numbers."""
    table = []
    for setting in settings_of(method):
        numbers = score_method(cases, method, setting)
        table.append({"setting": setting, "score": tuning_score(numbers), "named": numbers["named"],
                      "null_adequate": numbers["null_adequate"]})
    best = max(range(len(table)), key=lambda i: (table[i]["score"], _conservative(method, i)))
    return table[best]["setting"], table


def _conservative(method: str, index: int) -> tuple:
    if method == "stlsq":
        return STLSQ_SETTINGS[index]
    criterion, tolerance = FROLS_SETTINGS[index]
    return (tolerance, criterion == "bic")


def compare(cases: list[dict]) -> dict:
    """The comparison: each peer tuned on the tuning split, then every method scored on the evaluation split."""
    tuning = [c for c in cases if c["split"] == "tuning"]
    evaluation = [c for c in cases if c["split"] == "evaluation"]
    grids, rows = {}, [score_method(evaluation, "diagnose")]
    for method in ("stlsq", "frols"):
        best, table = tune(tuning, method)
        grids[method] = {"best": best, "tuning": table,
                         "evaluation": [{"setting": s, **_brief(score_method(evaluation, method, s))}
                                        for s in settings_of(method)]}
        # every setting tied with the best on the tuning split, and the spread of their evaluation numbers: the
        # tie-break's share of the result
        top = max(row["score"] for row in table)
        tied = [e for row, e in zip(table, grids[method]["evaluation"]) if row["score"] == top]
        count = {"named": lambda e: e["named"][0], "null_adequate": lambda e: e["null_adequate"][0],
                 "confident_wrong": lambda e: e["confident_wrong"]}
        grids[method]["tied_best"] = [e["setting"] for e in tied]
        grids[method]["tied_best_evaluation"] = {key: [min(map(f, tied)), max(map(f, tied))]
                                                 for key, f in count.items()}
        if method == "stlsq":  # PySINDy's own ridge: the best of its thresholds on the tuning split
            default = [row for row, (_t, ridge) in zip(table, STLSQ_SETTINGS) if ridge == 0.0]
            grids[method]["default_ridge_best"] = max(default, key=lambda row: row["score"])
        rows.append(score_method(evaluation, method, best))
    rows_tuning = [score_method(tuning, "diagnose")] + [score_method(tuning, m, grids[m]["best"])
                                                         for m in ("stlsq", "frols")]
    return {"methods": rows, "tuning_split": rows_tuning, "grids": grids,
            "records": {"tuning": len(tuning), "evaluation": len(evaluation)},
            "peer_wins": peer_wins(rows),
            "cases": [_case_row(c, grids) for c in evaluation]}


def _brief(numbers: dict) -> dict:
    return {k: numbers[k] for k in ("named", "null_adequate", "confident_wrong")}


def peer_wins(rows: list[dict]) -> list[str]:
    """Where a peer does better than the diagnosis, in words (empty if nowhere)."""
    ours = rows[0]
    wins = []
    for row in rows[1:]:
        if (row["named_rate"] or 0.0) > (ours["named_rate"] or 0.0):
            wins.append(f"{row['label']} names more hidden effects ({row['named'][0]}/{row['named'][1]} against "
                        f"{ours['named'][0]}/{ours['named'][1]})")
        if (row["null_adequate_rate"] or 0.0) > (ours["null_adequate_rate"] or 0.0):
            wins.append(f"{row['label']} calls more nulls adequate")
        if row["outclass"]["closest or related"] > ours["outclass"]["closest or related"]:
            wins.append(f"{row['label']} names the closest or a related candidate for more out-of-class rivals "
                        f"({row['outclass']['closest or related']} of {row['outclass_rivals']} against "
                        f"{ours['outclass']['closest or related']})")
        if row["confident_wrong"] < ours["confident_wrong"]:
            wins.append(f"{row['label']} gives fewer confident wrong answers out of class")
        if row["replays_with_upstream_median"] < ours["replays_median"]:
            wins.append(f"{row['label']} needs fewer model replays: {row['replays_with_upstream_median']} a record "
                        f"for the replay uncertainty, calibration and signatures it regresses, against the "
                        f"diagnosis's {ours['replays_median']}")
    return wins


def _case_row(case: dict, grids: dict) -> dict:
    row = {"name": case["name"], "benchmark": case["benchmark"], "hidden": case["truth"]["hidden"] or "nothing"}
    for method in METHODS:
        verdict, effect = answer_of(case, method, grids.get(method, {}).get("best"))
        row[method] = effect if verdict == "missing" else verdict
    return row


def read_cases(paths) -> list[dict]:
    """The cases' peers files, in name order within each split."""
    import json
    from pathlib import Path

    cases = [json.loads(Path(p).read_text(encoding="utf-8")) for p in paths]
    return sorted(cases, key=lambda c: (c["split"], c["benchmark"], c["name"]))
