"""The rack smoothing's search for its knot spacing keeps the fit of every spacing that passed
(parksteer.measure.smoothing.SmoothedRack.held_at): the replay ensemble smooths the rack again at those spacings,
holding rests, and takes the search's fits instead, on the promise that they are the same splines to the bit."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from parksteer.measure.importers import load_record
from parksteer.measure.smoothing import smooth_rack

ROOT = Path(__file__).resolve().parents[2]
RECORDS = ("data/measurements/example_unladen.csv", "data/samples/car/unladen__ground.csv")


def _rack(name: str) -> tuple[np.ndarray, np.ndarray]:
    record = load_record(ROOT / name)
    return np.asarray(record.time_s, dtype=float), np.asarray(record.rack_m, dtype=float)


def _same(a, b) -> bool:
    """Equal in value and type, arrays bit for bit."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.dtype == b.dtype
                and a.shape == b.shape and a.tobytes() == b.tobytes())
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return type(a) is type(b) and a == b


@pytest.mark.parametrize("name", RECORDS)
@pytest.mark.parametrize("rest_resolution_m", [0.0, 1e-4])
def test_the_searchs_fit_at_each_passing_spacing_is_the_spline_smoothed_at_it(name, rest_resolution_m):
    """For every spacing the search passed, held_at gives the rack smooth_rack makes at that spacing holding rests
    (the same least-squares fit of the same samples, turns and pauses): every field equal, arrays to the bit."""
    t, x = _rack(name)
    searched = smooth_rack(t, x, rest_resolution_m=rest_resolution_m)
    assert len(searched.passing_spacings_s) > 1  # the ensemble's spacings are more than the chosen one
    for spacing in searched.passing_spacings_s:
        kept = searched.held_at(t, x, spacing)
        made = smooth_rack(t, x, spacing, hold_rest=True, rest_resolution_m=rest_resolution_m)
        for field in dataclasses.fields(made):
            if field.name != "search_fits":
                assert _same(getattr(kept, field.name), getattr(made, field.name)), (spacing, field.name)


def test_no_fit_is_given_for_other_samples_another_spacing_or_a_smoothing_without_a_search():
    """held_at answers only for the samples the search fitted and a spacing that passed; a rack smoothed at a given
    spacing, or with its ends and pauses free, keeps no fits."""
    t, x = _rack(RECORDS[0])
    searched = smooth_rack(t, x)
    spacing = searched.passing_spacings_s[-1]
    moved = x.copy()
    moved[len(x) // 2] += 1e-6
    assert searched.held_at(t, moved, spacing) is None
    assert searched.held_at(t + 1e-3, x, spacing) is None
    assert searched.held_at(t, x, spacing * 1.01) is None
    assert smooth_rack(t, x, spacing).search_fits is None
    assert smooth_rack(t, x, hold_rest=False).held_at(t, x, spacing) is None


def _same_rack(a, b) -> bool:
    """Every field of two smoothed racks equal (arrays to the bit), but the search's fits."""
    return all(_same(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a)
               if f.name != "search_fits")


@pytest.mark.parametrize("name", RECORDS)
def test_a_rack_smoothed_again_is_the_rack_smooth_rack_makes_and_is_made_once(name):
    """smoothed_at (every passing spacing and one that failed, ends and pauses held and free) and resmoothed (the
    rack logged again) give what smooth_rack makes of the same arguments, every field equal and arrays to the bit;
    asked again with the same arguments and memo they give the very rack they made, with other samples another,
    and the rack they are asked of holds nothing of them (the memo is its owner's)."""
    t, x = _rack(name)
    searched = smooth_rack(t, x, rest_resolution_m=1e-4)
    memo = {}
    attributes_before = set(vars(searched))
    spacings = [*searched.passing_spacings_s, searched.passing_spacings_s[-1] * 0.8]
    for spacing in spacings:
        for hold in (True, False):
            made = searched.smoothed_at(t, x, spacing, hold, memo)
            assert _same_rack(made, smooth_rack(t, x, spacing, hold_rest=hold, rest_resolution_m=1e-4)), spacing
            assert searched.smoothed_at(t, x, spacing, hold, memo) is made
    moved = x.copy()
    moved[len(x) // 2] += 1e-4
    other = searched.smoothed_at(t, moved, spacings[0], False, memo)
    assert _same_rack(other, smooth_rack(t, moved, spacings[0], hold_rest=False, rest_resolution_m=1e-4))
    assert not _same_rack(other, searched.smoothed_at(t, x, spacings[0], False, memo))
    noise = np.random.default_rng(3).normal(0.0, 2e-5, len(t))
    logged = {}
    for hold in (True, False):
        logged[hold] = searched.resmoothed(t, lambda clean: clean + noise, hold, memo=memo)
        again = smooth_rack(t, searched.evaluate(t)[0] + noise, searched.knot_spacing_s, hold_rest=hold)
        assert _same_rack(logged[hold], again)
        assert searched.resmoothed(t, lambda clean: clean + noise, hold, memo=memo) is logged[hold]
    assert not _same_rack(searched.resmoothed(t, lambda clean: clean - noise, True, memo=memo), logged[True])
    assert searched.resmoothed(t, lambda clean: clean + noise, True) is not logged[True]  # no memo: made afresh
    assert set(vars(searched)) == attributes_before and memo
