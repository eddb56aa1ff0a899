"""Files the package ships (package data, read with importlib.resources): the parameter file, the printed
Table 1, the diagnosis JSON schema and the example user effect. They work the same from a checkout, an editable
install or an installed wheel.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path


def data_file(name: str) -> Path:
    """A file of ``parksteer/data`` (``parameters.toml``, ``table1_printed.csv``, ``diagnosis.schema.json``)."""
    return Path(str(files("parksteer") / "data" / name))


def example_effect(name: str = "column_imbalance") -> Path:
    """An example effect module shipped with the package (``parksteer/examples/<name>.py``)."""
    return Path(str(files("parksteer") / "examples" / f"{name}.py"))
