"""Integrator tolerances of the model: the handwheel-driven integration and the prescribed-rack solve.

Numeric settings of the solvers, not properties of the car; each with its reason.
"""

from __future__ import annotations

import numpy as np

# Handwheel-driven integration (parksteer.model.numeric.simulate.integrate): relative, and absolute per unit of
# each coordinate (m or rad) and its rate. The column damping turns rack-speed error into handwheel torque at
# c * G^2 (about 37,000 N m per m/s), so the speeds need tight absolute tolerances: with these the nominal
# cycle's torque is within 0.002 N m of a run at rtol 1e-11, atol 1e-13.
RTOL = 1e-7
ATOL_Q = {"m": 1e-10, "rad": 1e-9}
ATOL_U = {"m": 1e-8, "rad": 1e-7}

# Prescribed-rack solve (parksteer.model.numeric.prescribed): relative, and a multiple of the absolute
# tolerances above. With the rack prescribed, no rack-speed error reaches the column damping, so looser
# tolerances suffice: on data/measurements/example_unladen.csv the torque is within 0.004 N m (RMS 0.0007 N m)
# of a solve at rtol 1e-10 and a hundredth of ATOL_Q/ATOL_U, 2 % of an 8-bit converter step (0.2 N m); the
# solve takes a little over half the time it takes at RTOL and ATOL_Q/ATOL_U. The error is not uniform: on the exact
# rack of a free run (tests/model/test_rack_drive.py) a burst of 0.14 s reaches 0.09 N m, half an 8-bit step, while
# a solve at rtol 1e-8 gives the free run's torque back to 4e-6 N m.
PRESCRIBED_RTOL = 1e-5  # 1
PRESCRIBED_ATOL_FACTOR = 100.0  # 1


# Work budget of both integrations: at most this many steps per simulated second between two output times
# (odeint's mxstep, scaled by the output spacing, never below MIN_STEPS_PER_OUTPUT). The paper's cycles take
# about 170 steps per second (3,000 over 18 s; at most 47 between 10 ms outputs), a tyre a hundred times stiffer
# radially than any car tyre (1e10 N/m) about 7,000, and the stiffest effect of the library, the pre-sliding rack
# friction with its 0.1 ms bristle, about 100,000 (234,000 in its busiest 10 ms, at 1,560 N). Values that need
# more than twice that are far outside what the model is for: without the budget a 1e14 N/m tyre ran for
# minutes; with it the run fails in one line within two seconds.
STEP_BUDGET_PER_S = 500_000
MIN_STEPS_PER_OUTPUT = 2_000


def max_steps(t_out) -> int:
    """odeint's mxstep for the output times `t_out`: the work budget over the longest output interval."""
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
        message = (f"more than {STEP_BUDGET_PER_S:,} integration steps per simulated second (the work budget, "
                   "parksteer.model.numeric.tolerances): the values make the model too stiff to integrate")
    return SolverError(f"{what} failed at t = {t_failed:.4g} s: {message}", t_failed)
