"""Execute a jupytext (percent format) notebook and save it executed, for the pipeline's case study."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import UsageError
from ..tables import atomic_path

NOTEBOOK_TIMEOUT_S = 3600  # per cell; the diagnosis cell replays several files many times


def execute_notebook(source: str | Path, executed: str | Path, environment: dict[str, str],
                     working_directory: str | Path = ".") -> None:
    """Convert `source` to a notebook, run it in a fresh python3 kernel, write it executed to `executed`.

    `environment` is added to the kernel's environment (the notebook reads its input and
    output paths from it). A failing cell raises :class:`UsageError` naming the cell's error.
    """
    import jupytext
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    notebook = jupytext.read(str(source))
    saved = {key: os.environ.get(key) for key in environment}
    os.environ.update({key: str(value) for key, value in environment.items()})
    try:
        client = NotebookClient(notebook, timeout=NOTEBOOK_TIMEOUT_S, kernel_name="python3",
                                resources={"metadata": {"path": str(Path(working_directory).resolve())}})
        client.execute()
    except CellExecutionError as exc:
        last = [line for line in str(exc).strip().splitlines() if line.strip()][-1]
        raise UsageError(f"{source}: a cell failed: {last}") from None
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    with atomic_path(executed) as tmp:
        nbformat.write(notebook, str(tmp))
