"""The pipeline's configuration: config/config.yaml against workflow/schemas/config.schema.yaml, and the design
checks that need more than a schema."""

from __future__ import annotations

import copy

import pytest
import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

import syntax_trees

from parksteer.errors import UsageError
from parksteer.figures.model import FigureDesign


@pytest.fixture(scope="module")
def config(repo_root) -> dict:
    return yaml.safe_load((repo_root / "config" / "config.yaml").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def schema(repo_root) -> str:
    return str(repo_root / "workflow" / "schemas" / "config.schema.yaml")


def test_the_shipped_configuration_is_valid(config, schema):
    validate(copy.deepcopy(config), schema)


@pytest.mark.parametrize("section, key, value", [
    ("benchmark", "nulls", -1),  # a count
    ("benchmark", "bisection_tolerance", 1.5),  # a relative error below 1
    ("car", "files", [["unladen"]]),  # (case, surface) pairs
    ("variants", "air_bearing", {"model": "full", "surface": "ice"}),  # a known surface
    ("car", "colour", "red"),  # no unknown key
    ("variations", "files", [["unladen", "ground"]] * 4),  # a case has one to three files
    ("variations", "full_grid", "yes"),  # a switch
])
def test_a_bad_design_entry_is_refused(config, schema, section, key, value):
    bad = copy.deepcopy(config)
    bad[section][key] = value
    with pytest.raises(WorkflowError):
        validate(bad, schema)


def test_a_figure_run_of_an_undefined_variant_is_refused_in_one_line(config):
    bad = copy.deepcopy(config)
    bad["model_figures"]["fig14"].append(["unladen", "no_steering"])
    with pytest.raises(UsageError, match="model_figures.fig14") as info:
        FigureDesign.from_config(bad)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("size", [0, 2.5, "50"])
def test_a_sweep_batch_size_that_is_not_a_positive_integer_is_refused(config, schema, size):
    """sweep_batch_size counts points per sweep_batch job: zero, a fraction or a string is refused by the schema."""
    bad = copy.deepcopy(config)
    bad["sweep_batch_size"] = size
    with pytest.raises(WorkflowError):
        validate(bad, schema)


def test_the_rivals_are_a_selection_of_the_effects_that_declare_one(config):
    """The configuration selects rivals, it does not define them: its lists are effects that declare a rival, in
    the order given (the rows of the rivals figure, the seeds of the out-of-class data sets), every rival when a
    list is left out; rack_lash is a diagnosis candidate, not a rival, and naming it is refused in one line naming
    the entry."""
    from parksteer.model.symbolic.rivals import rival_effects
    from parksteer.plan import rival_names
    from parksteer.synthetic.outclass import OutclassDesign

    assert rival_names(config["rivals"]) == config["rivals"]
    assert rival_names(None) == sorted(rival_effects())
    without = {k: v for k, v in config["outclass"].items() if k != "rivals"}
    assert OutclassDesign.from_config(without, config["benchmark"]).rivals == tuple(sorted(rival_effects()))
    for call, entry in ((lambda: rival_names([*config["rivals"], "rack_lash"]), "config rivals"),
                        (lambda: OutclassDesign.from_config({**without, "rivals": ["rack_lash"]}, config["benchmark"]),
                         "config outclass.rivals")):
        with pytest.raises(UsageError, match=entry) as info:
            call()
        assert "\n" not in str(info.value) and "'rack_lash' is not a rival" in str(info.value)


def test_the_base_perturbation_has_one_definition(config, schema, repo_root):
    """The base perturbation is declared once (parksteer.synthetic.datasets.BASE_PERTURBATION): every benchmark's
    design built from the configuration carries its values, the configuration has no copy (its schema refuses a
    ``benchmark.perturbation``), and no other source file writes one of its fractions beside its key."""
    import ast

    from parksteer.experiments.variations import VariationDesign
    from parksteer.synthetic.datasets import BASE_PERTURBATION, BenchmarkDesign, CarDesign
    from parksteer.synthetic.outclass import OutclassDesign

    designs = (BenchmarkDesign.from_config(config["benchmark"]), CarDesign.from_config(config["car"]),
               OutclassDesign.from_config(config["outclass"], config["benchmark"]),
               VariationDesign.from_config(config["variations"]))
    assert all(d.perturbation == dict(BASE_PERTURBATION) for d in designs)
    with_copy = copy.deepcopy(config)
    with_copy["benchmark"]["perturbation"] = dict(BASE_PERTURBATION)
    with pytest.raises(WorkflowError):
        validate(with_copy, schema)
    # a second declaration: a mapping (a Python dict literal, a YAML mapping) whose keys are the perturbation's
    keys = set(BASE_PERTURBATION)

    def mappings(node):
        if isinstance(node, dict):
            yield node
            node = list(node.values())
        if isinstance(node, list):
            for item in node:
                yield from mappings(item)

    declaring = []
    for folder in ("src", "config", "workflow", "benchmarks", "data/samples"):
        for path in sorted((repo_root / folder).rglob("*")):
            if path.suffix == ".py":
                found = any(isinstance(n, ast.Dict) and {getattr(k, "value", None) for k in n.keys} == keys
                            for n in syntax_trees.nodes(path.read_text(encoding="utf-8")))
            elif path.suffix == ".yaml":
                found = any(set(m) == keys for m in mappings(yaml.safe_load(path.read_text(encoding="utf-8"))))
            elif path.suffix == ".smk":
                found = all(k in path.read_text(encoding="utf-8") for k in keys)
            else:
                continue
            if found:
                declaring.append(str(path.relative_to(repo_root)))
    assert declaring == ["src/parksteer/synthetic/datasets.py"]
