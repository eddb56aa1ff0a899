"""What the workflow takes from the package while it builds its DAG, as plain data (names, paths, cache keys).

The Snakefile needs the effect set of every model it derives, the case names of the benchmarks, the car data
set's files and the rivals of the out-of-class benchmark. Each function here returns JSON-ready data, which the
rules pass on as parameters (workflow/rules/common.smk, `plan`).
"""

from __future__ import annotations

from typing import Any


def model_set(spec: Any) -> dict:
    """The effects spec `spec` resolved: {"effects": the effect names in order, "key": its model cache key}."""
    from .model.codegen.cache import model_key
    from .model.symbolic.components import resolve_effects

    effects = resolve_effects(spec)
    return {"effects": [e.name for e in effects], "key": model_key(effects)}


def rival_names(selection: list | None = None) -> list[str]:
    """The rival effects the rivals figure compares: the configuration's `selection` checked to be rivals, or
    every effect that declares a rival (parksteer.model.symbolic.rivals.chosen_rivals)."""
    from .model.symbolic.rivals import chosen_rivals

    return list(chosen_rivals(selection, "config rivals"))


def case_file(folder: str, name: str, part: str) -> str:
    """The truth or diagnosis file of benchmark case `name` in its job's `folder`
    (parksteer.experiments.benchmark.case_files)."""
    from .experiments.benchmark import case_files

    return str(case_files(folder, name)[{"truth": 1, "diagnosis": 2}[part]])


def diagnosis(config: dict, parameters_path: str, user_effect: str) -> dict:
    """What the diagnosis rules need of the configuration's car data set and its three benchmarks:
    candidate model specs by name, the car data set's files, and the case names (and rivals) of the hidden-effect,
    out-of-class, variation and signature benchmarks."""
    from .experiments.benchmark import case_names as bench_case_names
    from .diagnose.candidates import candidate_models
    from .experiments.outclass import case_names as outclass_case_names
    from .experiments.outoflibrary import case_names as signature_case_names, design_from_config as signature_design
    from .experiments.variations import VariationDesign, case_names as variation_case_names
    from .parameters import load_parameters
    from .synthetic.datasets import BenchmarkDesign, CarDesign, file_name
    from .synthetic.outclass import OutclassDesign

    params = load_parameters(parameters_path)
    car = CarDesign.from_config(config["car"])
    bench = BenchmarkDesign.from_config(config["benchmark"])
    outclass = OutclassDesign.from_config(config["outclass"], config["benchmark"])
    variations = VariationDesign.from_config(config["variations"])
    return {
        "candidates": dict(candidate_models(None, (user_effect,))),
        "car_files": [file_name(case, surface) for case, surface in car.files],
        "bench_cases": bench_case_names(bench, params),
        "outclass_cases": outclass_case_names(outclass, params),
        "outclass_rivals": list(outclass.rivals),
        "variation_cases": variation_case_names(variations),
        "signature_cases": signature_case_names(signature_design(config["signature"])),
    }


def assisted_truth_cases(section: dict | None = None) -> list[str]:
    """The case names of the assisted benchmark on an independent truth (parksteer.experiments.assisted_truth), in
    its order, of the design config["assisted_truth"] gives (each case keeps its own seed and converter)."""
    from .experiments.assisted_truth import design_from_config
    from .experiments.assisted_truth_design import case_names

    return case_names(design_from_config(section))


def assisted_models(vehicle_path: str) -> dict[str, str]:
    """The compiled models of the assisted benchmarks' jobs (:func:`parksteer.diagnose.candidates.assisted_models`
    of the vehicle file's car: those its diagnoses replay, and the car with each assisted candidate its records
    hide), by name, as effects specs. Derived before the jobs, so that parallel jobs do not compile the same models
    side by side."""
    from pathlib import Path

    from .diagnose.candidates import assisted_models as models
    from .vehicle import load_vehicle

    if not Path(vehicle_path).is_file():  # a workflow copy without the car: its rules say what input is missing
        return {}
    sets = models(load_vehicle(vehicle_path))
    names = {e.name for e in sets[0]} if sets else set()
    out = {}
    for model in sets:
        extra = sorted(e.name for e in model if e.name not in names)
        name = "assisted_" + ("base" if not extra else f"with_{extra[0]}" if len(extra) == 1 else "diagnosis")
        out[name] = ",".join(e.name for e in model)
    return out


def assisted_cases(section: dict | None = None) -> list[str]:
    """The case names of the assisted benchmark (parksteer.experiments.assisted_benchmark), in its order: the full
    design's, or those of the hands config["assisted_benchmark"] keeps (each case keeps its own seed, so a kept
    case is the full grid's case of that name)."""
    from dataclasses import replace

    from .experiments.assisted_benchmark import AssistedDesign, case_names

    design = AssistedDesign()
    if section:
        named = [*section["hidden_variations"], *section["out_of_class_variations"]]
        unknown = [v for v in named if v not in design.null_variations]
        if unknown:
            from .errors import UsageError

            raise UsageError(f"config assisted_benchmark: {unknown[0]} is not a hand of the assisted benchmark "
                             f"(its hands: {', '.join(design.null_variations)})")
        design = replace(design, null_replicates=int(section["null_replicates"]),
                         hidden_variations=tuple(section["hidden_variations"]),
                         out_of_class_variations=tuple(section["out_of_class_variations"]))
    return case_names(design)


def sweep(path: str, parameters_path: str, full: bool, batch_size: int, index_dir: str) -> dict:
    """The sweep declared in `path`, read, checked and expanded (parksteer.sweep.load_sweep; its braked-wheel
    check resolves effects): its name, effect sets by variant, what every point spec shares, and its batch ids;
    each batch's points go to the sweep's batch index under `index_dir`
    (parksteer.sweep.batch_index.write_batch_index), where its job reads them."""
    from .parameters import load_parameters
    from .sweep import load_sweep
    from .sweep.batch_index import write_batch_index

    declared = load_sweep(path, load_parameters(parameters_path), full=full)
    write_batch_index(declared, batch_size, index_dir)
    return {
        "name": declared.name,
        "model_sets": dict(declared.model_sets),
        "shared": declared.shared_spec,
        "batches": sorted(declared.batches(batch_size)),
    }
