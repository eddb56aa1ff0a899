"""The diagnosis against its peers: sparse regression of the calibrated residual, on the same records.

Two common tools a user with a calibrated model and its residual might reach for instead of
:func:`parksteer.diagnose.select.diagnose`: **STLSQ** (sequentially thresholded least squares, PySINDy's
optimizer) and **FROLS** (forward regression with orthogonal least squares, SysIdentPy's method;
:func:`~.peer_methods.frols` is this project's own implementation, since SysIdentPy 0.9.0 does not install beside
the project's numpy, requirements/pipeline.lock). Both regress the calibrated base model's weighted residual (noise
floors) on a library (:func:`~.peer_methods.record_library`) of generic terms of the record, each scaled to RMS 1,
and of each observable candidate's weighted signature
(:attr:`parksteer.diagnose.candidates.Signature.weighted`). Their answers map onto the diagnosis's verdicts
(:func:`~.peer_methods.verdict_of`): nothing selected is ``adequate``, a selected candidate is ``missing`` that one,
generic terms alone ``unexplained``. Each peer's setting is tuned over :data:`~.peer_methods.STLSQ_SETTINGS` or
:data:`~.peer_methods.FROLS_SETTINGS` on records of another seed (:func:`~.peer_scoring.tune`) and scored on the
benchmarks' records (:func:`~.peer_scoring.score_method`). The library, the settings and the results:
docs/peers.md.
"""

from __future__ import annotations

import time

import numpy as np

from ..diagnose.select import Diagnosis
from .peer_methods import peer_answers, record_library


def case_result(truth: dict, diagnosis: Diagnosis, result: dict, wall_s: float, split: str, benchmark: str) -> dict:
    """A case's record for the comparison: the truth, the diagnosis's answer (`result` its JSON dict, with the
    outcome of its benchmark), the peers' answers on the same residual and signatures, the times."""
    library = record_library(diagnosis)
    answers = peer_answers(library)
    timings = diagnosis.timings_s
    # what the peers need and a diagnosis computes anyway: replay uncertainty, calibration, signatures
    upstream = sum(timings.get(k, 0.0) for k in ("nominal_and_replay_uncertainty", "calibration", "torque_lag",
                                                  "signatures_and_scores"))
    return {
        "name": truth["name"], "split": split, "benchmark": benchmark, "truth": truth,
        "diagnosis": {"verdict": result["verdict"], "effect": result.get("effect"),
                      "indistinguishable": [s["effect"] for s in result["indistinguishable"]],
                      "outcome": _benchmark_outcome(benchmark, truth, result)},
        "terms": list(library.names), "rows": int(library.residual.size),
        "residual_rms": float(np.sqrt(np.mean(library.residual**2))),
        "stlsq": answers["stlsq"], "frols": answers["frols"], "frols_ranking": answers["frols_ranking"],
        "time_s": {"diagnose": wall_s, "upstream": upstream, "stlsq": answers["time_s"]["stlsq"],
                   "frols": answers["time_s"]["frols"]},
        # model replays (the same on any machine): the whole diagnosis's, and those up to its signatures
        "replays": {"diagnose": diagnosis.replays,
                    "upstream": diagnosis.replays_by_stage["signatures_and_scores"]},
    }


def _benchmark_outcome(benchmark: str, truth: dict, result: dict) -> dict:
    if benchmark == "outclass":
        from .outclass import outcome
    else:
        from .variation_summary import outcome
    row = outcome(truth, result)
    keep = ("named", "false_alarm", "relation", "confident_wrong", "adequate_at_3_steps", "said", "verdict")
    return {k: getattr(row, k) for k in keep if hasattr(row, k)}


