"""Derive, generate, compile and cache a model; load it with ctypes.

A cache entry is a directory holding the generated C, the shared library and a JSON of
the state names, parameter order and outputs. Its key is a hash of the effect set, the
source of the model package (and of any effect module outside it) and the sympy version,
so a change of the model's source makes a new entry and a simulation never re-derives a
model that is already cached. The cache directory is ``$PARKSTEER_MODEL_CACHE``, else
``results/model`` in the repository when the package runs from a checkout, else the
user's cache directory.
"""

from __future__ import annotations

import ctypes
import hashlib
import inspect
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy

from ..errors import UsageError
from .components import Effect

CACHE_ENV = "PARKSTEER_MODEL_CACHE"
FORMAT_VERSION = "1"
PACKAGE_DIR = Path(__file__).resolve().parent
REPO_ROOT = PACKAGE_DIR.parents[2]


def cache_root() -> Path:
    env = os.environ.get(CACHE_ENV)
    if env:
        return Path(env)
    if (REPO_ROOT / "Snakefile").is_file() and (REPO_ROOT / "src" / "parksteer").is_dir():
        return REPO_ROOT / "results" / "model"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "parksteer" / "model"


def _effect_source(effect: Effect) -> str:
    module = sys.modules.get(type(effect).__module__)
    path = getattr(module, "__file__", None)
    if path and Path(path).resolve().is_relative_to(PACKAGE_DIR):
        return ""  # hashed with the package
    try:
        return inspect.getsource(module)
    except (OSError, TypeError):
        return repr(type(effect))


def model_key(effects: list[Effect]) -> str:
    """Hash of the effect set, the model package's source, external effects' source and the sympy version."""
    digest = hashlib.sha256()
    digest.update(f"format {FORMAT_VERSION}\nsympy {sympy.__version__}\n".encode())
    digest.update(("effects " + ",".join(e.name for e in effects) + "\n").encode())
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        digest.update(str(path.relative_to(PACKAGE_DIR)).encode() + b"\0" + path.read_bytes() + b"\0")
    for effect in effects:
        digest.update(_effect_source(effect).encode())
    return digest.hexdigest()[:20]


def find_compiler() -> str:
    for name in filter(None, (os.environ.get("CC"), "cc", "gcc", "clang")):
        found = shutil.which(name)
        if found:
            return found
    raise UsageError("no C compiler found (tried $CC, cc, gcc, clang): install one, e.g. apt-get install gcc")


