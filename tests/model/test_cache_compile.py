"""Compiling a pre-derived model: a cold cache entry built from the package's C needs the compiler and not the
derivation, so the process that builds it (a derive job of the pipeline, or a benchmark's job) never imports
sympy."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from importlib import metadata

import pytest

BUILD = """
import json, sys
from parksteer.model.codegen.cache import ensure
from parksteer.model.symbolic.components import resolve_effects
manifest = ensure(resolve_effects(None))
print(json.dumps({"sympy_imported": "sympy" in sys.modules, "manifest": manifest}))
"""


@pytest.mark.slow
def test_compiling_a_prebuilt_model_imports_no_sympy(tmp_path):
    """The default model, built into an empty cache in a fresh process, is compiled from the shipped C (no
    derivation), sympy is never imported, and the entry still records the sympy version its key was made with
    (the installed distribution's)."""
    env = {**os.environ, "PARKSTEER_MODEL_CACHE": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", BUILD], capture_output=True, text=True, env=env, check=True)
    out = json.loads(done.stdout.strip().splitlines()[-1])
    manifest = out["manifest"]
    assert manifest["built_now"] and manifest["prebuilt"] and manifest["timings_s"]["derive"] == 0.0
    assert out["sympy_imported"] is False
    entry = json.loads((tmp_path / manifest["key"] / "model.json").read_text(encoding="utf-8"))
    assert entry["sympy_version"] == metadata.version("sympy")
