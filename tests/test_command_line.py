"""The command line's shared conventions."""

from __future__ import annotations

from parksteer.cli import _join_dash_values, build_parser


def test_effects_spec_may_start_with_a_minus():
    """`--effects -rack_friction,+hooke_joint` (the documented form) is read as a value, not as an option."""
    argv = ["simulate", "--case", "unladen", "--effects", "-rack_friction,+hooke_joint", "--out", "x.csv"]
    joined = _join_dash_values(argv)
    assert "--effects=-rack_friction,+hooke_joint" in joined
    args = build_parser().parse_args(joined)
    assert args.effects == "-rack_friction,+hooke_joint"


def test_other_arguments_are_left_alone():
    """Only the listed options are rewritten; everything else passes through in order."""
    argv = ["simulate", "--case", "unladen", "--set", "steering.rack_friction_force=500", "--out", "x.csv"]
    assert _join_dash_values(argv) == argv


def test_version_is_the_installed_distributions(capsys):
    """`parksteer --version` prints the version from the package metadata (pyproject.toml), then exits 0."""
    from importlib import metadata

    import pytest

    with pytest.raises(SystemExit) as done:
        build_parser().parse_args(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"parksteer {metadata.version('parksteer')}"


def test_a_closed_pipe_ends_quietly(tmp_path):
    """`parksteer sweep expand ... | head` whose reader is gone ends with status 1 and no traceback."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    declaration = Path(__file__).resolve().parents[1] / "config" / "sweeps" / "design.yaml"
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader has gone before the first line is written
    try:
        done = subprocess.run(
            [sys.executable, "-c", "import sys; from parksteer.cli import main; sys.exit(main())",
             "sweep", "expand", str(declaration)],
            stdout=write_end, stderr=subprocess.PIPE, text=True, cwd=tmp_path, timeout=120)
    finally:
        os.close(write_end)
    assert "Traceback" not in done.stderr and "BrokenPipeError" not in done.stderr, done.stderr
    assert done.returncode == 1, done.stderr
