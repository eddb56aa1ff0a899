"""The reference pages of docs/ (the effect library, the command line, the vehicle file) are what the code gives
(parksteer.reference): a new option, effect or vehicle key changes the page, so the page cannot drift."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from parksteer import reference

DOCS = Path(__file__).resolve().parents[1] / "docs"


@pytest.mark.parametrize("name", sorted(reference.PAGES))
def test_reference_page_is_the_code_s(name):
    """docs/<name> is byte for byte the page its generator writes from the code now; after a change to an option,
    an effect or a vehicle-file key, `python -m parksteer.reference docs` writes it again."""
    page = (DOCS / name).read_text(encoding="utf-8")
    assert page == reference.PAGES[name](), (
        f"docs/{name} differs from the code: run `python -m parksteer.reference docs` and commit it")


def test_cli_page_follows_the_parser(monkeypatch):
    """An option added to a subcommand's parser appears on the command-line page with its help: the comparison
    above would fail on a page written before it."""
    from parksteer import cli

    real = cli.build_parser

    def with_extra_option() -> argparse.ArgumentParser:
        parser = real()
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        sub.choices["simulate"].add_argument("--extra-option-m", metavar="X", help="an option for this test")
        return parser

    before = reference.cli_page()
    monkeypatch.setattr(cli, "build_parser", with_extra_option)
    after = reference.cli_page()
    assert "| `--extra-option-m X` | an option for this test |" in after
    assert "--extra-option-m" not in before


def test_pages_name_every_effect_subcommand_and_required_key():
    """Each library effect has a row on the effects page, each subcommand a section on the command-line page, and
    each key a vehicle file must give a row on the vehicle-file page (the generators leave none out)."""
    from parksteer.cli import build_parser
    from parksteer.vehicle import REQUIRED

    effects = reference.effects_page()
    for name in reference._library_effects():
        assert f"| `{name}` |" in effects, name
    commands = reference.cli_page()
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    for name in sub.choices:
        assert f"## `parksteer {name}`" in commands, name
    vehicle = reference.vehicle_file_page()
    for key in REQUIRED:
        assert f"| `{key}` |" in vehicle and "| yes |" in vehicle.split(f"| `{key}` |")[1].splitlines()[0], key
