"""What a newcomer meets in the first hour, each a line that says what to do (README.md, docs/).

- a vehicle file with an [assist] left out of a compare or diagnose (no --with-assist) is said in one line on
  stderr, and not said for a file without one;
- an effect loaded from a file (--effects=+path.py) pickles by reference once the command has resolved it, as the
  diagnosis's worker pool needs (a cold diagnosis with the example user effect failed with a PicklingError).
"""

from __future__ import annotations

import argparse
import pickle
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


def test_assist_left_out_is_said_in_one_line():
    """The Polo's bus log compared with its vehicle file without --with-assist: one warning line on stderr naming
    the file and --with-assist; the run still completes (status 0)."""
    done = run_cli("compare", str(SAMPLE_LOG), "--bus", "vw_mqb", "--vehicle", str(POLO), "--case", "kerb",
                   "--surface", "ground", "--quiet")
    assert done.returncode == 0, done.stderr
    warnings = [line for line in done.stderr.splitlines() if "warning" in line]
    assert len(warnings) == 1, done.stderr
    assert str(POLO) in warnings[0] and "[assist]" in warnings[0] and "--with-assist" in warnings[0]


def test_no_assist_no_warning():
    """A vehicle file without [assist] (the paper's car), and the Polo with --with-assist: no warning."""
    done = run_cli("compare", "data/samples/car/unladen__ground.csv", "--vehicle", str(MAESTRO), "--quiet")
    assert done.returncode == 0, done.stderr
    assert "warning" not in done.stderr
    done = run_cli("compare", str(SAMPLE_LOG), "--bus", "vw_mqb", "--vehicle", str(POLO), "--with-assist",
                   "--case", "kerb", "--surface", "ground", "--quiet")
    assert done.returncode == 0, done.stderr
    assert "warning" not in done.stderr


def test_effect_from_a_file_pickles_by_reference():
    """The example user effect loaded from its file, as --effects=+path.py loads it, pickles and unpickles to the
    same class once effects_of has resolved it (before, its module was in no sys.modules entry)."""
    from parksteer.commands.measure import effects_of
    from parksteer.parameters import load_parameters

    path = REPO / "src" / "parksteer" / "examples" / "column_imbalance.py"
    args = argparse.Namespace(effects=f"+{path}", with_assist=False, vehicle=None, command="diagnose")
    effects = effects_of(args, load_parameters())
    user = next(e for e in effects if e.name == "column_imbalance")
    assert type(pickle.loads(pickle.dumps(user))) is type(user)
