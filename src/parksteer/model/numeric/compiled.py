"""Load a compiled model (the numeric half's entry to the generated code) with ctypes."""

from __future__ import annotations

import ctypes
import json
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from ..codegen.cache import ensure_entry, ensure_tangent_library, entry_path
from ..symbolic.components import Effect


@dataclass
class CompiledModel:
    """The compiled functions of one effect set, and its description."""

    directory: Path
    info: dict
    lib: ctypes.CDLL
    # positions of tuples of parameter keys, found once (positions)
    _positions_of_keys: dict = field(default_factory=dict, init=False, repr=False, compare=False)

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

    @cached_property
    def with_tangent(self) -> CompiledModel:
        """This model from its library with the tangent compiled in (eval_tangent, which the forward sensitivities
        call; the model's own library has a stub), compiled into the entry on first use. A model whose library has
        the tangent already, or whose generated C has none (an assist's drive: ``rack_drive`` false), is itself."""
        if self.lib.ps_sensitivities_available() or not self.info.get("rack_drive", True):
            return self
        library = ensure_tangent_library(self.directory, self.info)
        return CompiledModel(self.directory, self.info, bind(ctypes.CDLL(str(library))))

    @cached_property
    def parameter_positions(self) -> dict[str, int]:
        """Each parameter's position in the vector, found once (an assisted replay reads its boost table's hundred
        entries by name at every replay)."""
        positions: dict[str, int] = {}
        for i, name in enumerate(self.info["parameters"]):
            positions.setdefault(name, i)
        return positions

    def positions(self, keys: tuple[str, ...]) -> np.ndarray:
        """The positions of `keys` in the parameter vector (each name's first), found once per tuple of keys and
        kept on this model: an assisted replay reads its boost table's 552 scalars at every replay."""
        if keys not in self._positions_of_keys:
            self._positions_of_keys[keys] = np.array([self.parameter_positions[k] for k in keys], dtype=np.intp)
        return self._positions_of_keys[keys]

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


def bind(lib: ctypes.CDLL) -> ctypes.CDLL:
    """`lib`, a model's library (its own or its tangent's), with the C signatures of the runtime's functions."""
    vp, dbl, i32 = ctypes.c_void_p, ctypes.c_double, ctypes.c_int
    for name, restype, args in (
        ("ps_rhs", i32, [dbl, vp, vp, vp]),
        ("ps_jac", i32, [dbl, vp, vp, vp]),
        ("ps_forcing", None, [dbl, vp, vp, vp]),
        ("ps_forcing_dq", None, [dbl, vp, vp, vp]),
        ("ps_drive", None, [vp, vp, vp, vp, vp]),
        ("ps_handwheel", None, [dbl, vp, vp, vp]),
        ("ps_outputs", i32, [i32, vp, vp, vp, vp, vp, vp]),
        ("ps_rack", None, [dbl, vp, vp]),
        ("ps_prescribed_rhs", i32, [dbl, vp, vp, vp, vp]),
        ("ps_prescribed_jac", i32, [dbl, vp, vp, vp, vp, vp]),
        ("ps_prescribed_samples", i32, [i32, vp, vp, vp, vp, vp, vp, vp]),
        ("ps_integrate", i32, [vp, vp, i32, vp, i32, vp, dbl, vp, ctypes.c_long, vp, vp]),
        ("ps_integrate_prescribed", i32, [vp, vp, vp, vp, i32, vp, i32, vp, dbl, vp, ctypes.c_long, vp, vp]),
        ("ps_sensitivities_available", i32, []),
        ("ps_prescribed_tangent", i32, [dbl, vp, vp, vp, i32, vp, vp, vp, vp]),
        ("ps_forcing_tangent", i32, [dbl, vp, vp, i32, vp, vp]),
        ("ps_integrate_prescribed_sens", i32, [vp, vp, vp, vp, i32, vp, i32, vp, dbl, vp, ctypes.c_long, vp, vp,
                                               i32, vp, vp, vp]),
        ("ps_prescribed_torque_sens", i32, [i32, vp, vp, vp, vp, vp, i32, vp, vp]),
    ):
        function = getattr(lib, name)
        function.restype = restype
        function.argtypes = args
    return lib


class CompiledModels:
    """The compiled models one owner has loaded (a diagnosis's replay engine, or one call of :func:`load_model`), by
    cache entry: each entry's library is loaded once, and an entry loaded is used again without re-checking its
    files (the library in memory is the one checked)."""

    def __init__(self) -> None:
        self.loaded: dict[Path, CompiledModel] = {}

    def entry(self, directory: Path) -> CompiledModel:
        """The compiled model of the cache entry in `directory`."""
        directory = Path(directory).resolve()
        if directory in self.loaded:
            return self.loaded[directory]
        info = json.loads((directory / "model.json").read_text(encoding="utf-8"))
        lib = bind(ctypes.CDLL(str(directory / "model.so")))
        self.loaded[directory] = CompiledModel(directory, info, lib)
        return self.loaded[directory]

    def of(self, effects: list[Effect]) -> CompiledModel:
        """The compiled model of `effects`, from the cache (derived and compiled once if missing)."""
        path = entry_path(effects)  # the key hashes the model's source: once
        loaded = self.loaded.get(path.resolve())
        return loaded if loaded is not None else self.entry(ensure_entry(effects, path))


def load_entry(directory: Path) -> CompiledModel:
    """The compiled model of the cache entry in `directory`, loaded afresh."""
    return CompiledModels().entry(directory)


def load_model(effects: list[Effect], models: CompiledModels | None = None) -> CompiledModel:
    """The compiled model of `effects`, from the cache (derived and compiled once if missing), through `models`
    (the models an owner keeps loaded; by default, loaded afresh)."""
    return (models if models is not None else CompiledModels()).of(effects)
