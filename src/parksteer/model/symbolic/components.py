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

An effect may add generalized coordinates, fill one slot of the core (the linkage's steer
function, the column-to-pinion map, the column spring's deflection law, the tread ring's twist,
where vertical loads act; :data:`parksteer.model.symbolic.system.SLOTS`), add bodies, and
contribute loads (forces on points, torques on frames) and potential energy; see
:class:`parksteer.model.symbolic.system.ModelSpace`. It names the effects it requires; a set
in which two effects fill one slot, or one lacks an effect it requires, is refused.
Every quantity's value is a runtime input of the generated code, so changing one never
re-derives or recompiles. An effect beyond the paper should have a strength quantity
whose default means absent, so that it can be present at strength 0 and its sensitivity
taken numerically.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import inspect
import os
import pkgutil
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from importlib.metadata import entry_points
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

from ...errors import UsageError
from ...parameters import (DEFAULT_PATH, FILE_AND_CASE_KEYS, RUN_QUANTITIES, DeclaredQuantities, Parameters, Quantity,
                           declared_with, load_parameters, quantity, registry, unknown_key_message)

from .system import SLOTS

if TYPE_CHECKING:  # pragma: no cover
    from .system import ModelSpace

ENTRY_POINT_GROUP = "parksteer.effects"
MODULES_ENV = "PARKSTEER_EFFECT_MODULES"

@dataclass(frozen=True)
class Rival:
    """What makes an effect a rival of the paper's mechanisms, studied on its own and never a diagnosis candidate.

    ``closest`` is the diagnosis candidate physically closest to it (None when none is), ``related`` the other
    candidates that share its physics, ``why`` the physics they share. A diagnosis of records with the rival hidden
    that names the closest or a related candidate, or says ``unexplained``, has answered honestly; one that names
    any other candidate beyond the indistinguishable band has given a confident wrong answer (the out-of-class
    benchmark). ``probe_strength`` is the first strength of the rivals figure's secant search (in the unit of the
    effect's strength quantity, inside the range its source gives); the matched strength does not depend on it.
    """

    closest: str | None
    related: tuple[str, ...]
    why: str
    probe_strength: float


