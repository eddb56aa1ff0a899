"""Experiments about the diagnosis: benchmarks of hidden effects, the generators of their records' truths, and the
peer methods it is scored against. They import the method (:mod:`parksteer.diagnose`); the method never imports
them."""
