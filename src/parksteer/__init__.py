"""parksteer: car steering torque at parking speed, after Sharp & Granger."""

import atexit as _atexit
import os as _os
import sys as _sys

# The package needs Python 3.11 (tomllib, the typing it uses); pip refuses to install it on an older one, but a
# checkout on the path or a venv made by another interpreter gets here: one line, not a traceback from deep inside.
if _sys.version_info < (3, 11):
    _sys.stderr.write(f"parksteer: error: Python 3.11 or newer is needed, this is {_sys.version.split()[0]} "
                      f"({_sys.executable}): make the venv with a newer one, e.g. python3.11 -m venv .venv\n")
    raise SystemExit(2)

__version__ = "0.1.0"

# sympy's cache of constructed expressions (SYMPY_CACHE_SIZE, read once when sympy is first imported; 1000 entries
# unless set): a model build rebuilds the same sums and products many times over (Kane's method substitutes into
# every expression, code generation rewrites them in C symbols), and the largest, the diagnosis model, holds
# 23,600 distinct ones; with 1000 most are evicted before they are met again and built anew, their assumptions
# asked anew. 100,000 keeps a whole build's. The cache changes no expression, only how often one is built; a
# value the user sets wins, and a process that imported sympy before parksteer keeps its own.
_os.environ.setdefault("SYMPY_CACHE_SIZE", "100000")


def _release_sympy_cache() -> None:
    """Empty sympy's cache at exit, if sympy was imported: a process that derived models holds them there, and the
    interpreter's own teardown of that cache takes about a second after three models, against 0.05 s here."""
    sympy = _sys.modules.get("sympy")
    if sympy is not None:
        sympy.core.cache.clear_cache()


_atexit.register(_release_sympy_cache)
