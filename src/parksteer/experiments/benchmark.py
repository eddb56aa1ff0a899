"""The hidden-effect benchmark: diagnose synthetic data sets whose truth is known, and score the diagnoses.

One data set (:func:`run_case`) is generated (:func:`parksteer.synthetic.datasets.make_dataset`),
written as measurement files, read back through the same reader a user's file goes through,
and diagnosed; the truth is written to its own file. :func:`aggregate` then scores all of
them:

- a confusion matrix: what was hidden (a candidate, nothing, or a disturbance outside the
  library) against what the diagnosis said (the effect it named, ``adequate``, ``unexplained``);
- for hidden candidates, by strength: the fraction named first, and named first or inside
  the indistinguishable group the diagnosis reported;
- the false-alarm rate on the nulls (a ``missing`` verdict where nothing is hidden);
- the fraction of the disturbances outside the library called ``unexplained``;
- the weighted RMS error after adding the named effect, divided by the noise floor.

The benchmark's design (strengths, files, perturbation, seeds) is a
:class:`parksteer.synthetic.datasets.BenchmarkDesign`, from the pipeline's configuration.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..errors import UsageError
from ..measure.io import write_measurement
from ..parameters import Parameters, load_parameters
from ..synthetic.datasets import BenchmarkDesign, benchmark_specs, file_name, make_dataset
from ..tables import write_json
from ..diagnose.intake import Request, intake
from ..reporting.report import diagnosis_dict
from .rows import BenchmarkRow
from ..diagnose.settings import DEFAULT_SETTINGS, DiagnosisSettings

# The benchmarks' diagnoses: a user's, without the stages that only inform a report (the confound tests, the
# residual's signature, the assist's assumed values at their bands' ends), which change no verdict, name or interval
# the benchmarks score. bench_variations.py --confound-tests turns the confound tests on.
BENCHMARK_SETTINGS = replace(DEFAULT_SETTINGS, confound_tests=False, residual_signature=False,
                             assumed_values_replayed=False)

TARGETS = {"named_or_group_at_2_steps": 0.90, "false_alarm_rate": 0.05, "outside_unexplained": 0.80,
           "after_over_floor": 1.2}


def case_names(design: BenchmarkDesign, params: Parameters | None = None) -> list[str]:
    return [s.name for s in benchmark_specs(params or load_parameters(), design)]


def diagnose_written(params: Parameters, records, folder: str | Path, truth: dict, truth_path: str | Path,
                     diagnosis_path: str | Path, started_s: float,
                     settings: DiagnosisSettings = BENCHMARK_SETTINGS, on_diagnosis: Callable | None = None) -> dict:
    """Write `records` ((case, surface, measurement) each) into `folder`, diagnose them from the files (read back
    through the reader a user's file goes through) with `settings`, write the truth and the result. The result's
    cost gains the diagnosis's wall time and the generation's (from `started_s`, a perf_counter reading, to the
    files written). `on_diagnosis(diagnosis, result, truth_path, diagnosis_path)`, when given, is handed the
    diagnosis once both are written: another experiment on the same replays (the peers) without diagnosing again."""
    paths = []
    for case, surface, measurement in records:
        path = Path(folder) / file_name(case, surface)
        write_measurement(path, measurement, params)
        paths.append(path)
    generated = time.perf_counter()
    diagnosis = intake(Request(paths, params, settings=settings)).diagnose()
    result = diagnosis_dict(diagnosis)
    result["cost"]["wall_s"] = time.perf_counter() - generated
    result["cost"]["generation_s"] = generated - started_s
    write_json(truth_path, truth)
    write_json(diagnosis_path, result)
    if on_diagnosis is not None:
        on_diagnosis(diagnosis, result, truth_path, diagnosis_path)
    return result


def case_files(folder: str | Path, name: str) -> tuple[Path, Path, Path]:
    """Where case `name` of a benchmark job goes in the job's `folder`: (its records' folder, its truth file, its
    diagnosis file)."""
    folder = Path(folder)
    return folder / name, folder / f"{name}.truth.json", folder / f"{name}.diagnosis.json"


def run_batch(run_case: Callable, parameters_path: str | Path, design, names: list[str], folder: str | Path,
              **options) -> None:
    """Run the cases `names` of one benchmark job, each with `run_case` (this module's, the out-of-class or the
    variation benchmark's: ``run_case(parameters_path, design, name, records_folder, truth_path, diagnosis_path,
    **options)``) into its place in `folder` (:func:`case_files`)."""
    for name in names:
        records, truth, diagnosis = case_files(folder, name)
        records.mkdir(parents=True, exist_ok=True)
        run_case(parameters_path, design, name, records, truth, diagnosis, **options)


def paired_results(truth_paths, diagnosis_paths, what: str) -> Iterator[tuple[dict, dict]]:
    """(truth, diagnosis) of each data set, paired and ordered by file name (whatever folders the jobs wrote them
    to); a pair whose names differ is refused in one line naming `what` benchmark."""
    by_name = lambda path: (Path(path).name, path)  # noqa: E731
    for t_path, d_path in zip(sorted(map(str, truth_paths), key=by_name), sorted(map(str, diagnosis_paths), key=by_name)):
        if Path(t_path).name.split(".")[0] != Path(d_path).name.split(".")[0]:
            raise UsageError(f"{what}: truth {t_path} and diagnosis {d_path} do not pair up")
        yield (json.loads(Path(t_path).read_text(encoding="utf-8")),
               json.loads(Path(d_path).read_text(encoding="utf-8")))


def run_case(parameters_path: str | Path, design: BenchmarkDesign, name: str, folder: str | Path,
             truth_path: str | Path, diagnosis_path: str | Path) -> dict:
    """Generate data set `name`, write its files into `folder`, diagnose them from the files, write truth and result."""
    params = load_parameters(parameters_path)
    specs = {s.name: s for s in benchmark_specs(params, design)}
    if name not in specs:
        raise UsageError(f"unknown benchmark data set {name!r}")
    start = time.perf_counter()
    dataset = make_dataset(params, specs[name])
    records = [(case, surface, m) for m, (case, surface) in zip(dataset.measurements, specs[name].files)]
    return diagnose_written(params, records, folder, dataset.truth, truth_path, diagnosis_path, start)


def outcome(truth: dict, result: dict) -> BenchmarkRow:
    """How one diagnosis fares against its truth."""
    group = [s["effect"] for s in result["indistinguishable"]]
    said = result["effect"] if result["verdict"] == "missing" else result["verdict"]
    named_first = truth["kind"] == "candidate" and result["effect"] == truth["hidden"]
    in_group = truth["kind"] == "candidate" and result["verdict"] == "missing" and truth["hidden"] in group
    floor = result["noise_floor_Nm"]
    after = result["statistics"]["with_effect"]
    return BenchmarkRow(
        name=truth["name"],
        kind=truth["kind"],
        hidden=truth["hidden"] or "nothing",
        # grouped by the size asked for; a candidate whose largest strength falls short is hidden at that
        # strength and its actual size is kept beside it
        steps=truth.get("steps_requested", truth["steps"]) or 0.0,
        steps_actual=truth["steps"] if truth["steps"] is not None else 0.0,
        said=said,
        verdict=result["verdict"],
        indistinguishable=" ".join(group),
        named_first=named_first,
        named_or_group=named_first or in_group,
        calibrated_over_floor=result["statistics"]["calibrated"]["weighted_rms_Nm"] / floor,
        after_over_floor=after["weighted_rms_Nm"] / floor if after else float("nan"),
        plain_after_over_floor=after["rms_Nm"] / floor if after else float("nan"),
        replays=result["cost"]["replays"],
        wall_s=result["cost"].get("wall_s", float("nan")),
    )


def _fraction(values) -> float | None:
    values = list(values)
    return float(np.mean(values)) if values else None


def aggregate(truth_paths: list[str | Path], diagnosis_paths: list[str | Path],
              design: BenchmarkDesign | None = None) -> tuple[list[BenchmarkRow], dict]:
    """(one outcome per data set, the summary numbers, with the design they were made with if given)."""
    rows = [outcome(truth, result) for truth, result in paired_results(truth_paths, diagnosis_paths, "benchmark")]
    candidates = [r for r in rows if r.kind == "candidate"]
    nulls = [r for r in rows if r.kind == "null"]
    outside = [r for r in rows if r.kind == "outside"]
    steps = sorted({r.steps for r in candidates})
    by_steps = {
        f"{s:g}": {
            "data_sets": sum(r.steps == s for r in candidates),
            "named_first": _fraction(r.named_first for r in candidates if r.steps == s),
            "named_or_group": _fraction(r.named_or_group for r in candidates if r.steps == s),
        }
        for s in steps
    }
    strong = [r for r in candidates if r.steps >= 2.0]
    by_candidate = {
        name: {
            "named_or_group_at_2_steps": _fraction(r.named_or_group for r in strong if r.hidden == name),
            "said": [r.said for r in candidates if r.hidden == name],
        }
        for name in sorted({r.hidden for r in candidates})
    }
    successes = [r for r in candidates if r.named_or_group]
    after = [r.after_over_floor for r in successes if np.isfinite(r.after_over_floor)]
    confusion: dict[str, dict[str, int]] = {}
    for r in rows:
        truth_label = r.hidden if r.kind != "outside" else f"outside: {r.hidden}"
        confusion.setdefault(truth_label, {})
        confusion[truth_label][r.said] = confusion[truth_label].get(r.said, 0) + 1
    summary = {
        "data_sets": len(rows),
        "candidates": len(candidates),
        "nulls": len(nulls),
        "outside": len(outside),
        "by_steps": by_steps,
        "by_candidate": by_candidate,
        "named_first_at_2_steps": _fraction(r.named_first for r in strong),
        "named_or_group_at_2_steps": _fraction(r.named_or_group for r in strong),
        "false_alarm_rate": _fraction(r.verdict == "missing" for r in nulls),
        "null_not_adequate_rate": _fraction(r.verdict != "adequate" for r in nulls),
        "outside_unexplained": _fraction(r.verdict == "unexplained" for r in outside),
        "outside_said": {r.name: r.said for r in outside},
        "after_over_floor": {
            "median": float(np.median(after)) if after else None,
            "max": float(np.max(after)) if after else None,
            "within_target": _fraction(a <= TARGETS["after_over_floor"] for a in after),
        },
        "confusion": confusion,
        "targets": TARGETS,
        "settings": None if design is None else {
            "steps": list(design.steps),
            "files": [list(f) for f in design.files],
            "perturbation": design.perturbation,
            "seed": design.seed,
        },
        "cost": {
            "replays_median": float(np.median([r.replays for r in rows])) if rows else None,
            "diagnosis_wall_s_median": float(np.median([r.wall_s for r in rows])) if rows else None,
        },
    }
    return rows, summary
