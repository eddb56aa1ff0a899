"""Malformed and odd inputs across the entry points (tests/hardening/corpus.py), a user's effect files, boost tables
and the assist commands among them: each either runs (exit 0) or is refused with exit status 2 and one line on
stderr holding the expected fragment and the input's name, with no traceback and no output written. The class counts must be zero except "clean error" and "accepted"."""

from __future__ import annotations

import os

import pytest

from parksteer.cli import main

from .corpus import ACCEPTED, all_cases

CASES = all_cases()


def _run(argv, capsys):
    status = main(argv)
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_input_gets_its_expected_outcome(case, tmp_path, capsys, monkeypatch):
    """The outcome of one corpus input: 'accepted' runs to exit 0; otherwise exit 2, exactly one line on stderr
    holding the expected fragment, and none of the command's outputs written. An exception escaping main() (a
    traceback) fails the test by itself."""
    monkeypatch.chdir(tmp_path)
    for name, value in case.env:
        monkeypatch.setenv(name, value.replace("{scratch}", str(tmp_path)))
    argv = case.make(tmp_path)
    try:
        status, out, err = _run(argv, capsys)
    finally:
        for arg in argv:  # close descriptors opened for /dev/fd/N paths
            if arg.startswith("/dev/fd/"):
                os.close(int(arg.rsplit("/", 1)[1]))
    if case.expect == ACCEPTED:
        assert status == 0, err
        return
    assert "Traceback" not in err
    if case.status == 1:  # a verification's findings: one line per problem on stdout, then the summary
        assert status == 1, (status, out, err)
        assert sum(case.expect in line for line in out.splitlines()) == 1, out
        return
    lines = [line for line in err.splitlines() if line.strip()]  # a refused input gives its line alone, no notes
    assert status == 2, (status, err)
    assert len(lines) == 1, err
    assert case.expect in lines[0], lines[0]
    for rel in case.outputs:
        assert not (tmp_path / rel).exists(), rel


def test_corpus_is_large_and_covers_every_entry_point():
    """At least 60 inputs, every entry point tried, both outcomes present."""
    assert len(CASES) >= 60
    assert {c.entry for c in CASES} == {"compare", "diagnose", "simulate", "check-params", "checksums",
                                        "vehicle", "assist"}
    assert len({c.name for c in CASES}) == len(CASES)
    assert any(c.expect == ACCEPTED for c in CASES) and any(c.expect != ACCEPTED for c in CASES)
