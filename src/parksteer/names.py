"""The names every layer shares, defined once: the car's two sides, the surfaces a test runs on, and the column of
the torque at the handwheel (a simulation's output, a record's measured torque).

The symbolic model builds a coordinate per side from :data:`SIDES`, so this file is part of the model cache's key
(parksteer.model.codegen.cache), as the symbolic half's own files are.
"""

from __future__ import annotations

SIDES = ("left", "right")
# Each surface a test runs on, with the grip factor the tyre-to-ground friction is multiplied by: the floor, and
# the source's air bearings under both wheels (no friction at the contact patch).
SURFACES = {"ground": 1.0, "air_bearing": 0.0}
# The handwheel torque's column, N m: a run's output and a record's measured torque (a torsion bar's on an
# assisted car).
TORQUE = "handwheel_torque_Nm"
