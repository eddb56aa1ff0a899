"""Records of an assisted car: the variation benchmark's hand, a logger of the car's own bus, the assisted replay.

The rack follows a hand of :mod:`.variations` (its speed wandering, the Section 4 strokes on the car's own lock),
the torsion-bar torque and the motor current are the assisted prescribed-rack solve of that rack
(:func:`parksteer.model.numeric.assisted.solve_assisted`, checked against the handwheel-driven simulation to
2e-5 N m and 2e-5 A), and an :class:`AssistedLogger` logs rack, torsion-bar torque and current, each on a converter
of its own. What can be hidden: a candidate (any effect with its strength; the law-side ones act in the replay's
boost law) or an out-of-class change of the car (:data:`OUT_OF_CLASS`): a motor whose delivered torque ripples
once per revolution (an eccentric worm or rotor), a dead band of the boost curve other than the file's, a torsion
bar stiffer than the file's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import portable as pm
from ..measure.io import Measurement, metadata_text
from ..parameters import Parameters
from ..measure.converter import add_noise, quantise
from .logger import resample
from .variations import CLEAN_DT_S, HandVariant, VariationLogger, variation_rack
from ..names import TORQUE


@dataclass(frozen=True)
class AssistedLogger(VariationLogger):
    """A logger on an assisted car's bus: rack, torsion-bar torque (its own full scale and bits, a parking torsion
    bar carrying a few N m) and the motor current (A)."""

    torque_bits: int = 10
    torque_full_scale_Nm: float = 10.0
    torque_noise_Nm: float = 0.02
    current_bits: int = 12
    current_full_scale_A: float = 100.0
    current_noise_A: float = 0.1
    log_current: bool = True


# Out-of-class changes of an assisted car (none is a candidate's form): name -> (what, its size's unit, related
# candidates a diagnosis may honestly name). A ripple of the delivered torque (fraction of it, once per motor
# revolution) is no friction, offset or gain; a wider dead band changes the curve's shape near zero (a gain error
# shares the curve, so it is related); a torsion bar's stiffness does not reach the torque with the rack given
# (the column is massless): the right answer is adequate.
OUT_OF_CLASS = {
    "motor_ripple": ("the motor's delivered torque rippling once per revolution", "1", ()),
    "dead_band_change": ("a boost-curve dead band wider than the file's", "N m", ("boost_gain_error",)),
    "torsion_bar_stiffness": ("a torsion bar stiffer than the file's", "1", ()),
}


def _motor_ripple(amplitude: float, reduction: float, pinion_angle: np.ndarray) -> np.ndarray:
    """A factor 1 + a sin(motor angle) on the delivered torque, the motor angle N times the pinion angle (the column's
    but for the intermediate joint's ripple, which only moves the ripple's phase)."""
    return 1.0 + amplitude * pm.sin(reduction * pinion_angle)


def assisted_clean(params: Parameters, hand: HandVariant, effects: str, case: str, surface: str = "ground",
                   overrides: dict[str, float] | None = None, out_of_class: tuple[str, float] | None = None,
                   dt_s: float = CLEAN_DT_S) -> dict[str, np.ndarray]:
    """The clean columns (time, rack, torsion-bar torque, motor current) of `hand` on the assisted car of
    `effects` (a spec with its assist), with `overrides` and an out-of-class change (name, size) if given."""
    from ..model.numeric.assisted import boost_law, solve_assisted
    from ..model.numeric.simulate import prepare

    rack = variation_rack(params, hand)
    t = np.round(np.arange(float(rack.start_s), float(rack.end_s) + 1e-12, dt_s), 12)
    t = t[t <= rack.end_s]
    overrides = dict(overrides or {})
    run = prepare(case, effects, overrides, surface, params)
    law, delivered = boost_law(run, run.p), None
    rack_m = rack_position(rack, t)
    if out_of_class is not None:
        kind, size = out_of_class
        if kind == "motor_ripple":
            delivered = _motor_ripple(size, law.reduction, law.ratio * rack_m)
        elif kind == "dead_band_change":
            law = law.with_wider_dead_band(size)
        elif kind == "torsion_bar_stiffness":
            key = f"{law.name}.torsion_bar_stiffness"
            run = prepare(case, effects, {**overrides, key: run.p[run.parameter_index(key)] * (1.0 + size)}, surface,
                          params)
        else:
            raise ValueError(f"unknown out-of-class change {kind!r} (known: {', '.join(OUT_OF_CLASS)})")
    solution = solve_assisted(run, run.p, rack, t, law=law, delivered=delivered)
    return {"time_s": t, "rack_m": rack_m, TORQUE: solution.torque_Nm,
            "motor_current_A": solution.motor_current_A}


def rack_position(rack, t: np.ndarray) -> np.ndarray:
    """The rack's position at `t` (its piecewise polynomial evaluated)."""
    from scipy.interpolate import PPoly

    return PPoly(np.asarray(rack.coefficients), np.asarray(rack.breaks))(t)


