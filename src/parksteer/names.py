"""The names every layer shares, defined once: the car's two sides and the surfaces a test runs on.

The symbolic model builds a coordinate per side from :data:`SIDES`, so this file is part of the model cache's key
(parksteer.model.codegen.cache), as the symbolic half's own files are.
"""

from __future__ import annotations

SIDES = ("left", "right")
# Each surface a test runs on, with the grip factor the tyre-to-ground friction is multiplied by: the floor, and
# the source's air bearings under both wheels (no friction at the contact patch).
SURFACES = {"ground": 1.0, "air_bearing": 0.0}
