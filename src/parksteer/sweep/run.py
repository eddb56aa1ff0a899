"""One sweep point: simulate the cycle with the point's parameters and write its figures of merit.

With the wheels braked as well, if the sweep asks: a second simulation with the braked effect added
(at the top of its brake_fraction range, wheels held), which also records the post-hoc rig-theory
estimate from the free-rolling run as a cross-check; or that estimate alone (``braked: rig_theory``).

A point job never derives the model: it refuses to run unless the compiled model of its
effect set is already in the cache (the pipeline's derive rule puts it there first), so
every point pays only for loading the shared library and one integration.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

from ..errors import UsageError
from ..geometry import steer_axis
from ..parameters import Parameters, load_parameters
from ..tables import write_json
from .design import SweepError
from .fields import BRAKE_PARAMETER, BRAKED_NONE, BRAKED_RIG_THEORY
from .design import point_overrides
from .merit import braked_columns, braked_factor, figures_of_merit, ground_offset_m

RIG_THEORY_METHOD = (
    "rig theory: the simulated tyre-friction contribution multiplied by the braked/free-rolling ratio of "
    "parksteer.rig (the patch dragged rigidly about the axis's ground point instead of spinning about its centre), "
    "weighted over both wheels by W^1.5; the carcass wind-up is that of the free-rolling run"
)
BRAKED_QUANTITIES = ("plateau_torque_Nm", "peak_torque_Nm", "lock_torque_Nm")


def require_cached_model(effects) -> Path:
    """The cache entry of `effects`; a one-line error if it has not been derived yet."""
    from ..model.codegen.cache import entry_path

    entry = entry_path(effects)
    if not ((entry / "model.json").is_file() and (entry / "model.so").is_file()):
        names = ",".join(e.name for e in effects) or "none"
        raise UsageError(f"the model of effects {names} is not derived yet ({entry}): run `parksteer derive` first; "
                         "a sweep point never derives")
    return entry


def simulate_point(spec: dict[str, Any], params: Parameters) -> dict[str, Any]:
    """Simulate one point (a dict as Sweep.point_spec returns) and return its record of figures of merit."""
    from ..model.symbolic.components import resolve_effects
    from ..model.numeric.simulate import simulate

    effects = resolve_effects(spec["effects"])
    entry = require_cached_model(effects)
    try:
        overrides = point_overrides(params, spec["case"], spec["values"])
    except SweepError as exc:
        raise SweepError(f"point {spec['point']}: {exc}") from None
    result = simulate(spec["case"], effects=effects, overrides=overrides, surface=spec["surface"], params=params)
    merits = figures_of_merit(result.columns)
    record: dict[str, Any] = {
        "sweep": spec["sweep"],
        "point": spec["point"],
        "case": spec["case"],
        "surface": spec["surface"],
        "effects": [e.name for e in effects],
        "model_key": entry.name,
        "values": spec["values"],
        "overrides": overrides,
        "merits": merits,
    }
    record["braked"] = _braked(spec, params, overrides, result, merits)
    return record


def _tyre_total(merits: dict, names: list[str]) -> float:
    """The plateau torque carried by the named contributions (N m)."""
    return merits["plateau_torque_Nm"] * sum(merits.get(f"share_contrib_{n}_Nm", 0.0) for n in names)


def _braked(spec: dict[str, Any], params: Parameters, overrides: dict, free, free_merits: dict) -> dict[str, Any]:
    """The point with its wheels braked: simulated with the braked effect, or estimated by rig theory."""
    from ..model.symbolic.components import quantity_of, resolve_effects
    from ..model.numeric.simulate import simulate

    method = spec.get("braked", BRAKED_NONE)
    case, run_params = spec["case"], free.values.params
    if method == BRAKED_NONE:
        return {"method": "none", "factor": math.nan, "ground_offset_m": math.nan,
                **{q: math.nan for q in BRAKED_QUANTITIES}}
    pressure = free.values.value("tyre.tyre_pressure")
    factor = braked_factor(run_params, case, pressure)
    estimate = figures_of_merit(braked_columns(free.columns, factor))
    if method == BRAKED_RIG_THEORY:
        return {"method": RIG_THEORY_METHOD, "factor": factor,
                "ground_offset_m": ground_offset_m(run_params, case, "left"),
                **{q: estimate[q] for q in BRAKED_QUANTITIES}}
    effects = resolve_effects(spec["braked_effects"])
    entry = require_cached_model(effects)
    locked = quantity_of(f"{method}.{BRAKE_PARAMETER}", effects).upper
    run = simulate(case, effects=effects, overrides={**overrides, f"{method}.{BRAKE_PARAMETER}": locked},
                   surface=spec["surface"], params=params)
    braked = figures_of_merit(run.columns)
    return {
        "method": f"model effect {method} at {BRAKE_PARAMETER} = {locked:g} (wheels held), simulated",
        "model_key": entry.name,
        "factor": _tyre_total(braked, ["tyre_friction", method]) / _tyre_total(free_merits, ["tyre_friction"]),
        "ground_offset_m": abs(steer_axis(run_params, case, "left").scrub_radius_m()),
        **{q: braked[q] for q in BRAKED_QUANTITIES},
        "shares": {k: v for k, v in braked.items() if k.startswith("share_contrib_")},
        "rig_theory_factor": factor,
        **{f"rig_theory_{q}": estimate[q] for q in BRAKED_QUANTITIES},
    }


def run_point(spec: dict[str, Any], parameters_path: str | Path, out_json: str | Path) -> dict[str, Any]:
    """The point job: simulate `spec`, write its record as JSON, report the time on stderr."""
    start = time.perf_counter()
    record = simulate_point(spec, load_parameters(parameters_path))
    write_json(out_json, record)
    import sys

    print(f"point {spec['point']}: {time.perf_counter() - start:.3f} s, values {json.dumps(spec['values'])}",
          file=sys.stderr)
    return record


def run_batch(spec: dict[str, Any], parameters_path: str | Path, out_json: str | Path) -> dict[str, Any]:
    """The batch job: simulate every point of `spec` (as Sweep.batch_spec returns) in this one process, write
    their records to one JSON file (nothing if any point fails), report each point's time on stderr.

    The parameter file is read once and each compiled model loaded once for the whole batch; every record is the
    one simulate_point gives for that point alone.
    """
    import sys

    start = time.perf_counter()
    params = load_parameters(parameters_path)
    records = []
    for point in spec["points"]:
        begun = time.perf_counter()
        records.append(simulate_point(point, params))
        print(f"point {point['point']}: {time.perf_counter() - begun:.3f} s, values {json.dumps(point['values'])}",
              file=sys.stderr)
    batch = {"sweep": spec["sweep"], "batch": spec["batch"], "points": [p["point"] for p in spec["points"]],
             "records": records}
    write_json(out_json, batch)
    print(f"batch {spec['batch']}: {len(records)} points in {time.perf_counter() - start:.3f} s", file=sys.stderr)
    return batch