def assisted_record(clean: dict[str, np.ndarray], logger: AssistedLogger, case: str, surface: str = "ground"
                    ) -> Measurement:
    """`clean` logged: sampled at the logger's rate, noise added and each channel rounded to its converter."""
    time_s, sampled = resample(clean["time_s"], {k: v for k, v in clean.items() if k != "time_s"},
                               logger.sample_rate_hz)
    rng = np.random.default_rng(logger.seed)
    columns = {
        "time_s": time_s,
        "rack_m": quantise(add_noise(sampled["rack_m"], logger.rack_noise_m, rng), logger.rack_full_scale_m,
                           logger.rack_bits),
        TORQUE: quantise(add_noise(sampled[TORQUE], logger.torque_noise_Nm, rng),
                                        logger.torque_full_scale_Nm, logger.torque_bits),
    }
    metadata = {"case": case, "surface": surface, "source": "synthetic: parksteer.synthetic.assisted",
                "synthetic": True, "torque_sensor": "torsion_bar", "bits": logger.torque_bits,
                "full_scale_handwheel_torque_Nm": logger.torque_full_scale_Nm,
                # a bus states every signal's resolution: the rack's too (its replay ensemble relogs the rack)
                "bits_rack_m": logger.rack_bits, "full_scale_rack_m": logger.rack_full_scale_m,
                "sample_rate_hz": float(logger.sample_rate_hz), "noise_seed": logger.seed}
    if logger.log_current:
        columns["motor_current_A"] = quantise(add_noise(sampled["motor_current_A"], logger.current_noise_A, rng),
                                              logger.current_full_scale_A, logger.current_bits)
        metadata["bits_motor_current_A"] = logger.current_bits
        metadata["full_scale_motor_current_A"] = logger.current_full_scale_A
    return Measurement(path=None, columns=columns, metadata={k: metadata_text(v) for k, v in metadata.items()})


# The example record of an assisted car (data/measurements/example_polo_assisted.csv): the Polo file's column assist
# on the kerb-weight case, a hand of the variation benchmark, and a motor whose bearings drag more than the file says.
EXAMPLE_HAND = ("rest_after_stop", 7)
EXAMPLE_HIDDEN = {"assist_motor_friction.friction_torque": 0.03}  # N m at the motor, on top of the file's 0.02
EXAMPLE_CASE = "kerb"


def assisted_example(params: Parameters, assist: str) -> Measurement:
    """The example record of an assisted car: :data:`EXAMPLE_HAND` on the car of `params` with its assist effect
    `assist` and :data:`EXAMPLE_HIDDEN`, logged as the assisted benchmark logs (rack, torsion-bar torque, current)."""
    from .variations import variation_by_name

    name, seed = EXAMPLE_HAND
    hand, _ = variation_by_name(name).settings(seed)
    base = variation_by_name(name).logger
    logger = AssistedLogger(sample_rate_hz=base.sample_rate_hz, rack_bits=base.rack_bits,
                            rack_noise_m=base.rack_noise_m, torque_noise_Nm=0.03, current_noise_A=0.25, seed=seed)
    clean = assisted_clean(params, hand, f"+{assist},+assist_motor_friction", EXAMPLE_CASE,
                           overrides=dict(EXAMPLE_HIDDEN))
    record = assisted_record(clean, logger, EXAMPLE_CASE)
    hidden = ", ".join(f"{k} = {v:g}" for k, v in EXAMPLE_HIDDEN.items())
    record.metadata["source"] = metadata_text(f"synthetic: parksteer.synthetic.assisted.assisted_example "
                                              f"(hand {name} seed {seed}; hidden: {hidden})")
    return record


def write_assisted_example(path, vehicle_path) -> None:
    """Write the example record of the assisted car of the vehicle file `vehicle_path` (its ``[assist]``)."""
    from ..measure.io import write_measurement
    from ..model.numeric.assist import check_assist
    from ..vehicle import load_vehicle

    params = load_vehicle(vehicle_path)
    assist = check_assist(params)
    if assist is None:
        raise ValueError(f"{vehicle_path}: no [assist] section: the example is of an assisted car")
    write_measurement(path, assisted_example(params, assist), params)
