"""What a newcomer meets in the first hour, each a line that says what to do (README.md, docs/).

- no C compiler: one line naming the compilers tried, status 2, before any derivation starts;
- Python older than 3.11 (a checkout on the path, a venv of another interpreter; pip itself refuses to install):
  one line naming the version and what to do, status 2, at import (so at the CLI's start and the Snakefile's);
- a model cache that cannot be written (a read-only checkout, a path through a file, no space left): one line
  naming the cache folder, PARKSTEER_MODEL_CACHE and XDG_CACHE_HOME, status 2, and no scratch folder left behind;
- a vehicle file with an [assist] left out of a compare or diagnose (no --with-assist) is said in one line on
  stderr, and not said for a file without one;
- an effect loaded from a file (--effects=+path.py), which pickle cannot find by its module's name, reaches the
  worker processes of a diagnosis's engine all the same (a cold diagnosis with the example user effect failed with
  a PicklingError).
"""

from __future__ import annotations

import argparse
import errno
import glob
import os
import pickle
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
POLO = REPO / "data" / "vehicles" / "polo_vi.toml"
MAESTRO = REPO / "data" / "vehicles" / "maestro.toml"
SAMPLE_LOG = REPO / "data" / "samples" / "polo_kerb.log"


def run_cli(*argv: str, cwd: Path = REPO, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "parksteer.cli", *argv], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=300)


def compared(capsys, *argv: str) -> tuple[int, str]:
    """(exit status, stderr) of `parksteer compare ARGV` run in this process (the warning is the command's line on
    stderr, which no separate process is needed to show)."""
    from parksteer.cli import main

    capsys.readouterr()
    status = main(["compare", *argv])
    return status, capsys.readouterr().err


def test_assist_left_out_is_said_in_one_line(capsys):
    """The Polo's bus log compared with its vehicle file without --with-assist: one warning line on stderr naming
    the file and --with-assist; the run still completes (status 0)."""
    status, err = compared(capsys, str(SAMPLE_LOG), "--bus", "vw_mqb", "--vehicle", str(POLO), "--case", "kerb",
                           "--surface", "ground", "--quiet")
    assert status == 0, err
    warnings = [line for line in err.splitlines() if "warning" in line]
    assert len(warnings) == 1, err
    assert str(POLO) in warnings[0] and "[assist]" in warnings[0] and "--with-assist" in warnings[0]


def test_no_assist_no_warning(capsys):
    """A vehicle file without [assist] (the paper's car), and the Polo with --with-assist: no warning."""
    status, err = compared(capsys, str(REPO / "data" / "samples" / "car" / "unladen__ground.csv"), "--vehicle",
                           str(MAESTRO), "--quiet")
    assert status == 0, err
    assert "warning" not in err
    status, err = compared(capsys, str(SAMPLE_LOG), "--bus", "vw_mqb", "--vehicle", str(POLO), "--with-assist",
                           "--case", "kerb", "--surface", "ground", "--quiet")
    assert status == 0, err
    assert "warning" not in err


def test_effect_from_a_file_reaches_the_diagnosis_workers():
    """The example user effect loaded from its file, as --effects=+path.py loads it, has no importable home (plain
    pickle refuses it), yet a task holding it reaches the workers of a diagnosis's engine as the very effect and
    class it was loaded as, which the workers inherited; loaded twice in one process (as a long-lived one may),
    each load's own."""
    from parksteer.commands.measure import effects_of
    from parksteer.diagnose.engine import ReplayEngine
    from parksteer.diagnose.parallel import can_fork
    from parksteer.parameters import load_parameters

    path = REPO / "src" / "parksteer" / "examples" / "column_imbalance.py"
    args = argparse.Namespace(effects=f"+{path}", with_assist=False, vehicle=None, command="diagnose")
    for _ in range(2):
        effects = effects_of(args, load_parameters())
        user = next(e for e in effects if e.name == "column_imbalance")
        with pytest.raises(pickle.PicklingError):
            pickle.dumps(user)
        if not can_fork():
            continue
        engine = ReplayEngine(2, effects=tuple(effects))
        try:
            out = engine.pool.map(object(), lambda task: (task[0] is user, type(task[0]) is type(user), task[1]),
                                  [(user, 1), (user, 2)])
        finally:
            engine.close()
        assert out == [(True, True, 1), (True, True, 2)]


def one_line(done: subprocess.CompletedProcess) -> str:
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    return lines[0]


