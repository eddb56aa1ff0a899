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


def _run_as_main(tmp_path, argv: list[str], before: str = "", **options):
    """`argv` run as the `parksteer` command runs it (parksteer.cli.run_as_main), in a fresh interpreter, after the
    lines `before`."""
    import subprocess
    import sys

    code = f"import atexit, sys\n{before}\nfrom parksteer.cli import run_as_main\nsys.argv[1:] = {argv!r}\nrun_as_main()\n"
    return subprocess.run([sys.executable, "-c", code], capture_output="stdout" not in options, text=True,
                          cwd=tmp_path, timeout=120, **options)


def test_the_command_runs_the_exit_functions_and_flushes_its_output_before_it_ends(tmp_path):
    """The command ends through os._exit, without the interpreter's teardown (cli.run_as_main), yet as a normal exit
    would: the exit functions run (one registered before the command prints a line, unflushed, after the command's
    whole output), stdout reaches the reader complete and the status is the command's."""
    done = _run_as_main(tmp_path, ["effects"], "atexit.register(lambda: print('exit functions ran'))")
    lines = done.stdout.splitlines()
    assert done.returncode == 0, done.stderr
    assert lines[-1] == "exit functions ran"
    assert len(lines) > 10 and "rack_friction" in done.stdout  # the list of effects came before it, whole


def test_the_command_keeps_a_refusals_status_and_its_one_line(tmp_path):
    """A refused file through the command's exit (cli.run_as_main): status 2 and one line on stderr naming it."""
    done = _run_as_main(tmp_path, ["diagnose", "no_such_record.csv", "--json"])
    assert done.returncode == 2
    assert len(done.stderr.splitlines()) == 1 and "no_such_record.csv" in done.stderr, done.stderr


def test_the_command_whose_reader_is_gone_ends_quietly(tmp_path):
    """`parksteer sweep expand ... | head` through the command's exit (cli.run_as_main), the reader gone before the
    first line: status 1, no traceback (the flush at its end writes nowhere and raises nothing)."""
    import os
    import subprocess
    from pathlib import Path

    declaration = Path(__file__).resolve().parents[1] / "config" / "sweeps" / "design.yaml"
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        done = _run_as_main(tmp_path, ["sweep", "expand", str(declaration)], stdout=write_end, stderr=subprocess.PIPE)
    finally:
        os.close(write_end)
    assert "Traceback" not in done.stderr and "BrokenPipeError" not in done.stderr, done.stderr
    assert done.returncode == 1, done.stderr


def test_the_command_under_a_profiler_exits_as_usual_so_the_profile_is_written(tmp_path):
    """Under `python -m cProfile -o FILE -m parksteer.cli ...` the command leaves the interpreter's exit to it (the
    profiler writes its file after the program returns; cli.run_as_main's os._exit would lose it): the file is
    written and the status is the command's."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "cProfile", "-o", str(tmp_path / "profile"), "-m", "parksteer.cli",
                           "effects"], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "profile").stat().st_size > 0
