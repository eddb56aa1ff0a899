"""Synthetic measurement files for the diagnose tests, made once per session (seeded)."""

from __future__ import annotations

import pytest

from parksteer.synthetic.datasets import DatasetSpec, make_dataset
from parksteer.measure.io import write_measurement

ONE_FILE = (("unladen", "ground"),)


@pytest.fixture(scope="session")
def written(tmp_path_factory, params):
    """make(name, kind, hidden, steps, base_overrides, ...) -> (paths, truth); each data set generated once."""
    cache = {}
    root = tmp_path_factory.mktemp("diagnose_data")

    def make(name, kind="null", hidden=None, steps=None, base_overrides=None, files=ONE_FILE, seed=4242, phase=None,
             strength=None):
        if name not in cache:
            spec = DatasetSpec(name, seed, files, kind, hidden, steps, dict(base_overrides or {}), phase, strength)
            dataset = make_dataset(params, spec)
            paths = []
            for m, (case, surface) in zip(dataset.measurements, files):
                path = root / name / f"{case}__{surface}.csv"
                write_measurement(path, m, params)
                paths.append(path)
            cache[name] = (paths, dataset.truth)
        return cache[name]

    return make
