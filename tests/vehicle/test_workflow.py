"""The vehicle study in Snakemake: its own outputs under the vehicle's name, outside the default target."""

from __future__ import annotations

from pathlib import Path

import pytest


def _summary(snakemake, repo_root: Path, *args: str) -> dict[str, str]:
    """Output file -> rule of a target's DAG (snakemake --summary, `snakemake` the conftest fixture; no job runs)."""
    out, _ = snakemake(repo_root, *args, "--summary")
    rows = [line.split("\t") for line in out.splitlines()[1:] if "\t" in line]
    return {row[0]: row[2] for row in rows}


@pytest.fixture(scope="module")
def dags(repo_root, snakemake):
    return (_summary(snakemake, repo_root, "vehicle_study", "--config", "vehicle=polo_vi"),
            _summary(snakemake, repo_root, "all"))


def test_vehicle_study_writes_under_its_own_name(dags, repo_root):
    """Every file the Polo's study makes lies under results/vehicles/polo_vi/ or figures/vehicles/polo_vi/, apart
    from the compiled-model manifests the default build makes too; none is a checksummed figure."""
    study, default = dags
    own = [f for f in study if f.startswith(("results/vehicles/polo_vi/", "figures/vehicles/polo_vi/"))]
    assert {"results/vehicles/polo_vi/compare.json", "results/vehicles/polo_vi/diagnosis.json",
            "results/vehicles/polo_vi/report.html", "figures/vehicles/polo_vi/compare.svg",
            "figures/vehicles/polo_vi/diagnosis.svg"} <= set(own)
    shared = [f for f in study if f not in own]
    assert shared and all(study[f] == "derive" and f in default for f in shared), shared
    checksummed = {line.split()[-1].lstrip("*") for line in
                   (repo_root / "figures" / "SHA256SUMS").read_text().splitlines() if line.strip()}
    assert not checksummed & {str(Path(f)) for f in study}


def test_default_target_holds_no_vehicle_rule(dags):
    """`all` (what CI builds) plans no rule of the vehicle study."""
    _, default = dags
    assert default and not [f for f, rule in default.items() if rule.startswith("vehicle_")]
