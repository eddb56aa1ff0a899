"""Syntax trees of source texts, parsed and walked once per test process.

Several tests read every module of the package (its imports, docstrings, function sizes, module state, calls into
linear algebra), each walking the same trees: parsing and walking them again in each test was most of these
tests' time. The trees are shared: a test reads them and never changes them.
"""

from __future__ import annotations

import ast
from functools import lru_cache


@lru_cache(maxsize=None)
def tree(source: str) -> ast.Module:
    """The syntax tree of the Python text `source`."""
    return ast.parse(source)


@lru_cache(maxsize=None)
def nodes(source: str) -> tuple[ast.AST, ...]:
    """Every node of :func:`tree` of `source`, in :func:`ast.walk`'s order."""
    return tuple(ast.walk(tree(source)))
