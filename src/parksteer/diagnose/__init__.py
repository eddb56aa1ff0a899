"""The method: model against measurement. Compare, calibrate, rank the effects the model lacks, give the verdict.

Its front door is :mod:`.intake` (records, car, effects and options in; what :func:`.select.diagnose` takes out);
:mod:`.select` runs the table of stages (:mod:`.stages`) on one replay engine (:mod:`.engine`); the baseline
(``baseline*``) judges later records against a car's healthy ones; :mod:`.identify` reads an assist's boost map
and gear from a car's records. What the method found is told by :mod:`parksteer.reporting`, which it never
imports; it depends on nothing of ``synthetic`` or ``experiments`` (the contracts in ``pyproject.toml``).
"""
