"""The symbolic half of the model: bodies, effects and Kane's equations (sympy.physics.mechanics)."""
