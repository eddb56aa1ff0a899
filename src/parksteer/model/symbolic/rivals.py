"""The rivals of the paper's mechanisms among the effects: every effect that declares ``rival``
(:class:`parksteer.model.symbolic.components.Rival`), and a selection of them checked."""

from __future__ import annotations

from ...errors import UsageError
from .components import Effect, discover_effects


def rival_effects(registry: dict[str, Effect] | None = None) -> dict[str, Effect]:
    """The effects that declare themselves rivals of the paper's mechanisms (``rival`` set), in name order."""
    registry = registry if registry is not None else discover_effects()
    return {name: registry[name] for name in sorted(registry) if registry[name].rival is not None}


def chosen_rivals(names, where: str, registry: dict[str, Effect] | None = None) -> tuple[str, ...]:
    """`names` (a selection, e.g. a configuration's list) checked to be rival effects; None is every rival in name
    order. A name that is no rival is a one-line UsageError naming `where`."""
    rivals = rival_effects(registry)
    if names is None:
        return tuple(rivals)
    for name in names:
        if name not in rivals:
            raise UsageError(f"{where}: {name!r} is not a rival effect (the rivals: {', '.join(rivals)}; an effect "
                             "is one when it declares `rival`)")
    return tuple(str(n) for n in names)
