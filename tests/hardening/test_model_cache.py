"""The compiled-model cache survives a killed build and damage: a killed build's scratch directory is removed by
the next build, and an entry whose library or source no longer matches the SHA-256 it recorded is rebuilt; processes
that need the same model at the same time build it once."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from parksteer.model.codegen import cache
from parksteer.model.symbolic.components import resolve_effects

pytestmark = pytest.mark.slow

# The smallest effect set: the quickest build (a few seconds).
# A small set the package does not ship pre-derived (tests/model/test_prebuilt.py), so that it is derived here
SMALL = "-carcass_compliance,-hooke_joint,-lifting,-tyre_friction"


def _dead_pid() -> int:
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(done.stdout)


def _scratch(root: Path) -> list[Path]:
    return [p for p in root.iterdir() if p.name.startswith(".") and p.is_dir()]


def test_killed_build_leaves_scratch_that_the_next_build_removes(cache_dir):
    """A build killed by SIGKILL mid-way leaves its scratch directory; the next build removes it (its process is
    gone), keeps a live builder's, and ends with one sound entry and no scratch."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    code = ("from parksteer.model.codegen.cache import ensure_entry;"
            "from parksteer.model.symbolic.components import resolve_effects;"
            f"ensure_entry(resolve_effects({SMALL!r}))")
    proc = subprocess.Popen([sys.executable, "-c", code], env=env, start_new_session=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (cache_dir.is_dir() and _scratch(cache_dir)):
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    left = _scratch(cache_dir)
    assert left, "the build was killed before it made its scratch directory"
    host = socket.gethostname().replace(".", "-")
    live = cache_dir / f".{'0' * 20}.{host}.{os.getpid()}.live"  # this process is alive: never removed
    live.mkdir()
    entry = cache.ensure_entry(resolve_effects(SMALL))
    assert cache.entry_is_sound(entry)
    assert [p for p in _scratch(cache_dir) if p != live] == []
    assert live.is_dir()


def test_damaged_entry_is_rebuilt_and_a_dead_builders_scratch_removed(cache_dir):
    """Truncating model.so (its timestamp newer than model.json) makes the entry unsound; the next ensure
    rebuilds it to the recorded content. A scratch directory of a dead process on this host goes too."""
    effects = resolve_effects(SMALL)
    entry = cache.ensure_entry(effects)
    good = (entry / "model.so").read_bytes()
    (entry / "model.so").write_bytes(good[: len(good) // 2])
    assert not cache.entry_is_sound(entry)
    host = socket.gethostname().replace(".", "-")
    stale = cache_dir / f".{entry.name}.{host}.{_dead_pid()}.abcd"
    stale.mkdir()
    (stale / "model.c").write_text("half", encoding="utf-8")
    again = cache.ensure_entry(effects)
    assert again == entry and cache.entry_is_sound(entry)
    assert not stale.exists()
    assert _scratch(cache_dir) == []


def test_entry_without_recorded_hashes_is_not_trusted(tmp_path):
    """An entry from before hashes were recorded, or a model.json alone, is not sound."""
    d = tmp_path / "entry"
    d.mkdir()
    (d / "model.json").write_text("{}", encoding="utf-8")
    (d / "model.so").write_bytes(b"x")
    (d / "model.c").write_text("x", encoding="utf-8")
    assert not cache.entry_is_sound(d)
    assert not cache.entry_is_sound(tmp_path / "missing")


def test_processes_that_need_the_same_model_at_once_build_it_once(cache_dir):
    """Three processes ask for the same missing model together: one derives it, the others wait for its lock and
    load the entry it built; no lock file or scratch directory is left."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    code = ("from parksteer.model.codegen.cache import ensure_entry;"
            "from parksteer.model.symbolic.components import resolve_effects;"
            f"print(ensure_entry(resolve_effects({SMALL!r})))")
    procs = [subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for _ in range(3)]
    outputs = [p.communicate(timeout=600) for p in procs]
    assert all(p.returncode == 0 for p in procs), [err for _, err in outputs]
    assert len({out.strip() for out, _ in outputs}) == 1
    derivations = sum(err.count("deriving the model") for _, err in outputs)
    assert derivations == 1, [err for _, err in outputs]
    assert [p for p in cache_dir.iterdir() if p.name.startswith(".")] == []


def test_a_model_building_in_the_background_is_waited_for_not_built_again(cache_dir, capfd):
    """A diagnosis starts its candidates' models in the background (start_builds) and may need one before it is
    done: the load waits for the builder's lock (or builds it first, and the builder finds it built), so the model
    is derived once; the builder exits cleanly and leaves no lock file or scratch directory."""
    effects = resolve_effects(SMALL)
    builders = cache.start_builds([effects], jobs=2)
    assert len(builders) == 1
    path = cache.ensure_entry(effects)
    cache.finish_builds(builders)
    assert builders[0].exitcode == 0
    assert cache.entry_is_sound(path)
    assert capfd.readouterr().err.count("deriving the model") == 1
    assert [p for p in cache_dir.iterdir() if p.name.startswith(".")] == []


def test_a_background_build_ends_on_sigterm_whatever_handler_the_process_had(cache_dir):
    """A diagnosis ends its background builds with SIGTERM on an interrupt or an error (select.py), then waits for
    them. Forked from a process whose SIGTERM handler only sets a flag (as Snakemake's job scheduler leaves one in
    the process that ran it), a builder must still end, with status 143, and leave neither scratch directory nor
    entry nor build lock behind: it answers SIGTERM itself."""
    flagged = []
    before = signal.signal(signal.SIGTERM, lambda signum, frame: flagged.append(signum))
    try:
        builders = cache.start_builds([resolve_effects(SMALL)], jobs=2)
        deadline = time.monotonic() + 60
        while not (cache_dir.is_dir() and _scratch(cache_dir)):  # building: its scratch directory made
            assert time.monotonic() < deadline and builders[0].is_alive(), "the build never started"
            time.sleep(0.02)
        builders[0].terminate()
        builders[0].join(timeout=30)
    finally:
        signal.signal(signal.SIGTERM, before)
    assert builders[0].exitcode == 128 + signal.SIGTERM, builders[0].exitcode
    assert flagged == []
    assert list(cache_dir.iterdir()) == []
