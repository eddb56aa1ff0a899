"""The assisted truth benchmark's design: its out-of-class sizes' upper bounds, the design's fields (config/config.yaml,
section ``assisted_truth``), its cases and their seeds (:mod:`parksteer.experiments.assisted_truth` says what the
benchmark is)."""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field

from ..errors import UsageError
from ..synthetic.assisted_truth import HIDDEN_TRUTH, TruthGear, TruthMap
from ..synthetic.size_search import SizeSearch


# The largest size searched for each out-of-class form (its unit the truth's: N m, N m, rad, 1); a hidden
# candidate's is its row of HIDDEN_TRUTH.
OUT_OF_CLASS_LARGEST = {"cogging": 0.5, "boost_hysteresis": 1.0, "gear_backlash": 3.0, "current_friction": 0.8}


def largest_size(name: str) -> float:
    """The largest size the size search tries for hidden candidate or out-of-class form `name` (the truth's unit)."""
    return HIDDEN_TRUTH[name].largest if name in HIDDEN_TRUTH else OUT_OF_CLASS_LARGEST[name]


SEARCH = SizeSearch(iterations=4, tolerance=0.05, max_lag_s=0.0)


# Hidden effects at least this many noise floors RMS count towards the named rate (module docstring).
NAMED_MIN_FLOORS = 2.0


TIERS = ("rack", "angle")


@dataclass(frozen=True)
class TruthDesign:
    """The truth's car (map, gear), the owner's file (the map's points), the loggers' torque converters
    (bits, full scale), the cases (hands, sizes in noise floors, out-of-class forms), the tiers and the seed."""

    case: str = "kerb"
    boost: TruthMap = TruthMap()
    gear: TruthGear = TruthGear()
    map_points_Nm: tuple[float, ...] = (0.0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.5, 3.0, 4.0)
    torque_converters: tuple[tuple[int, float], ...] = ((10, 10.0), (11, 10.24), (12, 10.24))
    # the channels' noise, the assisted benchmark's (parksteer.experiments.assisted_benchmark: relative to the
    # parking range as the variation benchmark's)
    torque_noise_Nm: float = 0.03
    current_noise_A: float = 0.25
    tiers: tuple[str, ...] = TIERS
    null_variations: tuple[str, ...] = ("rest_after_stop", "mid_stroke_end", "pauses", "rate_8pc_50Hz",
                                        "rate_3pc_200Hz", "uneven_strokes", "lock_overshoot",
                                        "rack_16bit_torque_10bit")
    null_replicates: int = 1
    hidden_variations: tuple[str, ...] = ("pauses", "uneven_strokes")
    hidden: tuple[str, ...] = field(default_factory=lambda: tuple(HIDDEN_TRUTH))
    floors: tuple[float, ...] = (2.0, 4.0)
    out_of_class: tuple[tuple[str, float], ...] = (("cogging", 3.0), ("boost_hysteresis", 3.0),
                                                    ("gear_backlash", 3.0), ("current_friction", 3.0))
    out_of_class_variations: tuple[str, ...] = ("uneven_strokes",)
    routes: tuple[str, ...] = ("map",)
    baseline_variation: str = "rest_after_stop"
    seed: int = 4242


@dataclass(frozen=True)
class TruthCase:
    name: str
    tier: str
    kind: str  # null, hidden, outclass
    variation: str
    hidden: str | None
    floors: float | None
    converter: tuple[int, float]
    seed: int


def cases(design: TruthDesign) -> list[TruthCase]:
    """Every case of `design`, in a fixed order. A case's seed follows its hand's place in
    :data:`~parksteer.synthetic.variations.VARIATIONS`, its replicate and its tier, and its torque converter is one
    of the design's picked by its name: a case kept by a smaller design is the full design's case of that name."""
    out: list[TruthCase] = []
    for tier in design.tiers:
        made: list[tuple] = []
        for replicate in range(design.null_replicates):
            for v in design.null_variations:
                made.append((f"{v}__r{replicate}__null", "null", v, None, None, case_seed(design, v, replicate)))
        for v in design.hidden_variations:
            for effect in design.hidden:
                for size in design.floors:
                    made.append((f"{v}__{effect}_{size:g}", "hidden", v, effect, size, case_seed(design, v)))
        for v in design.out_of_class_variations:
            for form, size in design.out_of_class:
                made.append((f"{v}__{form}_{size:g}", "outclass", v, form, size, case_seed(design, v)))
        for name, kind, v, hidden, size, seed in made:
            converter = design.torque_converters[zlib.crc32(f"{tier}__{name}".encode()) % len(design.torque_converters)]
            out.append(TruthCase(f"{tier}__{name}__t{converter[0]}", tier, kind, v, hidden, size, converter,
                                 seed + (500 if tier == "angle" else 0)))
    return out


def case_seed(design: TruthDesign, variation: str, replicate: int = 0) -> int:
    from ..synthetic.variations import VARIATIONS

    names = [v.name for v in VARIATIONS]
    if variation not in names:
        raise UsageError(f"assisted truth: no hand {variation!r} (the hands: {', '.join(names)})")
    return design.seed + 1000 * replicate + 10 * names.index(variation)


def case_names(design: TruthDesign = TruthDesign()) -> list[str]:
    return [c.name for c in cases(design)]
