"""Exact rebuilds: a rule's parameters carry the digest of the package code its script runs, so an edit reruns
what it affects and an edited docstring, comment or test reruns nothing; the experiment design in
config/config.yaml reaches the rules as parameters, so a changed entry does too.

In a copy of the repository (its tracked and new files) every output of the pipeline is created empty and marked
up to date (`snakemake --touch`), once for the module; then a module is edited and a dry run lists the jobs
Snakemake would run. No job runs: the DAG alone shows which rules depend on which module. After each test the
edited file gets back its bytes and its modification time, which is all a dry run's verdict depends on (a dry run
writes no metadata), so the copy is up to date again for the next test without a second `--touch`.

Snakemake runs in the test's process (the conftest fixture `snakemake`): what is checked is the DAG each command
plans, not the process.
"""

from __future__ import annotations

import os
import re
import signal
from pathlib import Path

import pytest
import yaml

from parksteer.diagnose.parallel import STOPPING_SIGNALS

pytestmark = pytest.mark.slow


def _planned(snakemake, workdir: Path, *options: str) -> dict[str, int]:
    """Rule -> number of jobs a dry run of the default target plans (`snakemake`: the conftest fixture)."""
    out = "".join(snakemake(workdir, "all", "--dry-run", *options))  # the target first: --configfile takes several
    if "Nothing to be done" in out:
        return {}
    stats = out[out.index("Job stats:"):]
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\w+)\s+(\d+)$", stats, re.MULTILINE)
            if m.group(1) != "total"}


@pytest.fixture
def edit():
    """edit(path) appends a statement to path (edit(path, code=False): a comment line; edit(path, replace=(old,
    new)): the first `old` made `new`); after the test every edited file is restored, bytes and mtime."""
    saved: dict[Path, tuple[bytes, int, int]] = {}

    def _edit(path: Path, code: bool = True, replace: tuple[str, str] | None = None) -> None:
        stat = path.stat()
        saved.setdefault(path, (path.read_bytes(), stat.st_atime_ns, stat.st_mtime_ns))
        if replace is not None:
            path.write_text(path.read_text(encoding="utf-8").replace(*replace, 1), encoding="utf-8")
            return
        with path.open("a", encoding="utf-8") as f:
            f.write("\n_EDITED_BY_THE_REBUILD_TEST = 1\n" if code else "\n# edited by the rebuild test\n")

    yield _edit
    for path, (content, atime, mtime) in saved.items():
        path.write_bytes(content)
        os.utime(path, ns=(atime, mtime))
        assert path.read_bytes() == content and path.stat().st_mtime_ns == mtime


@pytest.fixture(scope="module")
def repository_copy(copy_repository, placeholder_outputs, snakemake, tmp_path_factory) -> Path:
    """A copy of the repository whose every pipeline output exists and is up to date."""
    work = copy_repository(tmp_path_factory.mktemp("rebuilds"))
    placeholder_outputs(work, snakemake(work, "--summary", "all")[0])
    return work


@pytest.fixture(scope="module")
def up_to_date_copy(repository_copy, snakemake) -> Path:
    """The copy, every output marked up to date (each newer than its inputs, in DAG order) and every job's metadata
    recorded as a run records it (its parameters, the code digest among them: --forceall makes --touch pass over
    every job); each test restores what it edits (fixture `edit`)."""
    from snakemake.executors.touch import Executor as TouchExecutor

    handlers = [signal.getsignal(number) for number in STOPPING_SIGNALS]
    # The touch executor waits SLEEPING_TIME (0.1 s) before each job's touch, so that its outputs come out newer
    # than its inputs: 9 s over the DAG's jobs. 20 ms is still two ticks of the coarsest kernel clock a file's
    # time is taken from (HZ = 100), and the dry run below shows every output up to date.
    sleeping = TouchExecutor.SLEEPING_TIME
    TouchExecutor.SLEEPING_TIME = 0.02
    try:
        snakemake(repository_copy, "--touch", "--forceall", "--cores", "1", "all")
    finally:
        TouchExecutor.SLEEPING_TIME = sleeping
    # Snakemake's scheduler sets a SIGTERM handler that does not end the process; the in-process run (conftest)
    # puts the test process's own back, or a pool forked later in this worker could never be terminated
    assert [signal.getsignal(number) for number in STOPPING_SIGNALS] == handlers
    assert _planned(snakemake, repository_copy) == {}
    return repository_copy


