"""`parksteer diagnose --jobs N` gives the same answer at any N (parksteer.diagnose.parallel,
parksteer.diagnose.engine.ReplayEngine): each route of the diagnosis, run on the records of data/samples/ in one
process and in worker processes, reports the same JSON, field by field, but its timings.

The routes differ in what the workers are handed: several records (a prediction's files spread over the workers,
two or three per pool), a torque lag searched (new problems on new files, at new instants, after the workers of
the first were forked), the handwheel angle fitted beside the torque (two signals a file, on one record: the
spreading of a prediction's files over the workers is the several records' route), a user's effect with
free strengths (a model derived from a file outside the package, its class found by reference in the workers) and
an assisted car (its torsion-bar torque and motor current).

Each route but the torque lag's runs on the first half of each record (:func:`first_half`: its cycle to the right
lock and back to about the centre), which takes the route through the same stages to the same verdict as the whole
record does, at about half the replays' cost: what is compared is one process against its workers on the same
problem, which the record's length does not enter. The torque lag's route keeps the whole records, on which the lag
found is the record's.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from parksteer.cli import main
from parksteer.diagnose.parallel import can_fork

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not can_fork(), reason="the platform cannot fork: everything runs in line")]

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "data" / "samples"
CAR = [SAMPLES / "car" / "unladen__ground.csv", SAMPLES / "car" / "part_laden__ground.csv"]
# One process (the reference), two workers (a worker serves several items in turn: the racks, the candidates, the
# refits, and on the route of three records one worker two files), and on that route three workers (each file's
# replays a worker of their own). Three on a route of two records adds nothing two does not: its file maps use two
# workers either way, and its maps of many items are served in turn by each worker at two as at three.
JOB_COUNTS = {"several_records": (1, 2, 3)}
DEFAULT_JOB_COUNTS = (1, 2)


def _rows(path: Path) -> tuple[list[str], list[str], list[list[str]]]:
    """(header lines, column names, rows) of the native record `path`."""
    lines = path.read_text(encoding="utf-8").splitlines()
    header = [line for line in lines if line.startswith("#")]
    names, *rows = [line.split(",") for line in lines if not line.startswith("#")]
    return header, names, rows


def _written(out: Path, header: list[str], names: list[str], rows: list[list[str]]) -> Path:
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(header + [",".join(names)] + [",".join(row) for row in rows]) + "\n", encoding="utf-8")
    return out


def first_half(path: Path, folder: Path) -> Path:
    """A copy of the native record `path` with the first half of its rows (its header as it is)."""
    header, names, rows = _rows(path)
    return _written(folder / "half" / path.name, header, names, rows[: len(rows) // 2])


def lagged(path: Path, folder: Path, samples: int) -> Path:
    """A copy of the native record `path` whose torque channel runs `samples` samples behind its other channels
    (each row's torque is the one `samples` rows before; the first rows, which have none, are dropped)."""
    header, names, rows = _rows(path)
    column = names.index("handwheel_torque_Nm")
    shifted = [row[:column] + [rows[i - samples][column]] + row[column + 1 :]
               for i, row in enumerate(rows) if i >= samples]
    return _written(folder / "lagged" / path.name, header, names, shifted)


def routes(folder: Path) -> dict[str, list[str]]:
    """Each route's arguments to `parksteer diagnose`, its records first."""
    def half(*paths: Path) -> list[str]:
        return [str(first_half(p, folder)) for p in paths]

    car = half(*CAR)
    return {
        "several_records": [*car, *half(SAMPLES / "car" / "offset_12_7mm__air_bearing.csv")],
        # 20 ms at 50 Hz: one sample; the whole records, on which the lag found is the record's (on their first
        # halves it comes out at 13 and 16 ms)
        "torque_lag": [*(str(lagged(p, folder, 1)) for p in CAR), "--torque-lag"],
        # one record, its two signals: the same verdict through the same stages as two records' (rack_lash among
        # the candidates, its twist through the column's deflection law)
        "angle": [car[0], "--angle"],
        "user_effect": [*car, f"--effects=+{ROOT / 'examples' / 'user_effect' / 'centre_friction.py'}"],
        "assisted": [*half(SAMPLES / "polo_baseline.csv", SAMPLES / "polo_drag.csv"), "--with-assist",
                     "--vehicle", str(ROOT / "data" / "vehicles" / "polo_vi.toml")],
    }


def fields(value, path: str = "") -> dict[str, object]:
    """Every leaf of a JSON document by its path (``/files[0]/torque_lag_s``)."""
    if isinstance(value, dict):
        return {k: v for key, item in value.items() for k, v in fields(item, f"{path}/{key}").items()}
    if isinstance(value, list):
        return {k: v for i, item in enumerate(value) for k, v in fields(item, f"{path}[{i}]").items()}
    return {path: value}


def diagnosed(arguments: list[str], jobs: int, capsys) -> dict[str, object]:
    assert main(["diagnose", *arguments, "--json", "--quiet", "--jobs", str(jobs)]) == 0
    result = fields(json.loads(capsys.readouterr().out))
    # how long each stage took is the one thing a job count may change
    return {k: v for k, v in result.items() if not k.startswith(("/cost/timings_s/", "/cost/wall_s"))}


# the longest first (the test run's workers take each route alone: tests/conftest.py); on an empty model cache the
# user's effect derives two models
@pytest.mark.parametrize("route", ["angle", "user_effect", "torque_lag", "assisted", "several_records"])
def test_every_route_gives_the_same_json_in_one_process_and_in_workers(route, tmp_path, capsys):
    """The diagnosis at 2 processes (and, with three records, 3) reports, field by field, what it reports in one
    (verdict, lags, fitted values and intervals, ranking, statistics, replay counts): the workers compute exactly
    what the process would, on the problem each prediction is asked on. With the torque lag searched, the lag found
    is also the record's (20 ms within 6 ms), so the lagged route really moved its problem to new instants."""
    arguments = routes(tmp_path)[route]
    job_counts = JOB_COUNTS.get(route, DEFAULT_JOB_COUNTS)
    results = {jobs: diagnosed(arguments, jobs, capsys) for jobs in job_counts}
    for jobs in job_counts[1:]:
        differing = sorted(k for k in results[1].keys() | results[jobs].keys()
                           if results[1].get(k, "(absent)") != results[jobs].get(k, "(absent)"))
        assert differing == [], f"--jobs {jobs} against --jobs 1: {len(differing)} fields differ"
    if route == "torque_lag":
        lags = [v for k, v in results[1].items() if k.endswith("/torque_lag_s")]
        assert len(lags) == 2 and all(v == pytest.approx(0.020, abs=0.006) for v in lags)
