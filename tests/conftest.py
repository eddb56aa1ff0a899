"""Shared fixtures: the repository root, the shipped parameter file, and synthetic measurement files (made once
per session, seeded) for the data-set and diagnosis tests."""

from __future__ import annotations

import atexit
import contextlib
import functools
import importlib.util
import io
import os
import shutil
import signal
import sys
import tempfile
from pathlib import Path

# One BLAS thread per test process, set before numpy loads here and inherited by the workers and every subprocess:
# the workers already take every CPU (pytest-xdist -n auto), and BLAS threads on top of them oversubscribe the
# CPUs (OpenBLAS's idle threads spin). Snakemake does the same for its jobs (its `threads`).
for _variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import pytest  # noqa: E402

import parksteer.diagnose.parallel as _parallel  # noqa: E402
from parksteer.model.codegen.cache import CACHE_ENV  # noqa: E402
from parksteer.parameters import DEFAULT_PATH, Parameters, load_parameters  # noqa: E402

# For the same reason, a diagnosis or baseline run in a test process without --jobs (the command line, or a
# caller of parksteer.diagnose.intake) replays in line when the test run's workers already take every CPU,
# instead of forking a pool of one process per CPU on top of them: the pool's processes each set up their
# replays again (about 10 % more CPU for the same JSON, which tests/diagnose/test_job_counts.py shows equal at
# every job count, and that test and tests/diagnose/test_parallel.py still run the pools). Subprocesses (the
# documents' commands) are not concerned.
_TEST_WORKERS = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
if _TEST_WORKERS > 1:
    _cpus = _parallel.available_workers()
    _parallel.available_workers = lambda: max(_cpus // _TEST_WORKERS, 1)

REPO_ROOT = Path(__file__).resolve().parents[1]

# SLURM's executor plugin, installed here for tests/cluster, asks the controller for its configuration (`scontrol
# show config`, 10 s timeout) at every start of Snakemake; where SLURM's tools are installed but no controller
# answers (the test cluster not started yet, or gone), each of the suite's many `snakemake` runs would wait about
# 9 s for it. The test run's processes get an `scontrol` that gives that query 1 s (a controller answers in
# milliseconds) and hands every other use to SLURM's own unchanged. Made once, by the process the workers are
# started from, and inherited with PATH.
_SCONTROL = shutil.which("scontrol")
if _SCONTROL and "PARKSTEER_TESTS_SCONTROL" not in os.environ:
    _folder = tempfile.mkdtemp(prefix="parksteer-tests-scontrol-")
    atexit.register(shutil.rmtree, _folder, True)
    _shim = Path(_folder) / "scontrol"
    _shim.write_text('#!/bin/sh\n'
                     f'if [ "$1" = show ] && [ "$2" = config ]; then exec timeout 1 {_SCONTROL} "$@"; fi\n'
                     f'exec {_SCONTROL} "$@"\n', encoding="utf-8")
    _shim.chmod(0o755)
    os.environ["PARKSTEER_TESTS_SCONTROL"] = _folder
    os.environ["PATH"] = _folder + os.pathsep + os.environ.get("PATH", "")


# Modules whose tests share no module fixture and are each long (the document chains, the diagnosis routes at several
# job counts): each test is a work unit of its own for the test run's workers, not the module; their slow tests
# start in this order, the longest first (pytest_collection_modifyitems).
INDEPENDENT_MODULES = ("tests/test_docs.py", "tests/diagnose/test_job_counts.py")


def _module(nodeid: str) -> str:
    return nodeid.split("::")[0]


@pytest.hookimpl(optionalhook=True)  # pytest-xdist's hook
def pytest_xdist_make_scheduler(config, log):
    """xdist's loadscope (pyproject.toml), but each test of :data:`INDEPENDENT_MODULES` a scope of its own."""
    from xdist.scheduler import LoadScopeScheduling

    class Scheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return nodeid if _module(nodeid) in INDEPENDENT_MODULES else super()._split_scope(nodeid)

    return Scheduling(config, log)


def pytest_collection_modifyitems(config, items):
    """Work units and their order for the test run's workers (xdist's loadscope with --no-loadscope-reorder,
    pyproject.toml: each unit goes whole to one worker, the units in the order given here).

    A module is one unit, so its tests share one worker and its fixtures; in :data:`INDEPENDENT_MODULES` each test
    is a unit (pytest_xdist_make_scheduler), so that no one module's long tests run end to end on one worker while
    the other idles. The real SLURM run starts first (it mostly waits on the cluster's polling), then the slow
    tests of those modules (each long), then the modules marked slow: the long ones start while short ones remain
    to fill the other worker, and the workers finish together (longest first)."""
    def rank(item):
        if item.get_closest_marker("slurm"):
            return (0, 0)
        if item.get_closest_marker("slow"):
            module = _module(item.nodeid)
            return (1, INDEPENDENT_MODULES.index(module)) if module in INDEPENDENT_MODULES else (2, 0)
        return (3, 0)

    items.sort(key=rank)  # stable: the order within each rank is the collection order


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    """An empty model cache of the test's own (PARKSTEER_MODEL_CACHE), for the tests of how entries are built."""
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "model"))
    return tmp_path / "model"


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The repository checkout (holds Snakefile, workflow/, data/)."""
    return REPO_ROOT


@pytest.fixture(scope="session")
def copy_repository(repo_root):
    """copy(dest) -> dest: the repository's tracked and new, not ignored, files copied into `dest` (no outputs, no
    model cache), for the tests that run the pipeline or the documents' commands in a scratch copy; its package's
    bytecode compiled, as the README's quick start leaves a checkout (and the cold-DAG timing its copy). Where
    PYTHONDONTWRITEBYTECODE is set, every process run from a copy without it compiles the modules it imports again."""
    spec = importlib.util.spec_from_file_location("bench_pipeline", repo_root / "benchmarks" / "bench_pipeline.py")
    bench_pipeline = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench_pipeline)
    # the benchmarks' scratch copy: the same files, and bytecode, the cold-DAG timing builds from
    return functools.partial(bench_pipeline.scratch_copy, bytecode=True)


@pytest.fixture(scope="session")
def copy_with_models(repo_root, copy_repository):
    """copy(dest, need_models=True) -> dest: a scratch copy of the repository with the worktree's compiled models
    (results/model/<key>/, copied, so that a pipeline run in it derives nothing); skips when the worktree has built
    none, unless `need_models` is false (then the copy's first run derives what it needs)."""
    def copy(dest: Path, need_models: bool = True) -> Path:
        cache = repo_root / "results" / "model"
        entries = [p for p in cache.iterdir() if p.is_dir() and not p.name.startswith(".")] if cache.is_dir() else []
        if not entries and need_models:
            pytest.skip("no compiled models in results/model: run `snakemake --cores 2 fig12` once")
        work = copy_repository(dest)
        for entry in entries:
            shutil.copytree(entry, work / "results" / "model" / entry.name)
        return work
    return copy


def _snakemake(workdir: Path, *args: str) -> tuple[str, str]:
    """`snakemake ARGS` run in `workdir` in this process; (stdout, stderr). A status other than 0 fails the test
    with the output's tail."""
    # The tests' outputs are empty placeholders; reading the workflow removes nothing (repair is `parksteer repair`).
    from snakemake.cli import main

    out, err = io.StringIO(), io.StringIO()
    status = None
    before, path = Path.cwd(), list(sys.path)  # Snakemake puts the workflow's folders on the path: taken off after
    # Snakemake's job scheduler answers SIGTERM with a handler that only sets a flag, and leaves it in place: a
    # process forked later by this test process (a multiprocessing pool) would inherit it and outlive the
    # SIGTERM that Pool.terminate sends, which then waits for it for good.
    handlers = {number: signal.getsignal(number) for number in _parallel.STOPPING_SIGNALS}
    os.chdir(workdir)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            main(list(args))
    except SystemExit as done:  # the entry point always ends so, with the command's exit status
        status = done.code
    finally:
        os.chdir(before)
        sys.path[:] = path
        for number, handler in handlers.items():
            signal.signal(number, handler)
    assert status == 0, (out.getvalue() + err.getvalue())[-3000:]
    return out.getvalue(), err.getvalue()


@pytest.fixture(scope="session")
def snakemake():
    """run(workdir, *args) -> (stdout, stderr): the command `snakemake ARGS` in `workdir`, through its command line's
    own entry point (snakemake.cli.main: the same arguments, the workflow's profile) in the test's process, for the
    tests that read what a command plans or writes without running a job: a process of its own for each command
    spent most of its time importing Snakemake and its plugins again."""
    return _snakemake


def _placeholder_files(work: Path, outputs: list[str]) -> None:
    """Create each of the workflow's `outputs` (paths relative to `work`) empty: its directory() outputs (the
    diagnosis benchmarks' job folders) are the names without a suffix, made as folders."""
    for name in outputs:
        output = work / name
        if output.suffix:
            output.parent.mkdir(parents=True, exist_ok=True)
            output.touch()
        else:
            output.mkdir(parents=True, exist_ok=True)


def _placeholder_outputs(work: Path, summary: str) -> None:
    """Create every output listed by `snakemake --summary` (`summary`) in `work` empty."""
    _placeholder_files(work, [line.split("\t")[0] for line in summary.splitlines()[1:]])


@pytest.fixture(scope="session")
def placeholder_outputs():
    """placeholder(work, summary): every output of a `snakemake --summary` listing created empty in `work`."""
    return _placeholder_outputs


@pytest.fixture(scope="session")
def placeholder_files():
    """placeholder(work, outputs): each of the workflow's outputs (paths relative to `work`) created empty."""
    return _placeholder_files


@pytest.fixture(scope="session")
def params() -> Parameters:
    """The shipped data/parameters.toml, validated."""
    return load_parameters(DEFAULT_PATH)


# Synthetic data sets: used by tests/synthetic (how they are made) and tests/diagnose (what is found in them).
ONE_FILE = (("unladen", "ground"),)


@pytest.fixture(scope="session")
def benchmark_design(repo_root):
    """The pipeline's benchmark design (config/config.yaml, section benchmark)."""
    import yaml

    from parksteer.synthetic.datasets import BenchmarkDesign

    config = yaml.safe_load((repo_root / "config" / "config.yaml").read_text(encoding="utf-8"))
    return BenchmarkDesign.from_config(config["benchmark"])


@pytest.fixture(scope="session")
def written(tmp_path_factory, params, benchmark_design):
    """make(name, kind, hidden, steps, base_overrides, ...) -> (paths, truth); each data set generated once."""
    from parksteer.measure.io import write_measurement
    from parksteer.synthetic.datasets import DatasetSpec, make_dataset

    cache = {}
    root = tmp_path_factory.mktemp("diagnose_data")

    def make(name, kind="null", hidden=None, steps=None, base_overrides=None, files=ONE_FILE, seed=4242, phase=None,
             strength=None):
        if name not in cache:
            spec = DatasetSpec(name, seed, files, kind, hidden, steps, dict(base_overrides or {}), phase, strength,
                               benchmark_design.search)
            dataset = make_dataset(params, spec)
            paths = []
            for m, (case, surface) in zip(dataset.measurements, files):
                path = root / name / f"{case}__{surface}.csv"
                write_measurement(path, m, params)
                paths.append(path)
            cache[name] = (paths, dataset.truth)
        return cache[name]

    return make


@pytest.fixture(scope="session")
def diagnosed(written, params):
    """diagnosed(name, **dataset) -> the diagnosis (the default effects and settings) of the data set `written` makes
    under `name`, with the same arguments; each diagnosed once per session, for the modules that read the same
    diagnosis (a Diagnosis is read by the tests, never changed)."""
    from parksteer.diagnose.problem import load_files
    from parksteer.diagnose.select import diagnose

    cache = {}

    def once(name, **dataset):
        if name not in cache:
            paths, _ = written(name, **dataset)
            cache[name] = diagnose(load_files(paths, params), params)
        return cache[name]

    return once