def build_entry(effects: list[Effect], directory: Path) -> dict:
    """Derive, generate and compile the model for `effects` into `directory`; return its description."""
    from .codegen import generate
    from .derive import derive

    start = time.perf_counter()
    derivation = derive(effects)
    t_derive = time.perf_counter() - start
    source, info = generate(derivation)
    t_codegen = time.perf_counter() - start - t_derive
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "model.c").write_text(source, encoding="utf-8")
    compiler = find_compiler()
    cmd = [compiler, "-O2", "-shared", "-fPIC", "-o", str(directory / "model.so"), str(directory / "model.c"), "-lm"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        first = (done.stderr.strip().splitlines() or ["unknown error"])[0]
        raise UsageError(f"C compiler failed on the generated model: {first}")
    t_compile = time.perf_counter() - start - t_derive - t_codegen
    info.update({
        "sympy_version": sympy.__version__,
        "timings_s": {"derive": t_derive, "codegen": t_codegen, "compile": t_compile,
                      "total": time.perf_counter() - start, **derivation.timings_s},
    })
    (directory / "model.json").write_text(json.dumps(info, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return info


def entry_path(effects: list[Effect]) -> Path:
    return cache_root() / model_key(effects)


def ensure_entry(effects: list[Effect]) -> Path:
    """The cache entry of `effects`, built if missing (atomically: built aside, then renamed into place)."""
    final = entry_path(effects)
    if (final / "model.json").is_file() and (final / "model.so").is_file():
        return final
    final.parent.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix=f".{final.name}.", dir=final.parent))
    try:
        build_entry(effects, scratch)
        try:
            os.rename(scratch, final)
        except OSError:
            if not (final / "model.json").is_file():  # someone else's complete entry wins
                raise
    finally:
        if scratch.exists():
            shutil.rmtree(scratch, ignore_errors=True)
    return final


@dataclass
class CompiledModel:
    """The compiled functions of one effect set, and its description."""

    directory: Path
    info: dict
    lib: ctypes.CDLL

    @property
    def n_q(self) -> int:
        return len(self.info["coordinates"])

    @property
    def coordinates(self) -> list[str]:
        return self.info["coordinates"]

    @property
    def outputs(self) -> list[str]:
        return self.info["outputs"]

    @property
    def effects(self) -> list[str]:
        return self.info["effects"]

    def index(self, coordinate: str) -> int:
        return self.coordinates.index(coordinate)

    # Thin wrappers (each returns new arrays); the integrator uses the raw functions directly.
    def rhs(self, t: float, y: np.ndarray, p: np.ndarray) -> np.ndarray:
        y = np.ascontiguousarray(y, dtype=float)
        out = np.empty(2 * self.n_q)
        if self.lib.ps_rhs(float(t), y.ctypes.data, p.ctypes.data, out.ctypes.data):
            raise FloatingPointError("mass matrix not positive definite")
        return out

    def jacobian(self, t: float, y: np.ndarray, p: np.ndarray) -> np.ndarray:
        y = np.ascontiguousarray(y, dtype=float)
        out = np.empty((2 * self.n_q, 2 * self.n_q))
        if self.lib.ps_jac(float(t), y.ctypes.data, p.ctypes.data, out.ctypes.data):
            raise FloatingPointError("mass matrix not positive definite")
        return out

    def forcing(self, t: float, y: np.ndarray, p: np.ndarray) -> np.ndarray:
        y = np.ascontiguousarray(y, dtype=float)
        out = np.empty(self.n_q)
        self.lib.ps_forcing(float(t), y.ctypes.data, p.ctypes.data, out.ctypes.data)
        return out

    def forcing_dq(self, t: float, y: np.ndarray, p: np.ndarray) -> np.ndarray:
        y = np.ascontiguousarray(y, dtype=float)
        out = np.empty((self.n_q, self.n_q))
        self.lib.ps_forcing_dq(float(t), y.ctypes.data, p.ctypes.data, out.ctypes.data)
        return out

    def drive_parts(self, y: np.ndarray, p: np.ndarray):
        """Mass matrix, forcing without the column torque, and the column torque's direction."""
        y = np.ascontiguousarray(y, dtype=float)
        n = self.n_q
        M, F, b = np.empty((n, n)), np.empty(n), np.empty(n)
        self.lib.ps_drive(y.ctypes.data, p.ctypes.data, M.ctypes.data, F.ctypes.data, b.ctypes.data)
        return M, F, b

    def handwheel(self, t: float, p: np.ndarray) -> tuple[float, float]:
        th, thd = ctypes.c_double(), ctypes.c_double()
        self.lib.ps_handwheel(float(t), p.ctypes.data, ctypes.byref(th), ctypes.byref(thd))
        return th.value, thd.value

    def evaluate_outputs(self, t: np.ndarray, y: np.ndarray, p: np.ndarray, accelerations=None, handwheel=None
                         ) -> dict[str, np.ndarray]:
        """Named outputs at samples (t, y); with `accelerations` and `handwheel` given (rack drive), uses them."""
        t = np.ascontiguousarray(t, dtype=float)
        y = np.ascontiguousarray(y, dtype=float).reshape(len(t), 2 * self.n_q)
        out = np.empty((len(t), len(self.outputs)))
        if accelerations is None:
            acc_ptr = hw_ptr = None
        else:
            accelerations = np.ascontiguousarray(accelerations, dtype=float)
            handwheel = np.ascontiguousarray(handwheel, dtype=float)
            acc_ptr, hw_ptr = accelerations.ctypes.data, handwheel.ctypes.data
        if self.lib.ps_outputs(len(t), t.ctypes.data, y.ctypes.data, acc_ptr, hw_ptr, p.ctypes.data,
                               out.ctypes.data):
            raise FloatingPointError("mass matrix not positive definite")
        return {name: out[:, i] for i, name in enumerate(self.outputs)}


_LOADED: dict[Path, CompiledModel] = {}


def load_entry(directory: Path) -> CompiledModel:
    directory = Path(directory).resolve()
    if directory in _LOADED:
        return _LOADED[directory]
    info = json.loads((directory / "model.json").read_text(encoding="utf-8"))
    lib = ctypes.CDLL(str(directory / "model.so"))
    vp, dbl, i32 = ctypes.c_void_p, ctypes.c_double, ctypes.c_int
    for name, restype, args in (
        ("ps_rhs", i32, [dbl, vp, vp, vp]),
        ("ps_jac", i32, [dbl, vp, vp, vp]),
        ("ps_forcing", None, [dbl, vp, vp, vp]),
        ("ps_forcing_dq", None, [dbl, vp, vp, vp]),
        ("ps_drive", None, [vp, vp, vp, vp, vp]),
        ("ps_handwheel", None, [dbl, vp, vp, vp]),
        ("ps_outputs", i32, [i32, vp, vp, vp, vp, vp, vp]),
    ):
        function = getattr(lib, name)
        function.restype = restype
        function.argtypes = args
    model = CompiledModel(directory, info, lib)
    _LOADED[directory] = model
    return model


def load_model(effects: list[Effect]) -> CompiledModel:
    """The compiled model of `effects`, from the cache (derived and compiled once if missing)."""
    return load_entry(ensure_entry(effects))