class Effect:
    """A physical mechanism of the model. Subclasses set the class attributes and override hooks.

    ``uses`` lists every quantity key the effect reads (``tyre.tyre_pressure``, ``rack_lash.lash``). The car's
    quantities (``tyre.*``, ``steering.*``, ...) are in the parameter file; an effect declares its own in
    ``quantities`` (key ``<name>.<quantity>``, with unit, bounds, default and source), the package's effects and a
    user's alike; they are known wherever the effect is (:func:`known_quantities`). ``requires`` names the effects
    it needs; ``replaces`` names the slot it fills (see :data:`SLOTS`). Per-build state lives on the model being built
    (``model.state(self)``), never on the effect.

    The effect's roles are the class attributes below the line ``# roles``, declared here and only here (see
    docs/model.md, "The effect's roles (`Effect`)"):

    - ``in_default_set``: in the model when no effect set is named (the paper's five);
    - ``diagnosis_candidate``: a candidate of the diagnosis of a car without power assist;
    - ``assist_candidate``: a candidate of the diagnosis of a car with an electric assist (its motor friction,
      its torsion bar's offset, its gain error);
    - ``rival``: a rival of the paper's mechanisms (:class:`Rival`), never a candidate;
    - ``power_assist``: ``"electric"`` or ``"hydraulic"`` for a power assist, None otherwise: its push is the
      gear's own, left out of the rack force, and a record of the car is replayed through its boost law
      (:mod:`parksteer.model.numeric.assisted`);
    - ``location``: a power assist's point of action, ``"column"``, ``"pinion"`` or ``"rack"`` (its torsion bar is
      in the column for a column assist, on the pinion otherwise), None for any other effect.
    """

    name: ClassVar[str] = ""
    description: ClassVar[str] = ""
    uses: ClassVar[tuple[str, ...]] = ()
    quantities: ClassVar[tuple[Quantity, ...]] = ()
    requires: ClassVar[tuple[str, ...]] = ()
    replaces: ClassVar[str | None] = None
    # roles (class docstring)
    in_default_set: ClassVar[bool] = True
    diagnosis_candidate: ClassVar[bool] = True
    assist_candidate: ClassVar[bool] = False
    rival: ClassVar[Rival | None] = None
    power_assist: ClassVar[str | None] = None
    location: ClassVar[str | None] = None

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """A rival is never a candidate: its ``diagnosis_candidate`` is False, and a class that declares both is
        refused (one line naming it), never corrected silently."""
        super().__init_subclass__(**kwargs)
        if cls.rival is not None:
            if cls.__dict__.get("diagnosis_candidate") is True:
                raise UsageError(f"effect {cls.name or cls.__qualname__}: declares both rival and "
                                 "diagnosis_candidate = True; a rival is never a diagnosis candidate")
            cls.diagnosis_candidate = False

    def configure(self, model: ModelSpace) -> None:
        """Before the kinematics are built: add coordinates (keep them in ``model.state(self)``)."""

    def bodies(self, model: ModelSpace) -> list[Any]:
        """After the kinematics are built: extra rigid bodies or particles, e.g. on coordinates this effect added."""
        return []

    def loads(self, model: ModelSpace) -> list[Any]:
        """Forces on points and torques on frames (``Force``, ``Torque``) acting on the core system."""
        return []

    def potential_energy(self, model: ModelSpace):
        """Potential energy (J) of the conservative part of this effect's loads (for the energy balance)."""
        return 0

    def outputs(self, model: ModelSpace) -> list[tuple[str, Any]]:
        """Extra named outputs of every run (name with its SI unit, expression), e.g. an assist's motor current."""
        return []

    def boost_law(self, law, value):
        """Law-side: the boost law of an assisted car's replay with this effect acting in it.

        `law` is the replay's :class:`parksteer.model.numeric.assisted.BoostLaw` (a frozen dataclass: return
        ``dataclasses.replace(law, ...)``), `value(key)` the value of a quantity this effect uses in the run. An
        effect that acts in the control unit (a sensor's offset, the curve's gain, the motor's limit) changes the
        law here and adds no load; one output carrying its strength keeps that quantity in the compiled model's
        parameter vector, where the replay reads it. Called for every effect of the replayed model, so at strength
        0 it must return the law unchanged. A handwheel-driven simulation does not call it. Default: `law`."""
        return law

    def own_keys(self) -> tuple[str, ...]:
        """The keys of the quantities only this effect has (``<name>.*``, declared in ``quantities``)."""
        return tuple(k for k in self.uses if k.partition(".")[0] == self.name)

    def describe(self, params) -> dict:
        """Name, description, slot, needs and quantities with their values (for ``parksteer effects --json``)."""
        table, params = registry(known_quantities([self])), with_effect_quantities(params, [self])
        return {
            "name": self.name,
            "description": self.description,
            "in_default_set": self.in_default_set,
            "requires": list(self.requires),
            "replaces": self.replaces,
            **({"rival": {"closest": self.rival.closest, "related": list(self.rival.related), "why": self.rival.why,
                          "probe_strength": self.rival.probe_strength}} if self.rival is not None else {}),
            "parameters": [
                {
                    "key": key,
                    "unit": table[key].unit,
                    "default": float(params[key]),
                    "min": table[key].lower,
                    "max": table[key].upper,
                    "source": params.source(key),
                }
                for key in self.uses
            ],
        }


def power_assist_of(effects) -> Effect | None:
    """The power assist among `effects` (a model has at most one), or None."""
    return next((e for e in effects if e.power_assist), None)


