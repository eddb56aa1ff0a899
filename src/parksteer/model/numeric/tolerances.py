"""Integrator tolerances of the model: the handwheel-driven integration and the prescribed-rack solve.

Numeric settings of the solvers, not properties of the car; each with its reason.
"""

from __future__ import annotations

import numpy as np

# Handwheel-driven integration (parksteer.model.numeric.simulate.integrate): relative, and absolute per unit of
# each coordinate (m or rad) and its rate. The column damping turns rack-speed error into handwheel torque at
# c * G^2 (about 37,000 N m per m/s), so the speeds need tight absolute tolerances: with these the nominal
# cycle's torque is within 0.0004 N m of a run at rtol 1e-11 and a ten-thousandth of these atol.
RTOL = 1e-7
ATOL_Q = {"m": 1e-10, "rad": 1e-9}
ATOL_U = {"m": 1e-8, "rad": 1e-7}

# Prescribed-rack solve (parksteer.model.numeric.prescribed, the generated integrator on the reduced system):
# relative, and a multiple of the absolute tolerances above. With the rack prescribed, no rack-speed error reaches
# the column damping, so looser tolerances suffice: on data/measurements/example_unladen.csv the torque is within
# 0.0005 N m (RMS 0.00014 N m) of a solve at rtol 1e-10 and a hundredth of ATOL_Q/ATOL_U, a quarter of a per cent
# of an 8-bit converter step (0.2 N m); the solve takes 4.0 ms, against 6.7 ms at RTOL and ATOL_Q/ATOL_U. On the
# exact rack of a free run (tests/model/test_rack_drive.py) the largest error is 0.003 N m, where a solve at rtol
# 1e-8 gives the free run's torque back to 2e-5 N m.
PRESCRIBED_RTOL = 1e-5  # 1
PRESCRIBED_ATOL_FACTOR = 100.0  # 1


# Work budget of both integrations: at most this many steps per simulated second between two output times
# (ps_integrate's and ps_integrate_prescribed's max_steps, scaled by the output spacing, never below
# MIN_STEPS_PER_OUTPUT).
# The budget is about twice the busiest case the model is for: the paper's cycles take about 100 steps per second,
# a tyre a hundred times stiffer radially than any car tyre (1e10 N/m) thousands, and the pre-sliding rack
# friction with its bristle root's mode undamped (rack_presliding.damping_ratio = 0) about 100,000, up to 234,000
# in its busiest 10 ms. Values that need more are far outside what the model is for, and fail in one line within
# seconds (a 1e16 N/m tyre) instead of running for minutes.
STEP_BUDGET_PER_S = 500_000
MIN_STEPS_PER_OUTPUT = 2_000


def max_steps(t_out) -> int:
    """The step limit between two outputs for the output times `t_out`: the work budget over the longest output
    interval."""
    t_out = np.asarray(t_out, dtype=float)
    longest = float(np.max(np.diff(t_out))) if len(t_out) > 1 else 0.0
    return max(MIN_STEPS_PER_OUTPUT, int(np.ceil(STEP_BUDGET_PER_S * longest)))


def absolute_tolerances(units: list[str], factor: float = 1.0) -> np.ndarray:
    """Absolute tolerances of the states (coordinates, then their rates) for coordinates of `units` (m or rad)."""
    return factor * np.array([ATOL_Q[u] for u in units] + [ATOL_U[u] for u in units])


def solver_failure(what: str, info: dict, t_out: np.ndarray) -> "SolverError":
    """The one-line error of an odeint call that gave up: its message and the last time it reached.

    odeint's ``tcur`` holds the time reached at each output up to the failure and undefined values after it;
    an entry counts while it is finite, not before its output time, not decreasing, and within the run.
    """
    from ...errors import SolverError

    t_out = np.asarray(t_out, dtype=float)
    span = float(t_out[-1] - t_out[0])
    t_failed = float(t_out[0])
    for t_req, reached in zip(t_out, np.asarray(info.get("tcur", []), dtype=float)):
        if not (np.isfinite(reached) and t_req <= reached <= t_out[-1] + span and reached >= t_failed):
            break
        t_failed = float(reached)
    # odeint's words, without its guess at the cause ("Excess work done on this call (perhaps wrong Dfun type).")
    message = str(info.get("message", "unknown failure")).split(" on this call")[0].rstrip(".").replace("\n", " ")
    if message.startswith("Excess work done"):
        message = BUDGET_MESSAGE
    return SolverError(f"{what} failed at t = {t_failed:.4g} s: {message}", t_failed)


BUDGET_MESSAGE = (f"more than {STEP_BUDGET_PER_S:,} integration steps per simulated second (the work budget, "
                  "parksteer.model.numeric.tolerances): the values make the model too stiff to integrate")
# The return codes of the generated integrator (ps_integrate, model/codegen/integrator.c), in words.
INTEGRATOR_FAILURES = {
    1: BUDGET_MESSAGE,
    2: "the step size fell below 1e-14 of the time: the solution is not smooth enough to follow (a singularity "
       "or a discontinuity the model does not declare)",
    3: "the right-hand side could not be evaluated (mass matrix not positive definite, or a value not finite) "
       "even after ten halvings of the step",
}


def integrator_failure(what: str, code: int, t_reached: float) -> "SolverError":
    """The one-line error of a ps_integrate call that returned `code`, having reached `t_reached`."""
    from ...errors import SolverError

    message = INTEGRATOR_FAILURES.get(code, f"unknown failure (code {code})")
    return SolverError(f"{what} failed at t = {t_reached:.4g} s: {message}", t_reached)