def diagnose_case(params, folder, truth: dict, benchmark: str, split: str) -> dict:
    """Diagnose the records of one benchmark case (its files in `folder`, in the truth's order) as its benchmark
    does, and run the peers on the same residual and signatures (:func:`case_result`)."""
    from dataclasses import replace
    from pathlib import Path

    from ..synthetic.datasets import file_name
    from ..synthetic.variations import variation_by_name
    from .benchmark import BENCHMARK_SETTINGS
    from ..diagnose.intake import Request, intake
    from ..reporting.report import diagnosis_dict

    settings = BENCHMARK_SETTINGS
    if benchmark == "variations":  # as variations.run_case diagnoses it
        variation = variation_by_name(truth["variation"])
        settings = replace(settings, use_handwheel_angle=variation.uses_angle,
                           torque_lag_fitted=variation.logger.torque_lag_s > 0.0)
    paths = [Path(folder) / file_name(f["case"], f["surface"]) for f in truth["files"]]
    start = time.perf_counter()
    diagnosis = intake(Request(paths, params, settings=settings)).diagnose()
    wall = time.perf_counter() - start
    return case_result(truth, diagnosis, diagnosis_dict(diagnosis), wall, split, benchmark)


def tuning_design(design, seed: int):
    """The tuning split: the variation benchmark's grid with records of another `seed`."""
    from dataclasses import replace

    return replace(design, seed=int(seed))


def run_tuning_case(params, design, name: str, folder) -> dict:
    """Make tuning case `name`'s records as the variation benchmark makes its own (other seed), write them into
    `folder`, and diagnose them from the files with the peers beside (:func:`diagnose_case`)."""
    from pathlib import Path

    from ..measure.io import write_measurement
    from ..synthetic.datasets import file_name
    from .variations import case_records

    truth, records, _settings = case_records(params, design, name)
    Path(folder).mkdir(parents=True, exist_ok=True)
    for case, surface, measurement in records:
        write_measurement(Path(folder) / file_name(case, surface), measurement, params)
    return diagnose_case(params, folder, truth, "variations", "tuning")


def run_peer_batch(parameters_path, jobs: list[str], folder, tuning=None) -> None:
    """Run one job's cases into `folder` (<split>__<case>.peers.json each: a tuning case has its evaluation twin's
    name). A job is ``tuning:<case name>`` (made with the `tuning` design, its records in folder/tuning/<case>) or ``variations:<truth file>`` / ``outclass:<truth file>`` (a
    benchmark case's truth, its records in the folder of its name beside it)."""
    import json
    from pathlib import Path

    from ..errors import UsageError
    from ..parameters import load_parameters
    from ..tables import write_json

    params = load_parameters(parameters_path)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    for job in jobs:
        kind, _, what = job.partition(":")
        if kind == "tuning":
            if tuning is None:
                raise UsageError(f"peers job {job!r}: no tuning design given")
            result = run_tuning_case(params, tuning, what, out / "tuning" / what)
        elif kind in ("variations", "outclass"):
            path = Path(what)
            truth = json.loads(path.read_text(encoding="utf-8"))
            result = diagnose_case(params, path.parent / truth["name"], truth, kind, "evaluation")
            written = path.with_name(f"{truth['name']}.diagnosis.json")  # the benchmark's own diagnosis
            if written.exists():
                said = json.loads(written.read_text(encoding="utf-8"))
                result["diagnosis"]["benchmark_said"] = said["effect"] if said["verdict"] == "missing" \
                    else said["verdict"]
        else:
            raise UsageError(f"peers job {job!r}: not tuning:, variations: or outclass:")
        write_json(out / peers_file_name(result["split"], result["name"]), result)


def peers_beside(benchmark: str):
    """The `on_diagnosis` of the variation or out-of-class benchmark's batch (`benchmark`): each case's peers run on
    the diagnosis the batch has just made, written beside its diagnosis as ``evaluation__<case>.peers.json``, the
    record :func:`run_peer_batch` would make by diagnosing the written files again (the same records and settings,
    so the same diagnosis): the comparison's evaluation split costs no replay of its own."""
    import json
    from pathlib import Path

    from ..tables import write_json

    def write(diagnosis: Diagnosis, result: dict, truth_path, diagnosis_path) -> None:
        truth = json.loads(Path(truth_path).read_text(encoding="utf-8"))  # as a peers job reads it back
        record = case_result(truth, diagnosis, result, result["cost"]["wall_s"], "evaluation", benchmark)
        record["diagnosis"]["benchmark_said"] = result["effect"] if result["verdict"] == "missing" \
            else result["verdict"]
        write_json(Path(diagnosis_path).with_name(peers_file_name("evaluation", truth["name"])), record)

    return write


def peers_file_name(split: str, name: str) -> str:
    return f"{split}__{name}.peers.json"


