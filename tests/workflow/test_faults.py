"""Interruptions, damage and determinism of the pipeline, on real `snakemake` runs of small targets.

A copy of the repository (its tracked and new files) gets the compiled models of the worktree's cache
(results/model/<key>/, copied, so that no test derives a model), then:
- a run of `figA3 fig12` is killed by SIGKILL sent to its whole process group while a job runs; `parksteer repair`
  and the next ordinary run, with no other hand step (no --unlock, no --rerun-incomplete on the command line),
  finish it, write the files figures/SHA256SUMS holds, and leave no scratch directory, temporary file, lock or
  incomplete marker;
- damaged intermediates (a truncated simulation, a manifest naming a cache entry that does not exist, a truncated
  figure, a truncated sweep batch) are left alone by a dry run, removed by `parksteer repair` and rebuilt to the
  stored sums by the next ordinary run.
Each run takes well under a minute on two cores. That a rebuild from nothing gives the stored bytes is CI's
(quick start 1's cold build, then verify_strict; .ci/other_kernels); the three rebuilds of the whole paper are
benchmarks/three_rebuilds.py (see docs/targets.md).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from parksteer.checksums import integrity_problem, read_sums
from parksteer.tables import atomic_path, remove_stale_temporaries, write_json

SNAKEMAKE = Path(sys.executable).with_name("snakemake")
TARGETS = ("figA3", "fig12")
TARGET_FILES = ("figures/figA3.svg", "figures/figA3.csv", "figures/fig12.svg", "figures/fig12.csv")


def _env(work: Path) -> dict[str, str]:
    """The copy's own package and model cache, whatever the calling shell points at."""
    env = {k: v for k, v in os.environ.items() if k != "PARKSTEER_MODEL_CACHE"}
    env["PYTHONPATH"] = str(work / "src")
    return env


def _run(work: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(SNAKEMAKE), "--cores", "2", *args], cwd=work, env=_env(work), capture_output=True,
                          text=True, timeout=600)


def _repair(work: Path) -> subprocess.CompletedProcess:
    """`parksteer repair` in `work`, with the copy's own package."""
    return subprocess.run([sys.executable, "-m", "parksteer.cli", "repair"], cwd=work, env=_env(work),
                          capture_output=True, text=True, timeout=300)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _dead_pid() -> int:
    """The id of a process that has ended (and been reaped)."""
    child = subprocess.Popen(["true"])
    child.wait()
    return child.pid


def _assert_stored_sums(work: Path) -> None:
    sums = read_sums(work / "figures" / "SHA256SUMS")
    for name in TARGET_FILES:
        assert _sha256(work / name) == sums[name], f"{name} differs from figures/SHA256SUMS"


def _leftovers(work: Path) -> list[str]:
    """Scratch directories of model builds, temporary files of writers, locks and incomplete markers."""
    found = [str(p) for root in ("results", "figures") for p in (work / root).rglob(".*")]
    for marker in ("locks", "incomplete"):
        folder = work / ".snakemake" / marker
        if folder.is_dir():
            found += [str(p) for p in folder.rglob("*") if p.is_file()]
    return found


@pytest.fixture(scope="module")
def copy(copy_with_models, tmp_path_factory) -> Path:
    return copy_with_models(tmp_path_factory.mktemp("faults"))


def _simulating(logs: Path) -> bool:
    """Whether a simulation job is running: its log (parksteer.rules.rule_log) has the script's progress line and
    not yet the line that ends every job's log."""
    for log in logs.glob("*.log"):
        lines = log.read_text(encoding="utf-8", errors="replace").splitlines()
        if any(line.startswith("simulating ") for line in lines) and not any(
                ": finished after " in line or ": failed after " in line for line in lines):
            return True
    return False


