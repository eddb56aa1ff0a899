"""Effects as components: the base class, their parameters, discovery and the effects spec.

A physical mechanism of the steering model (tyre friction, rack friction, ...) is an
:class:`Effect` living in one module of its own. The registry finds effects in three
places, so that adding one never needs an edit of the core:

- every module of the package :mod:`parksteer.model.symbolic.effects` that defines ``EFFECT``;
- Python entry points in the group ``parksteer.effects`` (each loads an Effect class or
  instance);
- a module given by name or file path in an effects spec (``+my_pkg.my_effect`` or
  ``+path/to/effect.py``) or in the environment variable ``PARKSTEER_EFFECT_MODULES``
  (entries separated by ``os.pathsep``).

An effect may add generalized coordinates, replace the steer functions of the linkage
or the column-to-pinion map, make the column's spring act on a deflection of its twist, move
where vertical loads act, add bodies, and contribute loads (forces on points, torques on frames)
and potential energy; see :class:`parksteer.model.symbolic.system.ModelSpace`.
Every parameter value is a runtime input of the generated code, so changing one never
re-derives or recompiles. An effect beyond the paper should have a strength parameter
whose default means absent, so that it can be present at strength 0 and its sensitivity
taken numerically.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import os
import pkgutil
from dataclasses import dataclass
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from ...errors import UsageError

if TYPE_CHECKING:  # pragma: no cover
    from .system import ModelSpace

ENTRY_POINT_GROUP = "parksteer.effects"
MODULES_ENV = "PARKSTEER_EFFECT_MODULES"


@dataclass(frozen=True)
class EffectParameter:
    """One parameter of an effect: SI unit, bounds and where its default comes from.

    ``file_key`` names the entry of data/parameters.toml that supplies the default (the
    paper's value or the project's documented choice); ``default`` is used only when the
    file has no such entry (a parameter that exists only for the model, e.g. a strength).
    """

    name: str
    unit: str
    minimum: float
    maximum: float
    source: str
    default: float | None = None
    file_key: str | None = None

    def default_value(self, params) -> float:
        if self.file_key is not None:
            try:
                return float(params[self.file_key])
            except KeyError:
                pass
        if self.default is None:
            raise UsageError(f"parameter {self.name}: no default and no entry {self.file_key!r} in the parameter file")
        return float(self.default)

    def check(self, owner: str, value: float) -> float:
        value = float(value)
        if not (self.minimum <= value <= self.maximum):
            raise UsageError(
                f"{owner}.{self.name} = {value:g} {self.unit} is out of bounds [{self.minimum:g}, {self.maximum:g}]"
            )
        return value


class Effect:
    """A physical mechanism of the model. Subclasses set the class attributes and override hooks."""

    name: ClassVar[str] = ""
    description: ClassVar[str] = ""
    parameters: ClassVar[tuple[EffectParameter, ...]] = ()
    in_default_set: ClassVar[bool] = True  # the paper's five are; candidate mechanisms are not

    def configure(self, model: ModelSpace) -> None:
        """Before the kinematics are built: add coordinates, replace steer/column maps, move load points."""

    def bodies(self, model: ModelSpace) -> list[Any]:
        """After the kinematics are built: extra rigid bodies or particles, e.g. on coordinates this effect added."""
        return []

    def loads(self, model: ModelSpace) -> list[tuple[Any, Any]]:
        """(Point, force Vector) and (ReferenceFrame, torque Vector) pairs acting on the core system."""
        return []

    def potential_energy(self, model: ModelSpace):
        """Potential energy (J) of the conservative part of this effect's loads (for the energy balance)."""
        return 0

    def parameter(self, name: str) -> EffectParameter:
        for spec in self.parameters:
            if spec.name == name:
                return spec
        known = ", ".join(s.name for s in self.parameters) or "none"
        raise UsageError(f"effect {self.name} has no parameter {name!r} (known: {known})")

    def describe(self, params) -> dict:
        """Name, description and parameters with their defaults (for ``parksteer effects --json``)."""
        return {
            "name": self.name,
            "description": self.description,
            "in_default_set": self.in_default_set,
            "parameters": [
                {
                    "name": s.name,
                    "unit": s.unit,
                    "default": s.default_value(params),
                    "min": s.minimum,
                    "max": s.maximum,
                    "source": s.source,
                }
                for s in self.parameters
            ],
        }


