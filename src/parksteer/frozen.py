"""A mapping that cannot change once made, and pickles, so that a value holding it may cross a process fork."""

from __future__ import annotations


class FrozenDict(dict):
    """A dict whose every mutating method raises :class:`TypeError` with :attr:`refusal`."""

    refusal = "this mapping is read-only: make a new one"

    def _read_only(self, *args, **kwargs):
        raise TypeError(self.refusal)

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = __ior__ = _read_only

    def __reduce__(self):
        return type(self), (dict(self),)
