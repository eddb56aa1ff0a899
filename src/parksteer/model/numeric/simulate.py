"""Simulate the steering model: the paper's handwheel cycle, or a prescribed rack travel.

With the handwheel prescribed, the model integrates y' = (u, M^-1 f) in the generated C: one call of
``ps_integrate`` (variable-order NDF, the method of MATLAB's ode15s, with the compiled analytic Jacobian;
model/codegen/integrator.c) runs the whole cycle, restarting at each corner of the handwheel input.
With a prescribed rack (a rack motion, such as a measurement's rack smoothed by
:func:`parksteer.measure.smoothing.smooth_rack`), the handwheel torque is solved for by
:func:`parksteer.model.numeric.prescribed.solve`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import SolverError, UsageError
from ...parameters import Parameters, load_parameters
from ...tables import write_csv
from .compiled import CompiledModel, CompiledModels, load_model
from ..symbolic.components import Effect, discover_effects, resolve_effects
from .inputs import HandwheelProfile, sawtooth_profile
from .statics import static_state
from .tolerances import PRESCRIBED_RTOL, RTOL, absolute_tolerances, integrator_failure, max_steps
from .values import RunValues, parameter_vector, resolve_values
from ...names import TORQUE

if TYPE_CHECKING:
    from .prescribed import RackMotion

ROLL_NEUTRAL_KEY = "derived.roll_spring_neutral"


@dataclass
class SimulationResult:
    """Output columns (numpy arrays, SI units in the names) and a header describing the run."""

    columns: dict[str, np.ndarray]
    header: dict[str, str]
    states: np.ndarray = field(repr=False)
    parameter_vector: np.ndarray = field(repr=False)
    model: CompiledModel = field(repr=False)
    values: RunValues = field(repr=False)

    def write_csv(self, path: str | Path) -> None:
        write_csv(path, self.columns, self.header)

    @property
    def contribution_names(self) -> list[str]:
        return [k for k in self.columns if k.startswith("contrib_")]

    def outputs(self) -> dict[str, np.ndarray]:
        """The model's named outputs (``column_angle_per_rack_rad_per_m``, ...) at every sample, from the states."""
        return self.model.evaluate_outputs(self.columns["time_s"], self.states, self.parameter_vector)


@dataclass
class PreparedRun:
    """A model with its parameter vector, ready to integrate (reusable for several integrations)."""

    model: CompiledModel
    effects: list[Effect]
    values: RunValues
    p: np.ndarray
    profile: object

    def parameter_index(self, key: str) -> int:
        position = self.model.parameter_positions.get(key)
        return self.model.info["parameters"].index(key) if position is None else position  # absent: ValueError


def prepare(case: str, effects=None, overrides: dict | None = None, surface: str = "ground",
            params: Parameters | None = None, handwheel: HandwheelProfile | None = None,
            models: CompiledModels | None = None) -> PreparedRun:
    """Resolve effects and values, load (or derive) the compiled model, and balance its static state.

    `handwheel` is the prescribed handwheel angle (default: the paper's saw tooth from the input section);
    `models`, the compiled models the caller keeps loaded (:class:`parksteer.model.numeric.compiled.CompiledModels`;
    by default the model is loaded afresh).
    """
    params = params if params is not None else load_parameters()
    chosen = resolve_effects(effects)
    values = resolve_values(params, case, chosen, overrides, surface, all_effects=discover_effects())
    model = load_model(chosen, models)
    profile = handwheel if handwheel is not None else sawtooth_profile(values.params)
    p = parameter_vector(model.info["parameters"], values, profile.table(model.info["max_input_pieces"]))
    run = PreparedRun(model, chosen, values, p, profile)
    balance_roll_spring(run)
    return run


def balance_roll_spring(run: PreparedRun) -> None:
    """Choose the roll spring's neutral angle so that the zero-steer state carries the Table B1 loads.

    With the tyre springs' free lengths set from the Table B1 loads, the body is in vertical
    equilibrium at zero bounce and roll; the roll spring (standing for the rear axle's
    stiffness) takes whatever moment the tyres do not, so its neutral angle is set to
    cancel the roll residual there. The moment is linear in the neutral angle.
    """
    model, p = run.model, run.p
    roll = model.index("roll")
    i_neutral = run.parameter_index(ROLL_NEUTRAL_KEY)
    stiffness = p[run.parameter_index("vehicle.chassis_roll_stiffness")]
    p[i_neutral] = 0.0
    residual = model.forcing(0.0, np.zeros(2 * model.n_q), p)[roll]
    p[i_neutral] = -residual / stiffness