def test_no_compiler_is_one_line_before_deriving(tmp_path):
    """With no cc, gcc or clang on PATH and CC unset, a simulation of a model the cache lacks (and the package does
    not carry) stops with one line and status 2, and derives nothing first."""
    env = {k: v for k, v in os.environ.items() if k != "CC"}
    (tmp_path / "bin").mkdir()
    env.update(PATH=str(tmp_path / "bin"), PARKSTEER_MODEL_CACHE=str(tmp_path / "cache"))
    done = run_cli("simulate", "--case", "unladen", "--effects=+column_friction", "--out", str(tmp_path / "run.csv"),
                   env=env)
    assert done.returncode == 2
    line = one_line(done)
    assert "no C compiler found" in line and "cc" in line
    assert not (tmp_path / "run.csv").exists()
    assert not list(tmp_path.glob("cache/**/model.c"))


def older_python() -> str | None:
    """A Python 3.10 that runs (a pyenv shim on PATH may name one that is not installed)."""
    candidates = [*sorted(glob.glob(os.path.expanduser("~/.pyenv/versions/3.10*/bin/python3.10"))),
                  shutil.which("python3.10")]
    for python in filter(None, candidates):
        try:
            done = subprocess.run([python, "-c", "import sys; print(sys.version_info[:2])"], capture_output=True,
                                  text=True, timeout=30)
        except OSError:
            continue
        if done.returncode == 0 and done.stdout.strip() == "(3, 10)":
            return python
    return None


def test_python_310_is_one_line():
    """Under Python 3.10 with the checkout on the path, the CLI and a bare import stop with one line naming the
    version and python3.11, status 2 (skipped where no 3.10 is installed)."""
    python = older_python()
    if python is None:
        pytest.skip("no Python 3.10 interpreter on this machine")
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    env.pop("VIRTUAL_ENV", None)
    for argv in (["-m", "parksteer.cli", "--help"], ["-c", "import parksteer.cli"]):
        done = subprocess.run([python, *argv], cwd=REPO, env=env, capture_output=True, text=True, timeout=60)
        assert done.returncode == 2
        line = one_line(done)
        assert "Python 3.11 or newer is needed" in line and "3.10" in line and "python3.11" in line


def test_unwritable_cache_is_one_line(tmp_path):
    """A model cache under a file (as a read-only or foreign folder is: nothing can be made there) stops a
    simulation with one line naming the folder, PARKSTEER_MODEL_CACHE and XDG_CACHE_HOME, status 2."""
    (tmp_path / "afile").write_text("", encoding="utf-8")
    cache = tmp_path / "afile" / "model"
    env = dict(os.environ, PARKSTEER_MODEL_CACHE=str(cache))
    done = run_cli("simulate", "--case", "unladen", "--effects=+column_friction", "--out", str(tmp_path / "run.csv"),
                   env=env)
    assert done.returncode == 2
    line = one_line(done)
    assert f"cannot write the model cache {cache}" in line
    assert "PARKSTEER_MODEL_CACHE" in line and "XDG_CACHE_HOME" in line


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root writes into a read-only folder")
def test_read_only_cache_folder_is_one_line(tmp_path):
    """A cache folder without write permission (a read-only checkout's results/model): one line, status 2."""
    cache = tmp_path / "model"
    cache.mkdir()
    cache.chmod(0o555)
    try:
        done = run_cli("simulate", "--case", "unladen", "--effects=+column_friction", "--out",
                       str(tmp_path / "run.csv"), env=dict(os.environ, PARKSTEER_MODEL_CACHE=str(cache)))
    finally:
        cache.chmod(0o755)
    assert done.returncode == 2
    assert f"cannot write the model cache {cache}" in one_line(done)


@pytest.mark.parametrize("code, said", [(errno.ENOSPC, "no space left on its disk"),
                                        (errno.EROFS, "Read-only file system")])
def test_cache_write_failure_leaves_nothing(tmp_path, monkeypatch, code, said):
    """A build that fails writing into the cache (the disk full while the C or the library is written; a read-only
    file system) is one UsageError naming the folder, the reason and XDG_CACHE_HOME, and the scratch folder it was
    writing is gone: the next run starts clean."""
    from parksteer.errors import UsageError
    from parksteer.model.codegen import cache
    from parksteer.model.symbolic.components import resolve_effects

    monkeypatch.setenv("PARKSTEER_MODEL_CACHE", str(tmp_path / "model"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))

    def full_disk(effects, directory, key=None):
        directory.mkdir(parents=True, exist_ok=True)
        (directory / "model.c").write_text("/* half */", encoding="utf-8")
        raise OSError(code, os.strerror(code))

    monkeypatch.setattr(cache, "build_entry", full_disk)
    with pytest.raises(UsageError) as caught:
        cache.ensure_entry(resolve_effects("+column_friction"))
    message = str(caught.value)
    assert "\n" not in message
    assert f"cannot write the model cache {tmp_path / 'model'}" in message and said in message
    assert f"XDG_CACHE_HOME {tmp_path / 'xdg'}" in message and "PARKSTEER_MODEL_CACHE" in message
    assert [p.name for p in (tmp_path / "model").iterdir()] == []
