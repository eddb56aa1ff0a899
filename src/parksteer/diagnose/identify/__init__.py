"""The identification tool: an electric assist's boost map and its gear's hidden numbers, read from the car's own
healthy records (``parksteer assist identify``), and the vehicle file written again with them.

What: records of an assisted car (torsion-bar torque, motor current, rack or handwheel angle) and its vehicle file
in; an :class:`.identified_file.Identified` out (values in SI units with their 95 % intervals), which writes the
vehicle file again. :mod:`.boost_map` fits the map (the current against the torque, model-free);
:mod:`.assist_identify` then the gear's numbers through the replay (:func:`.assist_identify.identify_boost`);
:mod:`.identified_file` holds the result and its TOML. A record or vehicle file it cannot use raises
:class:`parksteer.errors.UsageError` in one line naming the file.

Contract: the tool uses the method's core (the records, the replay engine, the calibration's statistics, a
quantity's provenance); the core never imports it (the ``identify-apart`` contract in ``pyproject.toml``). Its
callers are the baseline (``diagnose/baseline_assist.py``, for a car whose file gives only the gear), commands/ and
experiments/.
"""