def _atol(model: CompiledModel) -> np.ndarray:
    return absolute_tolerances(model.info["coordinate_units"])


def integrate(run: PreparedRun, t_out: np.ndarray, y0: np.ndarray | None = None, rtol: float = RTOL,
              atol: np.ndarray | None = None) -> np.ndarray:
    """States at `t_out` (increasing), from `y0` or the static state: one call of the generated integrator."""
    model, p = run.model, run.p
    n_y = 2 * model.n_q
    y0 = static_state(run) if y0 is None else np.asarray(y0, dtype=float)
    t_out = np.ascontiguousarray(t_out, dtype=float)
    y0 = np.ascontiguousarray(y0, dtype=float)
    atol = np.ascontiguousarray(_atol(model) if atol is None else np.broadcast_to(atol, (n_y,)), dtype=float)
    corners = np.ascontiguousarray([piece[0] for piece in run.profile.pieces], dtype=float)
    states = np.empty((len(t_out), n_y))
    stats = np.zeros(4)
    code = model.lib.ps_integrate(p.ctypes.data, y0.ctypes.data, len(t_out), t_out.ctypes.data, len(corners),
                                  corners.ctypes.data, float(rtol), atol.ctypes.data, max_steps(t_out),
                                  states.ctypes.data, stats.ctypes.data)
    if code != 0:
        raise integrator_failure("integration", code, float(stats[3]))
    return states


def _columns(run: PreparedRun, t: np.ndarray, states: np.ndarray, outputs: dict, handwheel: np.ndarray
             ) -> dict[str, np.ndarray]:
    model = run.model
    n = model.n_q
    cols = {
        "time_s": t,
        "handwheel_angle_rad": handwheel[:, 0],
        "rack_m": states[:, model.index("rack")],
        TORQUE: outputs["column_torque_Nm"],
        "load_left_N": outputs["load_left_N"],
        "load_right_N": outputs["load_right_N"],
    }
    for effect in model.effects:
        cols[f"contrib_{effect}_Nm"] = outputs[f"contrib_{effect}_Nm"]
    cols["contrib_inertia_Nm"] = outputs["contrib_inertia_Nm"]
    cols["handwheel_rate_rad_s"] = handwheel[:, 1]
    cols["column_angle_rad"] = outputs["column_angle_rad"]
    cols["steer_left_rad"] = outputs["steer_left_rad"]
    cols["steer_right_rad"] = outputs["steer_right_rad"]
    for i, name in enumerate(model.coordinates):
        if name != "rack":
            unit = model.info["coordinate_units"][i]
            cols[f"{name}_{unit}"] = states[:, i]
    cols["rack_speed_m_s"] = states[:, n + model.index("rack")]
    extra = model.info.get("effect_outputs", [])
    if extra:
        # The force the pinion and the assist together put on the rack: every load on the rack but theirs, i.e.
        # the handwheel-torque contributions of all but the assist, through d(column angle)/d(rack).
        assists = [f"contrib_{e.name}_Nm" for e in run.effects if e.power_assist]
        road = cols[TORQUE] - sum((cols[name] for name in assists), np.zeros(len(t)))
        cols["rack_force_N"] = road * outputs["column_angle_per_rack_rad_per_m"]
        for name in extra:
            cols[name] = outputs[name]
    return cols


def _header(run: PreparedRun, drive: str) -> dict[str, str]:
    header = {
        "model": "parksteer multibody steering model (Sharp & Granger section 4)",
        "case": run.values.case,
        "surface": run.values.surface,
        "components": ", ".join(run.model.effects) or "none",
        "drive": drive,
        "model_key": run.model.directory.name,
        "derived.roll_spring_neutral": f"{run.p[run.parameter_index(ROLL_NEUTRAL_KEY)]:.10g} rad",
        "units": "SI; torques at the handwheel in N m; contributions sum to handwheel_torque_Nm",
    }
    header.update(run.values.header(run.effects))
    return header


