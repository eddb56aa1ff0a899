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
# solve takes a little over half the time it takes at RTOL and ATOL_Q/ATOL_U.
PRESCRIBED_RTOL = 1e-5  # 1
PRESCRIBED_ATOL_FACTOR = 100.0  # 1


def absolute_tolerances(units: list[str], factor: float = 1.0) -> np.ndarray:
    """Absolute tolerances of the states (coordinates, then their rates) for coordinates of `units` (m or rad)."""
    return factor * np.array([ATOL_Q[u] for u in units] + [ATOL_U[u] for u in units])


def solver_failure(what: str, info: dict, t_start_s: float) -> "SolverError":
    """The one-line error of an odeint call that gave up: its message and the last time it reached."""
    from ...errors import SolverError

    reached = np.asarray(info.get("tcur", []), dtype=float)
    reached = reached[np.isfinite(reached)]
    t_failed = max(float(reached.max()), t_start_s) if reached.size else t_start_s
    message = str(info.get("message", "unknown failure")).rstrip(".").replace("\n", " ")
    hint = " (the output step is longer than the run?)" if "Nothing was done" in message else ""
    return SolverError(f"{what} failed at t = {t_failed:.4g} s: {message}{hint}", t_failed)
