"""The physical mechanisms of the steering model, one module each (see parksteer.model.symbolic.components).

Each module defines ``EFFECT``, an instance of an :class:`~parksteer.model.symbolic.components.Effect`
subclass; the registry finds every module of this package, so a new mechanism is one new file.
"""
