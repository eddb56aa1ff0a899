"""parksteer: car steering torque at parking speed, after Sharp & Granger."""

from .parameters import add_declarer

__version__ = "0.1.0"


def _load_effects() -> None:
    """Load every effect the registry finds, so that their own quantities (``<effect>.<name>``, declared on each
    effect) are known to :mod:`parksteer.parameters` when a key of one is first looked up."""
    from .model.symbolic.components import discover_effects

    discover_effects()


add_declarer(_load_effects)