def simulate(case: str, effects=None, overrides: dict | None = None, surface: str = "ground",
             rack_drive: RackMotion | None = None, params: Parameters | None = None,
             t_end_s: float | None = None, output_dt_s: float = 0.01, rtol: float | None = None,
             handwheel: HandwheelProfile | None = None) -> SimulationResult:
    """Simulate `case` (a Table B1 case) with the chosen effects.

    effects: None (the paper's five), an effects spec string ("-rack_friction,+hooke_joint")
    or a list of names/Effect instances. overrides: {key: value} (quantity keys, as --set). surface: "ground"
    or "air_bearing" (no tyre-to-ground friction, vertical support kept). rack_drive: a rack
    motion (:class:`parksteer.model.numeric.prescribed.RackMotion`, e.g. a
    :class:`parksteer.measure.rack_spline.RackSpline`); then the rack is prescribed from its start to
    its end (or t_end_s) and the handwheel torque is solved for. handwheel: a HandwheelProfile to
    drive instead of the paper's saw tooth (the run ends with the profile unless t_end_s is given).
    rtol: the integrator's relative tolerance (default: RTOL, or PRESCRIBED_RTOL with a rack drive;
    parksteer.model.numeric.tolerances). Returns the output columns at `output_dt_s` spacing.
    """
    if not (output_dt_s > 0):
        raise UsageError(f"output_dt_s must be positive, got {output_dt_s}")
    run = prepare(case, effects, overrides, surface, params, handwheel)
    try:
        if rack_drive is not None:
            return _simulate_rack_drive(run, rack_drive, t_end_s, output_dt_s,
                                        PRESCRIBED_RTOL if rtol is None else rtol)
        rtol = RTOL if rtol is None else rtol
        t_end = run.profile.end_time_s if t_end_s is None else float(t_end_s)
        if not (t_end > 0):
            raise UsageError(f"t_end_s must be positive, got {t_end}")
        t = np.round(np.arange(0.0, t_end + 0.5 * output_dt_s, output_dt_s), 12)
        if len(t) < 2:
            raise UsageError(f"output step {output_dt_s:g} s leaves fewer than two outputs in the run of {t_end:g} s; "
                             "give a shorter --output-dt")
        states = integrate(run, t, rtol=rtol)
    except SolverError as exc:
        raise SolverError(f"case {case} ({surface}), effects {','.join(e.name for e in run.effects)}, "
                          f"{_stated_values(overrides)}: {exc}", exc.t_failed_s) from None
    outputs = run.model.evaluate_outputs(t, states, run.p)
    samples = np.column_stack(run.profile.angle_rate(t))
    columns = _columns(run, t, states, outputs, samples)
    drive = "handwheel saw tooth (section 4)" if handwheel is None else "prescribed handwheel profile"
    return SimulationResult(columns, _header(run, drive), states, run.p, run.model, run.values)


def _stated_values(overrides: dict | None) -> str:
    """The values a caller changed, the usual cause of a stiff run ('the parameter file's values' if none)."""
    if not overrides:
        return "the parameter file's values (no --set)"
    return "values set: " + ", ".join(f"{key}={value:g}" if isinstance(value, (int, float)) else f"{key}={value}"
                                      for key, value in overrides.items())


def _simulate_rack_drive(run: PreparedRun, rack: RackMotion, t_end_s, output_dt_s: float, rtol: float
                         ) -> SimulationResult:
    t0 = float(rack.start_s)
    t_end = float(rack.end_s) if t_end_s is None else min(float(t_end_s), float(rack.end_s))
    t = np.round(np.arange(t0, t_end + 0.5 * output_dt_s, output_dt_s), 12)
    t = t[t <= rack.end_s]
    if len(t) < 2:
        raise UsageError(f"rack drive: the run from {t0:g} s to {t_end:g} s holds fewer than two outputs")
    from .prescribed import solve as solve_prescribed  # a free run never imports it

    solution = solve_prescribed(run, run.p, rack, t, rtol=rtol, outputs=True)
    columns = _columns(run, t, solution.states, solution.outputs, solution.handwheel)
    return SimulationResult(columns, _header(run, "prescribed rack"), solution.states, run.p, run.model, run.values)


def with_overrides(params: Parameters, section: str, **values) -> Parameters:
    """A copy of `params` with entries of one section replaced (a convenience for studies and tests)."""
    sections = {k: dict(v) for k, v in params.sections.items()}
    sections[section].update(values)
    return dataclasses.replace(params, sections=sections)