@pytest.mark.slow
def test_a_killed_run_is_finished_by_the_next_ordinary_run(copy):
    """SIGKILL to the process group of a running `snakemake` (and its jobs) leaves a lock and incomplete markers;
    with a temporary file of a killed writer and a scratch directory of a killed model build beside them,
    `parksteer repair` removes the lock, and the next plain `snakemake --cores 2 figA3 fig12` runs to the end and
    writes exactly the stored checksums, and nothing of the killed run remains."""
    run = subprocess.Popen([str(SNAKEMAKE), "--cores", "2", *TARGETS], cwd=copy, env=_env(copy),
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    incomplete = copy / ".snakemake" / "incomplete"
    deadline = time.monotonic() + 300
    try:  # kill while a simulation runs: its job's log says it is simulating and not yet that it ended
        while not (_simulating(copy / "logs" / "simulate_model") and any(incomplete.glob("*"))):
            assert run.poll() is None, "the run ended before it could be killed"
            assert time.monotonic() < deadline, "no simulation started within 300 s"
            time.sleep(0.05)
    finally:
        os.killpg(run.pid, signal.SIGKILL)
        run.wait()
    assert any((copy / ".snakemake" / "locks").glob("*.lock")), "the kill left no lock: nothing was interrupted"
    assert any(p.is_file() for p in incomplete.rglob("*")), "the kill left no job marked incomplete"
    host = socket.gethostname().replace(".", "-")
    pid = _dead_pid()
    (copy / "figures" / f".fig12.csv.{host}.{pid}.abcdefgh.tmp").write_text("time_s,torque_Nm\n0,1", "utf-8")
    (copy / "results" / "model" / f".0123456789abcdef0123.{host}.{pid}.abcdefgh").mkdir()

    repaired = _repair(copy)
    again = _run(copy, *TARGETS)

    assert repaired.returncode == 0, repaired.stderr[-3000:]
    assert "removed the lock of a Snakemake run that is no longer running" in repaired.stdout.splitlines()
    assert again.returncode == 0, (again.stdout + again.stderr)[-3000:]
    _assert_stored_sums(copy)
    assert _leftovers(copy) == []


@pytest.mark.slow
def test_damaged_intermediates_are_rebuilt_by_the_next_ordinary_run(copy):
    """After a finished run: a simulation truncated mid-row, the model manifest naming a cache entry that does not
    exist, a figure truncated mid-element and a sweep batch truncated mid-object are all still there, byte for
    byte, after a dry run (nothing is removed while Snakemake reads the workflow); `parksteer repair` removes each,
    with one line saying why. Snakemake alone would trust all four (each is newer than its inputs); with Fig. 12's
    drawing deleted, its job would then read the truncated simulation. The next plain run rebuilds the manifest,
    the simulation and both figures to the stored checksums."""
    done = _run(copy, *TARGETS)
    assert done.returncode == 0, (done.stdout + done.stderr)[-3000:]
    sim = copy / "results" / "sim" / "unladen__full.csv"
    sim.write_bytes(sim.read_bytes()[: sim.stat().st_size // 2])
    manifest = copy / "results" / "model" / "full.json"
    sound = json.loads(manifest.read_text("utf-8"))
    manifest.write_text(json.dumps({**sound, "key": "f" * 20}), "utf-8")
    svg = copy / "figures" / "figA3.svg"
    svg.write_bytes(svg.read_bytes()[: svg.stat().st_size // 3])
    batch = copy / "results" / "sweeps" / "design" / "batches" / "0123456789.json"
    batch.parent.mkdir(parents=True, exist_ok=True)
    batch.write_text('{"points": [{"point": "a", "plateau_torque_Nm": 1', "utf-8")
    (copy / "figures" / "fig12.svg").unlink()
    damaged = {path: path.read_bytes() for path in (sim, manifest, svg, batch)}

    dry = _run(copy, "--dry-run", *TARGETS)
    assert dry.returncode == 0, (dry.stdout + dry.stderr)[-3000:]
    assert {path: path.read_bytes() for path in damaged} == damaged
    repaired = _repair(copy)
    again = _run(copy, *TARGETS)

    assert repaired.returncode == 0, repaired.stderr[-3000:]
    removed = [line for line in repaired.stdout.splitlines() if line.startswith("removed")]
    assert len(removed) == 4, removed
    assert any(line.startswith("removed results/model/full.json: names cache entry ffff") for line in removed), removed
    assert any(line.startswith("removed results/sim/unladen__full.csv: does not end with a newline")
               for line in removed), removed
    assert not batch.exists()
    assert again.returncode == 0, (again.stdout + again.stderr)[-3000:]
    assert integrity_problem(sim) is None and json.loads(manifest.read_text("utf-8"))["key"] == sound["key"]
    _assert_stored_sums(copy)
    assert _leftovers(copy) == []


def test_a_killed_writers_temporary_file_is_removed_and_a_live_ones_kept(tmp_path):
    """atomic_path names its temporary file after the writing process: the next write of the same target removes
    one whose process has ended, and remove_stale_temporaries removes it anywhere under a folder, while a file
    being written by a live process (this one) and files that are not temporaries are left alone."""
    host = socket.gethostname().replace(".", "-")
    dead = tmp_path / f".table.json.{host}.{_dead_pid()}.abcdefgh.tmp"
    live = tmp_path / f".table.json.{host}.{os.getpid()}.abcdefgh.tmp"
    other = tmp_path / "sub" / f".fig.svg.{host}.{_dead_pid()}.ijklmnop.tmp"
    ordinary = tmp_path / "sub" / "notes.tmp"
    for path in (dead, live, other, ordinary):
        path.parent.mkdir(exist_ok=True)
        path.write_text("partial", "utf-8")
    write_json(tmp_path / "table.json", {"a": 1})
    assert not dead.exists() and live.exists() and other.exists()
    with atomic_path(tmp_path / "x.json") as tmp:
        assert tmp.name.startswith(f".x.json.{host}.{os.getpid()}.")
        assert remove_stale_temporaries(tmp_path) == [other]
    assert live.exists() and ordinary.exists() and not other.exists()


@pytest.mark.skipif(not Path("/proc/self/cwd").exists(), reason="tells running processes apart through /proc")
def test_the_lock_of_a_running_snakemake_is_kept_and_that_of_a_dead_one_removed(tmp_path):
    """repair removes Snakemake's lock only when no Snakemake process runs in the folder: with a process named
    snakemake running there (a renamed `sleep`), the lock stays; once it has ended, the lock goes, in one line."""
    from parksteer.outputs import other_snakemake_running, repair

    lock = tmp_path / ".snakemake" / "locks" / "0.output.lock"
    lock.parent.mkdir(parents=True)
    lock.write_text("results/x.csv\n", "utf-8")
    (tmp_path / "snakemake").symlink_to(shutil.which("sleep"))
    running = subprocess.Popen(["./snakemake", "60"], cwd=tmp_path)
    try:
        time.sleep(0.2)
        assert other_snakemake_running(tmp_path)
        assert repair(tmp_path)[0] == [] and lock.exists()
    finally:
        running.kill()
        running.wait()
    assert not other_snakemake_running(tmp_path)
    assert repair(tmp_path)[0] == ["removed the lock of a Snakemake run that is no longer running"]
    assert not lock.parent.exists()


def test_a_manifest_is_trusted_only_if_its_cache_entry_exists_and_matches(tmp_path, monkeypatch):
    """A model manifest naming the right key is still untrusted while that entry is missing, trusted once the
    entry holds model.c and model.so with the SHA-256 its model.json records, and untrusted again when the
    library is replaced (content, not timestamps); `parksteer repair`, which knows no expected key, judges by the
    entry alone."""
    from parksteer.model.codegen.cache import CACHE_ENV, model_key
    from parksteer.model.symbolic.components import resolve_effects
    from parksteer.outputs import manifest_problem

    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    key = model_key(resolve_effects(None))
    manifest = tmp_path / "full.json"
    manifest.write_text(json.dumps({"key": key}), "utf-8")
    assert "is missing or fails its SHA-256 check" in manifest_problem(manifest, key)
    assert manifest_problem(manifest).startswith(f"names cache entry {key}, which is missing")
    entry = tmp_path / "cache" / key
    entry.mkdir(parents=True)
    (entry / "model.c").write_text("int f(void) { return 1; }\n", "utf-8")
    (entry / "model.so").write_bytes(b"\x7fELF library")
    sums = {name: _sha256(entry / name) for name in ("model.c", "model.so")}
    (entry / "model.json").write_text(json.dumps({"sha256": sums}), "utf-8")
    assert manifest_problem(manifest, key) is None and manifest_problem(manifest) is None
    (entry / "model.so").write_bytes(b"\x7fELF replaced")
    assert "is missing or fails its SHA-256 check" in manifest_problem(manifest, key)
    other = model_key(resolve_effects("-rack_friction"))
    assert "but the model's sources now key it" in manifest_problem(manifest, other)


def test_repair_knows_the_key_a_manifests_effects_have_now(tmp_path):
    """The key `parksteer repair` expects of a manifest is the one its effects have now: the paper's set by its
    names gives the key the set is derived under, a set other than the manifest's gives another key, and an effect
    the library does not have by name (one from a file outside the package) leaves only the entry check."""
    from parksteer.model.codegen.cache import model_key
    from parksteer.model.symbolic.components import resolve_effects
    from parksteer.outputs import current_model_key

    manifest = tmp_path / "full.json"
    paper = resolve_effects(None)
    manifest.write_text(json.dumps({"key": "f" * 20, "effects": [e.name for e in paper]}), "utf-8")
    assert current_model_key(manifest) == model_key(paper) != model_key(resolve_effects("-rack_friction"))
    manifest.write_text(json.dumps({"key": "f" * 20, "effects": ["lifting", "column_imbalance"]}), "utf-8")
    assert current_model_key(manifest) is None


def test_repair_removes_the_damaged_outputs_only_and_says_why(tmp_path, monkeypatch, capsys):
    """`parksteer repair` reads every output rules write: a truncated table and an unparsable key-number file are
    removed, one line each naming the file and why; a sound table, a sound figure's data and the reference data of
    figures/reference/ (source, not an output, truncated here) are kept; a second repair finds nothing."""
    from parksteer.cli import main
    from parksteer.model.codegen.cache import CACHE_ENV

    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    files = {
        "results/table.csv": "a,b\n1,2\n3,4\n",
        "results/broken.csv": "a,b\n5,6\n7,",
        "results/fig3.json": '{"plateau_Nm": 1',
        "figures/fig3.csv": "p,t\n1,2\n",
        "figures/reference/fig4.csv": "p,t\n1,",
    }
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text, "utf-8")

    assert main(["repair", "--root", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "removed results/broken.csv: does not end with a newline (truncated); the next run rebuilds it"
    assert lines[1].startswith("removed results/fig3.json: not readable JSON")
    assert lines[2:] == ["4 outputs read, 2 removed"]
    assert sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*.*")) == [
        "figures/fig3.csv", "figures/reference/fig4.csv", "results/table.csv"]
    assert main(["repair", "--root", str(tmp_path)]) == 0
    assert capsys.readouterr().out.splitlines() == ["2 outputs read, 0 removed"]
