"""A real SLURM run: the SLURM profile (workflow/profiles/slurm) runs a four-point sweep on a one-node cluster on
localhost, and its results are byte-identical to a local run of the same sweep.

start_slurm.sh brings the cluster up from Debian's slurm-wlm and munge packages (slurmctld, slurmd and munged,
no slurmdbd); the test is skipped, with that script's one-line reason, where it cannot. What it verifies: the
plugin's sbatch submissions are accepted by a real slurmctld (partition, account, memory, runtime, CPUs, the
grouped point jobs), the jobs run under slurmd through the plugin's job step (a nested srun) and their outputs
reach Snakemake, which tracks the jobs to completion by polling squeue. What it cannot: a filesystem shared
between machines, partitions and accounts that are enforced, fair-share queueing, failing nodes.
"""

from __future__ import annotations

import concurrent.futures
import filecmp
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

pytestmark = [pytest.mark.slow, pytest.mark.slurm]

START_SLURM = Path(__file__).with_name("start_slurm.sh")
PARTITION = "debug"  # tests/cluster/slurm.conf.in
# Any name: without slurmdbd the plugin cannot validate an account (sacctmgr and sshare return nothing), warns
# and passes it to sbatch, which accepts it since no accounting enforces it.
ACCOUNT = "parksteer"
SWEEP_NAME = "slurm_check"
# Four designs of the unladen car with the paper's five effects: one compiled model (a derive job) and four
# points (in one batch, one group job under the profile's grouping of sweep batches); the sweep's gathering
# rule runs on the submitting host.
SWEEP = f"""\
name: {SWEEP_NAME}
description: Four designs of the unladen car, to compare a SLURM run with a local one.
base_case: unladen
effects: null
surface: ground
axes:
  tyre.tyre_pressure: [122500, 300000]
  design.front_axle_load: [5576, 8500]
map:
  x: tyre.tyre_pressure
  y: design.front_axle_load
  quantity: peak_torque_Nm
"""
SWEEP_FILE = f"config/sweeps/{SWEEP_NAME}.yaml"
TARGET = f"sweep_{SWEEP_NAME}"


def _start_cluster() -> None:
    if shutil.which("bash") is None:
        pytest.skip("no bash to run tests/cluster/start_slurm.sh")
    done = subprocess.run(["bash", str(START_SLURM)], capture_output=True, text=True, timeout=180)
    if done.returncode != 0:
        lines = (done.stderr or done.stdout).strip().splitlines() or [f"exit status {done.returncode}"]
        pytest.skip(f"no local SLURM cluster: {lines[-1]}")


def _node_limits() -> tuple[int, int]:
    """CPUs and memory (MB) of the cluster's one node, as slurmctld sees them."""
    out = subprocess.run(["sinfo", "--noheader", f"--partition={PARTITION}", "--format=%c %m"],
                         capture_output=True, text=True, check=True, timeout=30).stdout.split()
    return int(out[0]), int(out[1].rstrip("+"))


def _work_copy(repo_root: Path, dest: Path) -> Path:
    """A copy of the repository in which Snakemake can run: src/, paper/ and data/ linked, workflow/ and config/ copied
    (so that the profile can be edited), and the four-point sweep declared."""
    dest.mkdir()
    for name in ("src", "paper", "data"):
        if (repo_root / name).exists():
            (dest / name).symlink_to(repo_root / name)
    ignore = shutil.ignore_patterns("__pycache__", ".snakemake")
    shutil.copytree(repo_root / "workflow", dest / "workflow", ignore=ignore)
    shutil.copytree(repo_root / "config", dest / "config", ignore=ignore)
    (dest / SWEEP_FILE).write_text(SWEEP, encoding="utf-8")
    return dest


def _point_the_profile_at_the_test_cluster(work: Path, cpus: int, memory_mb: int) -> None:
    """The shipped profile with this cluster's partition and an account in place of the placeholders, a group
    job no larger than the node, and job states polled with squeue (there is no slurmdbd for sacct)."""
    path = work / "workflow" / "profiles" / "slurm" / "config.yaml"
    profile = yaml.safe_load(path.read_text(encoding="utf-8"))
    profile["default-resources"]["slurm_partition"] = PARTITION
    profile["default-resources"]["slurm_account"] = ACCOUNT
    limits = profile.setdefault("resources", {})
    limits["cpus_per_task"] = min(int(limits.get("cpus_per_task", cpus)), cpus)
    limits["mem_mb"] = min(int(limits.get("mem_mb", memory_mb)), memory_mb)
    # slurm.conf.in keeps a finished job in squeue for MinJobAge = 600 s, well above the plugin's threshold
    # (3 x the first check's delay). The plugin checks first after this delay, then 10 s later than the time before
    # until a job has finished: each of the run's two jobs (7-9 s, a Snakemake started inside the job) is seen done
    # at the second check, 1 + 11 s after its submission with a first check after 1 s (2 + 12 s after 2 s, 40 + 50 s
    # after the default 40 s).
    profile["slurm-status-command"] = "squeue"
    profile["slurm-init-seconds-before-status-checks"] = 1
    path.write_text(yaml.safe_dump(profile, sort_keys=False), encoding="utf-8")


