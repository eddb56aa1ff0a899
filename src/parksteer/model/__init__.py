"""The multibody steering model of the paper's section 4 (front end of the car, Kane's method).

- :mod:`.system`: the core bodies, coordinates and loads, built with sympy.physics.mechanics;
- :mod:`.components` and :mod:`.effects`: each physical mechanism as a component in one file;
- :mod:`.derive`, :mod:`.codegen`, :mod:`.compiled`: Kane's equations, C code with an analytic
  Jacobian, compilation and the on-disk cache;
- :mod:`.values`, :mod:`.inputs`, :mod:`.simulate`: parameter vectors, drives and simulation.

Use :func:`parksteer.model.numeric.simulate.simulate`, or the ``parksteer simulate`` command.
"""
