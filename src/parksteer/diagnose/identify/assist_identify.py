"""An electric assist's boost table and its gear's hidden numbers identified from the car's own records.

:func:`identify_boost` (``parksteer assist identify``) takes one or more records of an assisted car (the torsion-bar
torque S as the car's bus logs it, the motor current i, the rack or the handwheel angle) and the car's vehicle file
(its gear's data: reduction N, efficiencies, torque constant, rotor inertia, motor limit) and gives an
:class:`Identified`, which writes the vehicle file again with what the records fix (:meth:`Identified.to_vehicle_toml`).

Two least-squares steps, each with 95 % intervals that keep the residuals' correlation in time (a sandwich over
blocks of :data:`BLOCK_S`): the map i = K(S - c), a :mod:`parksteer.boost_table` law in ampere on the origin, the
dead band and :data:`SPAN_POINTS` points, with its scatter and hysteresis reported; then the gear, the column
balance of :mod:`parksteer.model.numeric.assisted` replayed on the record's rack, which fixes the product
k_t eta_f N (N m/A), the sensor's zero offset (N m), the :data:`MECHANICS` parameters and, where enough samples
are back-driven (:data:`BACK_DRIVEN_SHARE`), the back-driven efficiency. The assist's ``friction_speed`` stays the
file's. A gear number is written only where it is physical and its interval excludes the file's value, and a value
the file gives from a data sheet always stays (:attr:`Identified.kept`); each written entry's ``source`` names the
records. The method, its intervals and its accuracy on known cars: docs/assist_identify.md.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ... import portable as pm
from ...errors import UsageError
from ...model.symbolic.effects.assist_common import directional_efficiency
from ...parameters import Parameters
from .boost_map import BLOCK_S, Z95, _blocks, _estimate, _sandwich, _t95, fit_map
from .identified_file import Identified
from ..problem import FileData
from ..stages.assumed import is_assumed

# The mechanics' calibrated parameters (key, finite-difference step) beside the offset and the product: the column
# torque is linear in the two frictions and the rotor's inertia, so one linear least-squares step is exact.
MECHANICS = (
    ("motor_friction_torque", 0.01),  # of the assist's section
    ("motor_inertia", 1.0e-4),  # of the assist's section: its torque N^2 J theta'' is linear in J
    ("steering.rack_friction_force", 50.0),
)
# The back-driven efficiency is fitted when at least this share of the samples read while the gear moves is
# back-driven (the rack returning the motor after a reversal); else the file's stays.
BACK_DRIVEN_SHARE = 0.03
# Not calibrated: the tyre-ground friction scales the road torque as the product scales the assist (the column
# balance cannot tell them apart: S is the small difference of the two), so the product is identified at the file's
# value, and its dependence on it reported (the product's change for this change of the friction).
TYRE_FRICTION = ("tyre.friction_coefficient", 0.05)
# The column balance is read where the gear moves: the friction's smooth sign tanh(beta v) at least this.
MOVING_SIGN = 0.95
# A residual shape counts as beyond the noise at this many of its standard errors.
BEYOND_SE = 4.0


def _files(records, params, case, surface, channel_map, name) -> list[FileData]:
    """The records ready to replay, in their order: paths read as ``parksteer diagnose`` reads them, and records
    already in memory (:class:`parksteer.measure.io.Measurement`, e.g. a benchmark's) prepared the same way (an
    angle-only one's rack derived through the column and the torsion bar)."""
    from ...measure.column import with_derived_rack
    from ...measure.io import Measurement
    from ..problem import load_files, prepare_file, torsion_bar

    out = []
    for k, record in enumerate(records):
        if isinstance(record, Measurement):
            record, resolution = with_derived_rack(record, params, torsion_bar(name))
            label = record.path.name if record.path is not None else f"record {k + 1}"
            out.append(prepare_file(record, case or record.case, label=label, rest_resolution_m=resolution))
        else:
            out += load_files([str(record)], params, case, surface, channel_map, name)
    return out


def _assist_name(effects) -> str:
    from ...model.symbolic.components import power_assist_of

    effect = power_assist_of(effects)
    if effect is None or effect.power_assist != "electric":
        raise UsageError("assist identify: the vehicle file's [assist] must be an electric one (type column, pinion "
                         "or rack): a hydraulic gear has no motor current to read its map from")
    return effect.name


def identify_boost(records, vehicle, case: str | None = None, surface: str | None = None, channel_map=None,
                   quiet: bool = True) -> Identified:
    """The boost table and the gear's hidden numbers of an electric assist from its records (module docstring).

    `records`: paths of measurement files (any format :func:`parksteer.measure.importers.load_record` reads, with
    `channel_map` for a logger's or a bus's) or records in memory (:class:`parksteer.measure.io.Measurement`), each
    with the torsion-bar torque (``torque_sensor: torsion_bar``),
    the motor current ``motor_current_A`` and a rack or a handwheel angle. `vehicle`: the vehicle file's path, or
    its loaded :class:`~parksteer.parameters.Parameters` (its ``[assist]`` gives the gear; its boost curve, table or
    line, is not used). `case`, `surface`: as for
    ``parksteer diagnose``. Returns an :class:`Identified`; :meth:`Identified.to_vehicle_toml` writes the file."""
    from ...model.numeric.assist import check_assist, effects_with_assist
    from ...model.numeric.assisted import boost_keys, rack_speed_mps
    from ...model.symbolic.components import discover_effects, resolve_effects
    from ...vehicle import load_vehicle
    from ..engine import ReplayEngine
    from ..problem import Problem

    discover_effects()  # a vehicle file's [assist] entries are the assist effect's quantities
    if isinstance(vehicle, Parameters):
        params, vehicle_path = vehicle, Path(vehicle.path)
    else:
        vehicle_path = Path(vehicle)
        params = load_vehicle(vehicle_path)
    if check_assist(params) is None:
        raise UsageError(f"{vehicle_path}: no [assist] section: identify needs the gear's data (type, reduction, "
                         "efficiency, torque constant)")
    effects = resolve_effects(effects_with_assist(None, params))
    name = _assist_name(effects)
    files = _files(records, params, case, surface, channel_map, name)
    for f in files:
        if f.motor_column != "motor_current_A":
            raise UsageError(f"{f.measurement.path or f.label}: column 'motor_current_A': missing; identify reads the "
                             "map from the motor current beside the torsion-bar torque")
        if f.measurement.torque_sensor != "torsion_bar":
            raise UsageError(f"{f.measurement.path or f.label}: column 'handwheel_torque_Nm': a handwheel torque; "
                             "identify needs the torsion-bar torque of an assisted car (torque_sensor: torsion_bar)")
    say = (lambda text: None) if quiet else (lambda text: print(text, flush=True))
    say("identify: the map of current against torsion-bar torque")
    fitted = fit_map(files)
    law = fitted.law()

    v = lambda key: float(params[f"{name}.{key}"])  # noqa: E731
    location = name.rsplit("_", 1)[1]
    ratio = float(params["steering.handwheel_to_rack_ratio"])
    eta, eta_b, reduction, k_t = v("efficiency"), v("back_efficiency"), v("reduction_ratio"), v("torque_constant")
    product_file = k_t * eta * reduction  # per A, at the point of action
    scale = ratio if location == "rack" else 1.0  # a rack force in torsion-bar torque units: / G_hr

    # Step 2: the column balance on the manual car's replay (boost off).
    problem = Problem(files, params)
    engine = ReplayEngine(1)
    boost_off = {key: 0.0 for key in boost_keys(name)}
    keys = [f"{name}.{k}" if "." not in k else k for k, _ in MECHANICS]
    theta = np.array([float(params[k]) for k in keys])
    # the rotor's speed: N times the point of action's rate (at the column the joint's ratio taken as G_hr: a few
    # per cent of a band's width)
    lever = 1.0 if location == "rack" else ratio
    rack_speeds = [rack_speed_mps(f.rack, f.time_s) for f in files]
    rotor = [speed * reduction * lever for speed in rack_speeds]
    motors = [law(f.torque_Nm - fitted.centre) * k_t for f in files]
    S_all = np.concatenate([f.torque_Nm for f in files])
    t_all = np.concatenate([f.time_s + 1e6 * k for k, f in enumerate(files)])
    sigma = np.concatenate([np.full(f.n, f.noise.total_rms) for f in files])
    back = np.concatenate([m * w < 0.0 for m, w in zip(motors, rotor)])

    # where the motion is defined: the smoothed rack's speed beyond the car-wide friction smoothing's band (its sign
    # sure; nearer a reversal the spline's timing of it is not), whatever band the gear's friction has
    sharpness = float(params["steering.friction_smoothing"])
    use = np.concatenate([np.abs(pm.tanh(sharpness * speed)) >= MOVING_SIGN for speed in rack_speeds])
    split = (use & back).sum() >= BACK_DRIVEN_SHARE * use.sum()
    if use.sum() < 20 * (len(MECHANICS) + 2):
        raise UsageError(f"{', '.join(str(r) for r in records)}: the steering hardly moves: identify needs "
                         "records in which the wheel turns (the column balance is read while the gear moves)")

    def road(changes: dict[str, float]):
        overrides = {**boost_off, **dict(zip(keys, theta)), **changes}
        return np.concatenate([engine.replay(problem, effects, k).solve(overrides).torque_Nm[: f.n]
                               for k, f in enumerate(files)])

    say("identify: the column balance on the car's replay")
    try:
        y0 = road({})
        columns = [(road({key: value + step}) - y0) / step for key, value, (_, step) in zip(keys, theta, MECHANICS)]
        tyre_key, tyre_step = TYRE_FRICTION
        tyre_column = (road({tyre_key: float(params[tyre_key]) + tyre_step}) - y0) / tyre_step
    finally:
        engine.close()
    # what the file's gear delivers for the identified current, its direction changing over the file's band of
    # rotor speed
    D = np.concatenate([directional_efficiency(m, w, eta, eta_b, v("limit_smoothing"), 1.0 / v("friction_speed"))
                        * reduction * m / scale for m, w in zip(motors, rotor)])
    # y0 + J dtheta + o - S - p D = 0  ->  [J, 1, -D] [dtheta, o, p] = S - y0, with D split into the samples the
    # motor drives and those it is driven back (their factor p_b = p eta_b,file / eta_b)
    # only while the gear moves: at rest its friction and the direction of its power are not defined
    parts = [-D * ~back, -D * back] if split else [-D]
    design = (np.column_stack([*columns, np.ones_like(S_all), *parts]) / sigma[:, None])[use]
    solution = pm.lstsq(design, ((S_all - y0) / sigma)[use])
    resid = ((S_all - y0) / sigma)[use] - pm.matmul(design, solution)
    cov = _sandwich(design, resid, _blocks(t_all[use], BLOCK_S))
    # the product at the tyre friction moved by its step: the same fit on y0 + step x its column
    moved = pm.lstsq(design, ((S_all - y0 - tyre_step * tyre_column) / sigma)[use])
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    values = theta + solution[: len(keys)]
    offset, p = float(solution[len(keys)]), float(solution[len(keys) + 1])
    se_o, se_p = float(se[len(keys)]), float(se[len(keys) + 1])
    product_per_tyre = (float(moved[len(keys) + 1]) - p) * product_file / tyre_step
    back_efficiency = None
    if split:  # eta_b = eta_b,file p / p_b, its standard error by the delta method
        j = len(keys) + 2
        p_b = float(solution[j])
        ratio = p / p_b
        gradient = np.array([1.0 / p_b, -p / p_b ** 2])
        block = cov[np.ix_([len(keys) + 1, j], [len(keys) + 1, j])]
        back_se = eta_b * math.sqrt(max(pm.dot(gradient, pm.matmul(block, gradient)), 0.0))
    z = _t95(len(np.unique(_blocks(t_all[use], BLOCK_S))) - design.shape[1])
    if split:
        back_efficiency = _estimate(eta_b * ratio, back_se, "1", z)
    balance_rms = float(np.sqrt(np.mean((resid * sigma[use]) ** 2)))
    balance_floors = float(np.sqrt(np.mean(resid ** 2)))
    torque_noise = float(np.sqrt(np.mean(sigma ** 2)))

    # the table at the point of action: P K, its interval from the map's and the product's
    # What the written file takes from the balance: each number the file's value unless the number's 95 % interval
    # excludes it, and the file's kept where the estimate is no physical value (a friction or an inertia below zero:
    # the balance's misfit, not the gear's). A value the file gives from a data sheet (its source not assumed) is
    # a measurement of the part and stands: the balance reads the gear through the replayed road load (the product
    # moves with the tyre-ground friction) and through the rack's timing at the reversals (the back-driven samples),
    # and neither is known as well as a data sheet (module docstring).
    # (value, interval's low, high, the file's value) by key:
    judged = {
        "torque_constant": (p * product_file, (p - z * se_p) * product_file, (p + z * se_p) * product_file,
                            product_file),
        "motor_friction_torque": (values[0], values[0] - z * se[0], values[0] + z * se[0], v("motor_friction_torque")),
        "motor_inertia": (values[1], values[1] - z * se[1], values[1] + z * se[1], v("motor_inertia")),
    }
    if back_efficiency is not None:
        judged["back_efficiency"] = (back_efficiency.value, *back_efficiency.ci95, eta_b)

    kept = [key for key, (value, lo, hi, file_value) in judged.items()
            if not is_assumed(params, f"{name}.{key}") or value < 0.0
            or lo <= file_value <= hi]
    # the product the table is written with: the balance's, or the file's where it is kept
    P = product_file if "torque_constant" in kept else p * product_file
    point_cov = pm.matmul(pm.matmul(fitted.jacobian_values, fitted.covariance), fitted.jacobian_values.T) \
        + np.diag(fitted.representation ** 2)
    current = np.array(fitted.current)
    assist = P * current
    # the product is read through the map: the map's own error at its points (not averaged by more samples) is a
    # relative error of the product, weighted as the balance weighs the assist (by its size)
    map_relative = float(np.sqrt(np.sum(fitted.representation ** 2) / np.sum(current ** 2)))
    se_p = math.hypot(se_p, p * map_relative)
    rel_p = se_p / p if p > 0 else math.inf
    se_assist = np.sqrt((P ** 2) * np.maximum(np.diag(point_cov), 0.0) + (assist * rel_p) ** 2)
    step_i = max(f.measurement.quantisation_step(f.motor_column) for f in files)
    beyond = []
    if abs(fitted.hysteresis) > BEYOND_SE * fitted.hysteresis_se and abs(fitted.hysteresis) > 0.5 * step_i:
        beyond.append(f"hysteresis: the current on loading is {fitted.hysteresis:+.3f} A from that on unloading at "
                      f"equal torsion-bar torque (+-{Z95 * fitted.hysteresis_se:.3f} A; {fitted.hysteresis_Nm:.4f} N m "
                      "of torque), a current that depends on the way the steering turns (outward or back)")
    if fitted.rms > 1.5 * fitted.noise and fitted.rms - fitted.noise > 0.5 * step_i:
        beyond.append(f"scatter: the current departs from the map by {fitted.rms:.3f} A RMS against {fitted.noise:.3f} "
                      "A of the channels' noise")
    names = [f.label for f in files]
    mech = {k: _estimate(val, s, u, z) for (k, _), val, s, u in zip(MECHANICS, values, se[: len(keys)],
                                                                   ("N m", "kg m^2", "N"))}
    return Identified(
        vehicle=str(vehicle_path), records=tuple(names), assist_name=name,
        torques=tuple(float(t) for t in fitted.torques), assist=tuple(float(a) for a in assist),
        assist_ci95=tuple((float(a - Z95 * s), float(a + Z95 * s)) for a, s in zip(assist, se_assist)),
        current_A=tuple(float(c) for c in current),
        current_ci95=tuple((float(c - Z95 * s), float(c + Z95 * s)) for c, s in
                           zip(current, np.sqrt(np.maximum(np.diag(point_cov), 0.0)))),
        # the log and the control unit read the torque in steps: the map between two of them is never seen
        dead_band=_estimate(fitted.torques[1], math.hypot(math.sqrt(max(fitted.covariance[0, 0], 0.0)),
                                                          fitted.torque_step / math.sqrt(12.0),
                                                          fitted.dead_band_representation), "N m"),
        map_centre=_estimate(fitted.centre, math.hypot(math.sqrt(max(fitted.covariance[1, 1], 0.0)),
                                                       fitted.torque_step / math.sqrt(12.0)), "N m"),
        product=_estimate(P, se_p * product_file, "N/A" if location == "rack" else "N m/A", z),
        motor_friction=mech["motor_friction_torque"], motor_inertia=mech["motor_inertia"],
        back_efficiency=back_efficiency, offset=_estimate(offset, se_o, "N m", z),
        rack_friction=mech["steering.rack_friction_force"], tyre_friction=float(params[TYRE_FRICTION[0]]),
        product_per_tyre_friction=product_per_tyre,
        map_rms_A=fitted.rms, map_noise_A=fitted.noise,
        hysteresis_A=_estimate(fitted.hysteresis, fitted.hysteresis_se, "A"), hysteresis_Nm=float(fitted.hysteresis_Nm),
        balance_rms_Nm=balance_rms, torque_noise_Nm=torque_noise, beyond_map=tuple(beyond),
        balance_floors=balance_floors, kept=tuple(kept),
        balance_product=p * product_file,
        gain_uncertainty=Z95 / math.sqrt(float(np.sum((assist[assist > 0] / se_assist[assist > 0]) ** 2))),
        file_values={"product": product_file, "motor_friction_torque": v("motor_friction_torque"),
                     "motor_inertia": v("motor_inertia"), "back_efficiency": eta_b,
                     "efficiency": eta, "reduction_ratio": reduction, "torque_constant": k_t},
    )