def _snakemake(work: Path, *args: str) -> tuple[float, str]:
    bindir = Path(sys.executable).parent
    env = dict(os.environ, PATH=f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}")
    start = time.monotonic()
    done = subprocess.run([str(bindir / "snakemake"), *args, "--config", f"sweep={SWEEP_FILE}", "--", TARGET],
                          cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=1200)
    elapsed = time.monotonic() - start
    assert done.returncode == 0, f"snakemake {' '.join(args)} failed in {work}:\n{done.stdout[-4000:]}"
    return elapsed, done.stdout


def _job_states(jobs: list[str]) -> dict[str, str]:
    """The state slurmctld records for each job (it keeps finished jobs for MinJobAge, 600 s here)."""
    out = subprocess.run(["squeue", "--states=all", "--noheader", "--format=%i|%T", f"--jobs={','.join(jobs)}"],
                         capture_output=True, text=True, check=True, timeout=30).stdout
    return dict(line.split("|", 1) for line in out.split())


def _results(work: Path) -> list[str]:
    """The sweep's results, relative to the work copy: every batch of point records, the figure's CSV and the key
    numbers (the SVG is left out: it is a rendering of the CSV)."""
    points = sorted(str(p.relative_to(work)) for p in (work / "results" / "sweeps" / SWEEP_NAME).rglob("*")
                    if p.is_file())
    return points + [f"figures/{TARGET}.csv", f"results/{TARGET}.json"]


def test_slurm_run_of_a_sweep_matches_the_local_run_byte_for_byte(repo_root, tmp_path):
    """The four-point sweep run through SLURM with the project's profile gives the same bytes, file by file, as
    the same sweep run locally with --cores 2; and its jobs did go through SLURM (slurmctld records every job the
    plugin submitted as completed)."""
    pytest.importorskip("snakemake_executor_plugin_slurm", reason="the SLURM executor plugin is a test-only extra")
    _start_cluster()
    cpus, memory_mb = _node_limits()
    on_slurm = _work_copy(repo_root, tmp_path / "slurm")
    _point_the_profile_at_the_test_cluster(on_slurm, cpus, memory_mb)
    local = _work_copy(repo_root, tmp_path / "local")

    # The local run goes on beside the SLURM run, which mostly waits for the plugin's status checks: the first
    # comes 40 s after a submission by default (a real cluster's queue), 1 s here (the profile as
    # _point_the_profile_at_the_test_cluster sets it: a one-node cluster on this machine answers at once); what the
    # checks find is the same.
    with concurrent.futures.ThreadPoolExecutor(max_workers=1) as pool:
        beside = pool.submit(_snakemake, local, "--cores", "2")
        slurm_s, slurm_log = _snakemake(on_slurm, "--profile", "workflow/profiles/slurm")
        local_s, _ = beside.result()

    submitted = re.findall(r"has been submitted with SLURM jobid (\d+)", slurm_log)
    # the derivation and the one group of batches; the gathering rule is local (workflow/rules/sweep.smk)
    assert len(submitted) == 2, slurm_log[-4000:]
    states = _job_states(submitted)
    assert states == {job: "COMPLETED" for job in submitted}, states
    produced = _results(on_slurm)
    batches = [p for p in produced if p.endswith(".json") and "/batches/" in p]
    assert sum(len(json.loads((on_slurm / p).read_text())["records"]) for p in batches) == 4, produced
    assert produced == _results(local)
    differing = [p for p in produced if not filecmp.cmp(on_slurm / p, local / p, shallow=False)]
    assert not differing, f"differ between the SLURM and the local run: {differing}"
    print(f"\nslurm run: {slurm_s:.1f} s ({len(submitted)} SLURM jobs); local run: {local_s:.1f} s; "
          f"{len(produced)} files identical")
