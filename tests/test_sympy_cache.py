"""sympy's expression cache, which the package sizes for a whole model build (parksteer/__init__.py), is emptied at
exit: a process that derived models would otherwise spend about a second in the interpreter's teardown of it."""

from __future__ import annotations

import subprocess
import sys


def test_a_process_that_built_sympy_expressions_exits_with_sympys_cache_empty():
    """An exit function registered before the package is imported runs after the package's own (they run last
    registered first): it finds every cached function of sympy's empty, after a derivation's worth of cached
    expressions (here the derivative of a product, which fills sympy's caches) was built in the process."""
    code = ("import atexit, sys\n"
            "def sizes():\n"
            "    from sympy.core.cache import CACHE\n"
            "    print('cached after exit:', sum(f.cache_info().currsize for f in CACHE))\n"
            "atexit.register(sizes)\n"
            "import parksteer\n"
            "import sympy\n"
            "x, y = sympy.symbols('x y')\n"
            "expression = sympy.diff(sympy.sin(x * y) * sympy.exp(x + y) / (1 + x ** 2), x, 2)\n"
            "from sympy.core.cache import CACHE\n"
            "print('cached before exit:', sum(f.cache_info().currsize for f in CACHE))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    before, after = done.stdout.splitlines()
    assert int(before.split(":")[1]) > 100
    assert after == "cached after exit: 0"