def _checked_effect(effect: Effect, where: str, known: Mapping[str, Quantity] | None = None) -> Effect:
    """`effect`, its quantities checked against `known` (:func:`shipped_quantities`) and every key it uses known."""
    for q in effect.quantities:
        if q.section != effect.name:
            raise UsageError(f"{where}: quantity {q.key} must be named {effect.name}.<name>")
    known = declared_with(effect.quantities, shipped_quantities() if known is None else known)
    if effect.rival is not None and effect.diagnosis_candidate:
        raise UsageError(f"{where}: effect {effect.name} is a rival, so it cannot be a diagnosis candidate")
    if effect.replaces is not None and effect.replaces not in SLOTS:
        raise UsageError(f"{where}: effect {effect.name} replaces unknown slot {effect.replaces!r} "
                         f"(slots: {', '.join(SLOTS)})")
    for key in effect.uses:
        if key not in known and key not in FILE_AND_CASE_KEYS:
            raise UsageError(f"{where}: effect {effect.name} uses {unknown_key_message(key)}")
    return effect


def register_effect(effect: Effect, where: str) -> Effect:
    """An effect made in code (not a module's EFFECT), its quantities and keys checked (:func:`_checked_effect`);
    `where` names it in an error."""
    return _checked_effect(effect, where)


def _effect_of(obj: Any, where: str, known: Mapping[str, Quantity] | None = None) -> Effect:
    if inspect.isclass(obj) and issubclass(obj, Effect):
        obj = obj()
    if not isinstance(obj, Effect) or not obj.name:
        raise UsageError(f"{where}: does not define an Effect with a name")
    return _checked_effect(obj, where, known)


def _effect_of_module(module: Any, where: str, known: Mapping[str, Quantity] | None = None) -> Effect:
    if not hasattr(module, "EFFECT"):
        raise UsageError(f"{where}: module defines no EFFECT")
    return _effect_of(module.EFFECT, where, known)


def load_effect_module(ref: str) -> Effect:
    """The EFFECT of a module given by dotted name or by path to a .py file."""
    if ref.endswith(".py") or os.sep in ref or "/" in ref:
        path = Path(ref)
        if not path.is_file():
            raise UsageError(f"effect module {ref}: no such file")
        # The module's name carries a hash of the file's text: the compiled model's cache key names the effect's
        # class by it (a module loaded from a file is not in sys.modules, so its source cannot be read back), and
        # an edited file must build its own model.
        mod_name = f"parksteer_effect_{path.stem}_{hashlib.sha256(path.read_bytes()).hexdigest()[:16]}"
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


@lru_cache(maxsize=1)
def _installed_effects() -> tuple[tuple[str, Effect], ...]:
    """The package's effect modules, then the installed entry points' (found once a process: scanning every
    installed distribution's entry points costs milliseconds, and a diagnosis prepares hundreds of runs)."""
    from . import effects as package

    modules = (importlib.import_module(f"{package.__name__}.{info.name}")
               for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda i: i.name))
    loaded = [(module.__name__, module.EFFECT) for module in modules if hasattr(module, "EFFECT")]
    loaded += [(f"entry point {ep.name}", ep.load())
               for ep in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name)]
    known, found = RUN_QUANTITIES, {}
    for where, obj in loaded:  # each checked against the quantities of those before it and its own
        effect = _effect_of(obj, where, known)
        known = declared_with(effect.quantities, known)
        found.setdefault(effect.name, effect)
    return tuple(found.items())


@lru_cache(maxsize=1)
def shipped_quantities() -> DeclaredQuantities:
    """The quantities the installed effects and the run declare, by key (read-only)."""
    return DeclaredQuantities(declared_with(q for _, e in _installed_effects() for q in e.quantities))


def known_quantities(effects: Iterable[Effect] = ()) -> DeclaredQuantities:
    """The quantities a run of `effects` can name beyond the file's (the run's, the installed effects', theirs)."""
    shipped = shipped_quantities()
    known = declared_with((q for e in effects for q in e.quantities), shipped)
    return known if known is shipped else DeclaredQuantities(known)