def _effect_of(obj: Any, where: str) -> Effect:
    if inspect.isclass(obj) and issubclass(obj, Effect):
        obj = obj()
    if not isinstance(obj, Effect) or not obj.name:
        raise UsageError(f"{where}: does not define an Effect with a name")
    return obj


def _effect_of_module(module: Any, where: str) -> Effect:
    if not hasattr(module, "EFFECT"):
        raise UsageError(f"{where}: module defines no EFFECT")
    return _effect_of(module.EFFECT, where)


def load_effect_module(ref: str) -> Effect:
    """The EFFECT of a module given by dotted name or by path to a .py file."""
    if ref.endswith(".py") or os.sep in ref or "/" in ref:
        path = Path(ref)
        if not path.is_file():
            raise UsageError(f"effect module {ref}: no such file")
        mod_name = f"parksteer_effect_{path.stem}"
        spec = importlib.util.spec_from_file_location(mod_name, path)
        module = importlib.util.module_from_spec(spec)
        try:
            spec.loader.exec_module(module)
        except Exception as exc:  # a user's file: report, do not crash with a traceback
            raise UsageError(f"effect module {ref}: cannot load ({type(exc).__name__}: {exc})") from None
        return _effect_of_module(module, ref)
    try:
        module = importlib.import_module(ref)
    except ImportError as exc:
        raise UsageError(f"effect module {ref}: cannot import ({exc})") from None
    return _effect_of_module(module, ref)


def discover_effects() -> dict[str, Effect]:
    """Every effect the registry can find: the package's modules, entry points and configured modules."""
    from . import effects as package

    found: dict[str, Effect] = {}
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda i: i.name):
        module = importlib.import_module(f"{package.__name__}.{info.name}")
        if hasattr(module, "EFFECT"):
            effect = _effect_of_module(module, module.__name__)
            found[effect.name] = effect
    for ep in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
        effect = _effect_of(ep.load(), f"entry point {ep.name}")
        found.setdefault(effect.name, effect)
    for ref in filter(None, os.environ.get(MODULES_ENV, "").split(os.pathsep)):
        effect = load_effect_module(ref)
        found[effect.name] = effect
    return found


def default_effect_names(registry: dict[str, Effect] | None = None) -> list[str]:
    registry = registry if registry is not None else discover_effects()
    return [name for name, e in registry.items() if e.in_default_set]


def resolve_effects(spec: str | list | tuple | None = None) -> list[Effect]:
    """The effects chosen by `spec`, in a canonical order (sorted by name).

    `spec` is None (the default set), a string such as ``"-rack_friction,+hooke_joint"``
    (each ``+name``/``-name`` edits the default set; a bare list ``"a,b"`` without signs
    names the set exactly; ``none`` is the empty set), or a list of names or Effect instances.
    """
    registry = discover_effects()
    if isinstance(spec, (list, tuple)):
        chosen: dict[str, Effect] = {}
        for item in spec:
            effect = item if isinstance(item, Effect) else _lookup(registry, str(item))
            chosen[effect.name] = effect
        return [chosen[n] for n in sorted(chosen)]
    text = (spec or "").strip()
    items = [s.strip() for s in text.split(",") if s.strip()]
    if items == ["none"]:
        return []
    signed = [s for s in items if s[0] in "+-"]
    if signed and len(signed) != len(items):
        raise UsageError(f"effects spec {text!r}: mix of signed (+/-) and bare names")
    if items and not signed:
        chosen = {name: _lookup(registry, name) for name in items}
    else:
        chosen = {name: registry[name] for name in default_effect_names(registry)}
        for item in signed:
            sign, name = item[0], item[1:].strip()
            effect = _lookup(registry, name)
            if sign == "+":
                chosen[effect.name] = effect
            else:
                chosen.pop(effect.name, None)
    return [chosen[n] for n in sorted(chosen)]


def _lookup(registry: dict[str, Effect], name: str) -> Effect:
    if name in registry:
        return registry[name]
    if "." in name or "/" in name:
        effect = load_effect_module(name)
        registry[effect.name] = effect
        return effect
    raise UsageError(f"unknown effect {name!r} (known: {', '.join(sorted(registry))})")
