"""`snakemake --report`: every figure and table the pipeline builds (the inputs of rule `all`, that is every file
of FIGURES in workflow/rules/common.smk and the article) is in the report, with its own caption and a category.

A report only needs the marked files to exist, not their contents: in a copy of the repository (its tracked and
new files) every output of the pipeline is created empty, then `snakemake --report` runs on the copy. No job runs.
The list of files the report must hold is read from the DAG (the dry run of rule `all`), not from the report code.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

# Snakemake's report, run in this process (the conftest fixture `snakemake`), calls docutils with an argument
# docutils 2.0 will drop: its warning is about that code, not this package's.
pytestmark = [pytest.mark.slow,
              pytest.mark.filterwarnings('ignore:Argument "writer_name" will be removed:PendingDeprecationWarning')]

def _script_value(html: str, name: str):
    """The JSON value the report page assigns to `var <name> = ...;` (its last such line: the page's bundled
    libraries come first and may use the same name)."""
    starts = list(re.finditer(rf"\bvar {name} = ", html))
    assert starts, f"report has no `var {name}`"
    value, _ = json.JSONDecoder().raw_decode(html, starts[-1].end())
    return value


@pytest.fixture(scope="module")
def repository_copy(copy_repository, tmp_path_factory) -> Path:
    """A copy of the repository (its tracked and new files)."""
    return copy_repository(tmp_path_factory.mktemp("report"))


def _report(snakemake, placeholder_files, work: Path, target: str, *options: str) -> tuple[list[str], dict, str]:
    """(the inputs of rule `target`, the report's results by path, the report page), every output of the target's
    DAG created empty first.

    One dry run gives both: with the outputs missing it plans every job of the DAG, each with its outputs, and the
    target's own job (a rule of inputs alone, planned whatever exists) with its inputs."""
    planned = "".join(snakemake(work, target, "--dry-run", *options))
    inputs = re.search(rf"^(?:local)?rule {target}:\n\s+input: (.+)$", planned, re.MULTILINE)
    assert inputs, planned[-3000:]
    outputs = [name for line in re.findall(r"^\s+output: (.+)$", planned, re.MULTILINE) for name in line.split(", ")]
    assert outputs, planned[-3000:]
    placeholder_files(work, outputs)
    snakemake(work, "--report", f"{target}.html", target, *options)
    html = (work / f"{target}.html").read_text(encoding="utf-8")
    return inputs.group(1).split(", "), _script_value(html, "results"), html


@pytest.fixture(scope="module")
def report(repository_copy, placeholder_files, snakemake) -> tuple[list[str], dict, str]:
    """The report of the default target `all`."""
    return _report(snakemake, placeholder_files, repository_copy, "all")


def test_every_figure_and_the_article_are_in_the_report(report):
    """Each file rule `all` builds (every FIGURES file, plot and data, and paper/parksteer.pdf) is an entry of the
    report, and nothing else is."""
    targets, results, _ = report
    assert "paper/parksteer.pdf" in targets and "figures/fig12.svg" in targets and "figures/table1.csv" in targets
    assert sorted(results) == sorted(targets)


def test_each_entry_has_its_own_caption_naming_its_rule(report):
    """A caption is written for each figure: the rendered caption names the rule that built the file, and no two
    figures share a caption (the model figures, one wildcard rule, each get their own text)."""
    _, results, _ = report
    by_figure: dict[str, set[str]] = {}
    for path, entry in results.items():
        caption = entry["caption"]
        rule = entry["job_properties"]["rule"]
        assert f'<tt class="docutils literal">{rule}</tt>' in caption, (path, caption)
        by_figure.setdefault(Path(path).stem, set()).add(caption)
    assert all(len(captions) == 1 for captions in by_figure.values()), by_figure  # plot and data share one
    captions = [next(iter(c)) for c in by_figure.values()]
    assert len(set(captions)) == len(captions)


def test_each_entry_is_in_a_category_and_labelled(report):
    """Every entry is filed under a category and a subcategory named after its figure, labelled plot or data."""
    _, results, html = report
    categories = _script_value(html, "categories")
    filed = {path: (category, sub) for category, subs in categories.items() for sub, paths in subs.items()
             for path in paths}
    for path, entry in results.items():
        assert path in filed, path
        category, sub = filed[path]
        assert category and category != "Other", (path, category)
        assert sub == Path(path).stem, (path, sub)
        assert entry["labels"] == {"figure": Path(path).stem,
                                   "file": "data (CSV)" if path.endswith(".csv") else "plot"}


def test_a_vehicle_study_report_holds_its_figures_and_the_diagnosis_page(repository_copy, placeholder_files,
                                                                        snakemake):
    """`snakemake --report ... vehicle_study --config vehicle=polo_vi` holds the study's comparison and diagnosis
    figures and its HTML diagnosis report, filed under the vehicle, each caption naming the vehicle."""
    targets, results, _ = _report(snakemake, placeholder_files, repository_copy, "vehicle_study", "--config", "vehicle=polo_vi")
    shown = sorted(t for t in targets if t.endswith((".svg", ".html")))
    assert shown == sorted(["figures/vehicles/polo_vi/compare.svg", "figures/vehicles/polo_vi/diagnosis.svg",
                            "results/vehicles/polo_vi/report.html"])
    assert sorted(results) == shown
    for path, entry in results.items():
        assert "polo_vi" in entry["caption"], path
