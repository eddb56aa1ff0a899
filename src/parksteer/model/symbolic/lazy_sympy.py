"""sympy for the package's effects and model space, imported when first used.

Every process that loads a model imports the effects (their quantities and roles), but only a derivation builds
their expressions. ``sp`` and ``me`` stand for ``sympy`` and ``sympy.physics.mechanics``: the first attribute
read imports the module and copies its namespace in, so later reads are plain attribute lookups. A process that
replays compiled models never imports sympy.
"""

from __future__ import annotations

import importlib
from typing import Any


class LazyModule:
    """The module `name`, imported at the first attribute read."""

    def __init__(self, name: str) -> None:
        self.__dict__["_lazy_name"] = name

    def __getattr__(self, attr: str) -> Any:
        module = importlib.import_module(self.__dict__["_lazy_name"])
        self.__dict__.update(vars(module))
        return getattr(module, attr)


sp: Any = LazyModule("sympy")
me: Any = LazyModule("sympy.physics.mechanics")