def test_a_figure_module_edit_reruns_that_figure_and_the_paper_only(up_to_date_copy, edit, snakemake):
    """figures/lifting.py draws Fig. A3 alone: editing it plans figA3 and the paper that shows it, nothing else."""
    edit(up_to_date_copy / "src" / "parksteer" / "figures" / "lifting.py")
    assert _planned(snakemake, up_to_date_copy) == {"figA3": 1, "paper": 1, "all": 1}


def test_a_numeric_model_edit_derives_nothing_and_reruns_the_simulations(up_to_date_copy, edit, snakemake):
    """model/numeric does not key the compiled model: editing simulate.py plans every simulation again (the model
    figures' runs, the sweep's batches, the synthetic data) but no derive job."""
    edit(up_to_date_copy / "src" / "parksteer" / "model" / "numeric" / "simulate.py")
    planned = _planned(snakemake, up_to_date_copy)
    assert "derive" not in planned
    assert planned["simulate_model"] > 0 and planned["sweep_batch"] > 0 and planned["diag_car_data"] == 1


def test_a_diagnosis_setting_edit_reruns_the_diagnoses_not_the_model_figures(up_to_date_copy, edit, snakemake):
    """diagnose/settings.py holds the diagnosis thresholds: editing it reruns the benchmark's diagnoses and the
    case study, and leaves the compiled models, the simulations of the model figures and the sweep alone."""
    edit(up_to_date_copy / "src" / "parksteer" / "diagnose" / "settings.py")
    planned = _planned(snakemake, up_to_date_copy)
    assert planned["diag_bench_batch"] > 0 and planned["case_study"] == 1 and planned["diag_benchmark"] == 1
    assert not {"derive", "simulate_model", "model_figure", "sweep_batch", "fig3", "figA3"} & set(planned)


def test_a_design_entry_reruns_what_it_affects(up_to_date_copy, tmp_path, snakemake):
    """A new seed of the synthetic car (config car.seed) plans its data set again and what reads it (comparison,
    case study, ladder, paper), not the benchmark; a new legend label of Fig. 14's ablation plans Fig. 14 alone."""
    seed = tmp_path / "seed.yaml"
    seed.write_text("car:\n  seed: 1984\n", encoding="utf-8")
    planned = _planned(snakemake, up_to_date_copy, "--configfile", str(seed))
    assert planned == {"diag_car_data": 1, "diag_compare": 1, "case_study": 1, "diag_ladder": 1, "paper": 1,
                       "all": 1}
    label = tmp_path / "label.yaml"
    label.write_text("variants:\n  no_friction: {model: no_friction, surface: ground, label: lifting alone}\n",
                     encoding="utf-8")
    assert _planned(snakemake, up_to_date_copy, "--configfile", str(label)) == {"model_figure": 1, "paper": 1, "all": 1}


def test_a_docstring_or_comment_edit_reruns_nothing(up_to_date_copy, edit, snakemake):
    """A rule's code parameter is the digest of its modules without docstrings and comment lines: rewording the
    docstring of diagnose/settings.py (which every diagnosis runs) and adding a comment line to it plans no job,
    and neither does an edited test."""
    settings = up_to_date_copy / "src" / "parksteer" / "diagnose" / "settings.py"
    edit(settings, replace=('"""', '"""Reworded. '))
    edit(settings, code=False)
    edit(up_to_date_copy / "tests" / "diagnose" / "test_verdict.py")
    assert _planned(snakemake, up_to_date_copy) == {}