def quantity_of(key: str, effects: Iterable[Effect] = ()) -> Quantity:
    """The quantity of `key` (:func:`parksteer.parameters.quantity`) among the :func:`known_quantities` of `effects`."""
    return quantity(key, known_quantities(effects))


def with_effect_quantities(params: Parameters, effects: Iterable[Effect] = ()) -> Parameters:
    """`params` knowing the :func:`known_quantities` of `effects`: their defaults read, their overrides checked."""
    return params.knowing(known_quantities(effects))


def discover_effects() -> dict[str, Effect]:
    """Every effect the registry can find: the package's modules, entry points and configured modules."""
    found = dict(_installed_effects())
    for ref in filter(None, os.environ.get(MODULES_ENV, "").split(os.pathsep)):
        effect = load_effect_module(ref)
        found[effect.name] = effect
    return found


STRENGTH_NAME = "strength"


@lru_cache(maxsize=1)
def _shipped_values() -> MappingProxyType:
    """The shipped parameter file's scalar values by key, read-only."""
    params = load_parameters(DEFAULT_PATH)
    return MappingProxyType({f"{section}.{name}": float(value) for section, table in params.sections.items()
                             for name, value in table.items() if isinstance(value, (int, float))})


def strength_parameter(effect: Effect, params=None) -> Quantity | None:
    """The quantity whose default means absent: ``<effect>.strength``, else the only own quantity of value 0
    whose lower bound is 0 (in `params`, by default the shipped parameter file).

    A candidate effect (off by default) is added to a model at a fitted or chosen size through it.
    """
    declared = {q.key: q for q in effect.quantities}
    table = registry(known_quantities([effect]))
    own = [declared.get(k) or table[k] for k in effect.own_keys()]
    named = [q for q in own if q.name == STRENGTH_NAME]
    if named:
        return named[0]

    def is_zero(q: Quantity) -> bool:
        if q.key in declared:
            return q.default == 0.0
        if params is not None:
            return float(params[q.key]) == 0.0
        return _shipped_values().get(q.key, q.default) == 0.0

    zero = [q for q in own if is_zero(q) and q.lower == 0.0]
    return zero[0] if len(zero) == 1 else None


def default_effect_names(registry: dict[str, Effect] | None = None) -> list[str]:
    registry = registry if registry is not None else discover_effects()
    return [name for name, e in registry.items() if e.in_default_set]


def resolve_effects(spec: str | list | tuple | None = None) -> list[Effect]:
    """The effects chosen by `spec`, in a canonical order (sorted by name).

    `spec` is None (the default set), a string such as ``"-rack_friction,+hooke_joint"``
    (each ``+name``/``-name`` edits the default set; a bare list ``"a,b"`` without signs
    names the set exactly; ``none`` is the empty set), or a list of names or Effect instances.
    """
    return _checked(_chosen(spec), spec)


def _checked(effects: list[Effect], spec) -> list[Effect]:
    """Refuse a set in which two effects fill one slot or an effect lacks one it requires."""
    where = f"effects {spec!r}" if isinstance(spec, str) else "effects"
    names = {e.name for e in effects}
    filled: dict[str, str] = {}
    for effect in effects:
        missing = [n for n in effect.requires if n not in names]
        if missing:
            raise UsageError(f"{where}: {effect.name} requires {', '.join(missing)} (add +{missing[0]})")
        if effect.replaces is not None:
            if effect.replaces in filled:
                raise UsageError(f"{where}: {filled[effect.replaces]} and {effect.name} both fill the slot "
                                 f"{effect.replaces}; choose one")
            filled[effect.replaces] = effect.name
    return effects


def _chosen(spec) -> list[Effect]:
    registry = discover_effects()
    if isinstance(spec, (list, tuple)):
        chosen: dict[str, Effect] = {}
        for item in spec:
            effect = _checked_effect(item, item.name) if isinstance(item, Effect) else _lookup(registry, str(item))
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
