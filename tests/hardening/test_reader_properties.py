"""Property: how a record is written (delimiter, line ends, byte-order mark, blank lines, spacing around cells)
does not change what the one reader returns for it."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from parksteer.measure.importers import load_record

from .corpus import record_text

PLAIN = record_text()


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(sep=st.sampled_from([",", ";", "\t"]), newline=st.sampled_from(["\n", "\r\n", "\r"]), bom=st.booleans(),
       blank_every=st.integers(min_value=0, max_value=7), pad=st.sampled_from(["", " ", "  "]))
def test_dialect_does_not_change_the_record(tmp_path_factory, params, sep, newline, bom, blank_every, pad):
    """The same samples written in any accepted dialect read back to identical columns and metadata."""
    folder = tmp_path_factory.mktemp("dialect")
    plain = folder / "plain.csv"
    plain.write_text(PLAIN, encoding="utf-8", newline="")
    text = record_text(sep=pad + sep + pad, newline=newline, blank_every=blank_every, bom=bom)
    odd = folder / "odd.csv"
    odd.write_text(text, encoding="utf-8", newline="")
    a, b = load_record(plain, params=params), load_record(odd, params=params)
    assert list(a.columns) == list(b.columns)
    for name in a.columns:
        assert np.array_equal(a.columns[name], b.columns[name]), name
    assert a.metadata == b.metadata
