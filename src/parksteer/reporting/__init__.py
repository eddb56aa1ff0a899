"""The diagnosis told: its JSON, its markdown and HTML pages, the error ladder, and the case study's notebook run.

What: a finished :class:`parksteer.diagnose.state.Diagnosis` (and the records it was made from) in, text and files out.
:mod:`.report` writes the JSON (``diagnosis_dict``, documented by ``parksteer/data/diagnosis.schema.json``) and the
rows and lines other views read from it; :mod:`.sections` builds the report's sections once, from that JSON;
:mod:`.pages` renders them as markdown and as one self-contained HTML page (:mod:`.user_effect_pages`,
:mod:`.relative_text`: the parts on a user's own effect and on a baseline); :mod:`.ladder` diagnoses the grown
model again to show the error falling to the noise floor; :mod:`.notebook` executes a percent-format notebook.

Contract: reporting reads what the method found and decides nothing the JSON does not already hold (the ladder
calls :func:`parksteer.diagnose.select.diagnose`, as any caller may). It imports the method; the method never
imports it (the ``layers`` contract in ``pyproject.toml``: reporting sits above ``diagnose``), and commands/,
figures/, experiments/ and the workflow call it. Bad output paths raise :class:`parksteer.errors.UsageError`.
"""
