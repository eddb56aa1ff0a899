"""What the one-line corpus cannot see of the entry points newer than it: stdout that must be JSON alone, a file
that must be left as it was, an option every subcommand must take, and the workflow's configuration given on the
command line."""

from __future__ import annotations

import argparse
import json

import pytest
import yaml

from parksteer.cli import build_parser, main

from .corpus import BASELINE, POLO, REPO


def _leaves(parser: argparse.ArgumentParser, prefix: tuple[str, ...] = ()):
    groups = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not groups:
        yield prefix, parser
        return
    for name, child in groups[0].choices.items():
        yield from _leaves(child, prefix + (name,))


def test_every_subcommand_takes_quiet():
    """The README promises --quiet for every subcommand: each leaf of the command tree has it (15 or more)."""
    leaves = list(_leaves(build_parser()))
    assert len(leaves) >= 15
    missing = [" ".join(p) for p, parser in leaves if not any("--quiet" in a.option_strings for a in parser._actions)]
    assert missing == []


def test_identify_json_is_json_alone_and_force_overwrites(tmp_path, capsys):
    """assist identify --json into an existing file with --force: stdout parses as one JSON document (progress and
    'wrote' on stderr) and the file is the identified vehicle, not the one that was there."""
    out = tmp_path / "id.toml"
    out.write_text("# the user's own file\n", encoding="utf-8")
    status = main(["assist", "identify", str(BASELINE), "--vehicle", str(POLO), "--out", str(out), "--json",
                   "--force"])
    stdout, stderr = capsys.readouterr()
    assert status == 0, stderr
    assert json.loads(stdout)["assist"] == "electric_assist_column"
    assert "identify:" in stderr and f"wrote {out}" in stderr
    assert "[assist.boost]" in out.read_text(encoding="utf-8")


def test_identify_leaves_an_existing_file_as_it_was(tmp_path, capsys):
    """Without --force an existing --out is refused before any work, its bytes unchanged."""
    out = tmp_path / "id.toml"
    out.write_bytes(b"# the user's own file\n")
    assert main(["assist", "identify", str(BASELINE), "--vehicle", str(POLO), "--out", str(out)]) == 2
    assert "exists (--force to overwrite)" in capsys.readouterr().err
    assert out.read_bytes() == b"# the user's own file\n"


@pytest.mark.parametrize("value, valid", [(True, True), (False, True), ("true", True), ("false", True),
                                          ("yes", False), (1, False)])
def test_sweep_full_schema_takes_the_command_lines_spelling(value, valid):
    """`snakemake --config sweep_full=true` gives the string 'true' (Snakemake reads only True and False as
    booleans): the schema takes it and the boolean, and refuses other words and numbers."""
    import jsonschema

    schema = yaml.safe_load((REPO / "workflow" / "schemas" / "config.schema.yaml").read_text(encoding="utf-8"))
    errors = list(jsonschema.Draft7Validator({"type": "object", "properties": {
        "sweep_full": schema["properties"]["sweep_full"]}}).iter_errors({"sweep_full": value}))
    assert (errors == []) == valid


def test_sweep_full_is_read_as_its_truth():
    """The rule reads 'false' as false (bool('false') is True) and writes the boolean back for the batch jobs."""
    text = (REPO / "workflow" / "rules" / "sweep.smk").read_text(encoding="utf-8")
    line = next(l for l in text.splitlines() if l.startswith("SWEEP_FULL ="))
    for given, expected in ((True, True), ("true", True), (False, False), ("false", False)):
        config = {"sweep_full": given}
        assert eval(line.partition("=")[2], {"config": config}) is expected  # noqa: S307 (the rule's own line)
    assert 'config["sweep_full"] = SWEEP_FULL' in text
