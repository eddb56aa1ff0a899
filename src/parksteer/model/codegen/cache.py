"""Derive, generate, compile and cache a model: the symbolic half of the model, ready to load.

A cache entry is a directory holding the generated C, the shared library and a JSON of
the state names, parameter order and outputs. Its key is a hash of the effect set, the
source of the model package (and of any effect module outside it) and the sympy version,
so a change of the model's source makes a new entry and a simulation never re-derives a
model that is already cached. The cache directory is ``$PARKSTEER_MODEL_CACHE``, else
``results/model`` in the repository when the package runs from a checkout, else the
user's cache directory. :func:`ensure` is the one way to get a model built and described.
"""

from __future__ import annotations

import errno
import hashlib
import inspect
import json
import os
import shutil
import signal
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from functools import lru_cache
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING

from ...errors import UsageError
from ...progress import note
from .compiler import COMPILE_FLAGS, compile_model, find_compiler, shared_flags, tangent_library
from .runtime import SHARED_OBJECTS
from .scratch import build_lock, clean_stale_scratch, scratch_directory

if TYPE_CHECKING:  # the workflow checks cache entries on every run: sympy is imported only to derive or key a model
    from ..symbolic.components import Effect

CACHE_ENV = "PARKSTEER_MODEL_CACHE"
FORMAT_VERSION = "1"
MODEL_DIR = Path(__file__).resolve().parents[1]
# The symbolic half: what the generated code depends on. numeric/ is not hashed, so editing it never re-derives.
SYMBOLIC_DIRS = (MODEL_DIR / "symbolic", MODEL_DIR / "codegen")
# Files outside the two halves whose names the symbolic model builds on (the sides a coordinate is made for).
KEYED_FILES = (MODEL_DIR.parent / "names.py",)
# These modules store and compile entries and generate nothing, so their source is not part of the key (the flags
# are).
KEYLESS_SOURCES = (Path(__file__).resolve(), Path(__file__).resolve().with_name("compiler.py"),
                   Path(__file__).resolve().with_name("scratch.py"),
                   # printed from the keyed symbolic half and checked against it where a model is derived
                   Path(__file__).resolve().with_name("boost_table.c"))
# Built files whose SHA-256 model.json records: an entry is used only if both exist and match.
BUILT_FILES = ("model.c", "model.so")
# The package's pre-derived models: the generated C (gzip) and description of the effect sets a first diagnosis of
# a car with the default effects builds, named by their cache keys (`parksteer derive --prebuilt` writes them; the
# tests derive each again and compare the bytes). Outside the symbolic half, so they are not part of any key.
PREBUILT_DIR = MODEL_DIR / "prebuilt"


@lru_cache(maxsize=1)
def checkout_root() -> Path | None:
    """The repository the package runs from (editable install, or src/ on the path); None when installed (once)."""
    package = MODEL_DIR.parent
    with suppress(metadata.PackageNotFoundError):
        # An installed wheel's files sit where its metadata says: never a checkout, wherever the environment is.
        if Path(str(metadata.distribution("parksteer").locate_file("parksteer"))).resolve() == package:
            return None
    root = package.parents[1]
    if package.parent.name == "src" and (root / "workflow" / "Snakefile").is_file():
        return root
    return None


def cache_root() -> Path:
    """$PARKSTEER_MODEL_CACHE, else results/model of the checkout the package runs from, else the user cache."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return Path(env)
    root = checkout_root()
    if root is not None:
        return root / "results" / "model"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "parksteer" / "model"


@lru_cache(maxsize=None)
def _in_symbolic_half(path: str) -> bool:  # resolving a path is a system call a directory: once a path
    return any(Path(path).resolve().is_relative_to(d) for d in SYMBOLIC_DIRS)


def _effect_source(effect: Effect) -> str:
    module = sys.modules.get(type(effect).__module__)
    path = getattr(module, "__file__", None)
    if path and _in_symbolic_half(path):
        return ""  # hashed with the symbolic half
    try:
        return inspect.getsource(module)
    except (OSError, TypeError):
        return repr(type(effect))


@lru_cache(maxsize=1)
def _symbolic_half_source() -> bytes:
    """The symbolic half's files (symbolic/ and codegen/, Python and C) and :data:`KEYED_FILES`, each with its path,
    read once per process (a simulation loads its model by key)."""
    sources = [p for d in SYMBOLIC_DIRS for pattern in ("*.py", "*.c") for p in d.rglob(pattern)]
    return b"".join(str(path.relative_to(MODEL_DIR.parent)).encode() + b"\0" + path.read_bytes() + b"\0"
                    for path in sorted(p for p in [*sources, *KEYED_FILES] if p not in KEYLESS_SOURCES))


@lru_cache(maxsize=None)
def _sympy_version() -> str:
    return metadata.version("sympy")


def model_key(effects: list[Effect]) -> str:
    """Hash of the effect set, the symbolic half's source (symbolic/ and codegen/, Python and C), external effects'
    source, the sympy version (its distribution's: a replay keys its model without importing sympy) and the compiler
    flags."""
    shared = ", ".join(f"{name} {' '.join(shared_flags(name))}" for name in SHARED_OBJECTS)
    digest = hashlib.sha256()
    digest.update(f"format {FORMAT_VERSION}\nsympy {_sympy_version()}\ncc {' '.join(COMPILE_FLAGS)}\n"
                  f"shared {shared}\n".encode())
    digest.update(("effects " + ",".join(e.name for e in effects) + "\n").encode())
    digest.update(_symbolic_half_source())
    for effect in effects:
        digest.update(_effect_source(effect).encode())
    return digest.hexdigest()[:20]


def derive_source(effects: list[Effect]) -> tuple[str, dict, dict]:
    """Derive and generate the model of `effects`: its C source, its description and the derivation's timings."""
    from ..symbolic.derive import derive
    from .generate import generate

    names = ",".join(e.name for e in effects) or "none"
    note(f"deriving the model of {names} (sympy Kane's method) ...")
    start = time.perf_counter()
    derivation = derive(effects)
    t_derive = time.perf_counter() - start
    note(f"derived: {len(derivation.coordinate_names)} coordinates ({', '.join(derivation.coordinate_names)}), "
         f"{len(derivation.parameter_names)} parameters, {t_derive:.1f} s "
         f"({', '.join(f'{k} {v:.1f} s' for k, v in derivation.timings_s.items())})")
    source, info = generate(derivation)
    t_codegen = time.perf_counter() - start - t_derive
    note(f"generated C: {source.count(chr(10))} lines, {len(source) / 1024:.0f} KiB, {t_codegen:.1f} s")
    return source, info, {"derive": t_derive, "codegen": t_codegen, **derivation.timings_s}


def _prebuilt_paths(key: str) -> tuple[Path, Path]:
    return PREBUILT_DIR / f"{key}.c.gz", PREBUILT_DIR / f"{key}.json"


def prebuilt_info(info: dict) -> dict:
    """A generated model's description as the package keeps it: without its code-generation timings (which
    depend on the machine), so that the same model gives the same file."""
    return {k: v for k, v in info.items() if k != "codegen_timings_s"}


def prebuilt_source(key: str) -> tuple[str, dict] | None:
    """The package's pre-derived C and description under `key`, or None (:data:`PREBUILT_DIR`). A damaged pair
    (truncated, or a placeholder in its place) is said on stderr and the model derived instead."""
    import gzip

    c_path, json_path = _prebuilt_paths(key)
    if not (c_path.is_file() and json_path.is_file()):
        return None
    try:
        source = gzip.decompress(c_path.read_bytes()).decode("utf-8")
        info = json.loads(json_path.read_text(encoding="utf-8"))
    except (OSError, ValueError, EOFError) as error:
        note(f"the package's pre-derived model {c_path.name} is damaged ({error}): deriving it instead")
        return None
    info.pop("spec", None)
    return source, info


def prebuilt_specs() -> dict[str, str | list | dict | None]:
    """The effects spec (:func:`~parksteer.model.symbolic.components.resolve_effects`) of each pre-derived model,
    by its key: what `parksteer derive --prebuilt` was asked for, so that a stale key can be told (a model of the
    signature benchmark's records: ``{"truth_form": name}``, the default set with that truth form)."""
    specs = {}
    for json_path in sorted(PREBUILT_DIR.glob("*.json")):
        try:
            specs[json_path.stem] = json.loads(json_path.read_text(encoding="utf-8")).get("spec")
        except (OSError, ValueError):
            specs[json_path.stem] = None
    return specs


def write_prebuilt(effect_sets: list[tuple[str | list | None, list[Effect]]]) -> list[Path]:
    """Derive each (spec, effects) of `effect_sets` and keep its C and description, with its spec, as the package's
    pre-derived models, replacing all others (after writing boost_table.c again); return the models' files written.
    The gzip stream carries no time stamp, so the same C gives the same file."""
    import gzip

    from ...tables import atomic_path

    if checkout_root() is None:
        raise UsageError("--prebuilt writes into the package's source: run it in a checkout of the repository "
                         "(an editable install), not an installed package")
    from .generate import table_functions_source
    from .runtime import BOOST_TABLE_FILE

    with atomic_path(BOOST_TABLE_FILE) as tmp:  # the shared C the assisted models link (runtime.SHARED_OBJECTS)
        tmp.write_text(table_functions_source(), encoding="utf-8")
    PREBUILT_DIR.mkdir(parents=True, exist_ok=True)
    written = []
    for number, (spec, effects) in enumerate(effect_sets, 1):
        c_path, json_path = _prebuilt_paths(model_key(effects))
        if c_path in written:
            continue
        note(f"pre-deriving model {number} of {len(effect_sets)}: {','.join(e.name for e in effects) or 'none'}")
        source, info, _ = derive_source(effects)
        # each file renamed into place whole: a cold build reading meanwhile finds the old file or the new one
        with atomic_path(c_path) as tmp:
            tmp.write_bytes(gzip.compress(source.encode("utf-8"), compresslevel=9, mtime=0))
        with atomic_path(json_path) as tmp:
            tmp.write_text(json.dumps({**prebuilt_info(info), "spec": spec}, indent=1, sort_keys=True) + "\n",
                           encoding="utf-8")
        written += [c_path, json_path]
    for path in PREBUILT_DIR.iterdir():
        if path.name.endswith((".c.gz", ".json")) and path not in written:
            path.unlink()
    return written


def build_entry(effects: list[Effect], directory: Path, key: str | None = None) -> dict:
    """Derive, generate and compile the model for `effects` into `directory` (with the cache `key`, the package's
    pre-derived C of that key is compiled instead of deriving it, :data:`PREBUILT_DIR`); return its description.
    Compiling pre-derived C imports no sympy: its version is the installed distribution's, as the key has it."""
    names = ",".join(e.name for e in effects) or "none"
    compiler = find_compiler()  # before the derivation: without one, say so at once rather than after minutes
    start = time.perf_counter()
    prebuilt = prebuilt_source(key) if key is not None else None
    if prebuilt is not None:
        source, info = prebuilt
        timings = {"derive": 0.0, "codegen": 0.0, "read_prebuilt": time.perf_counter() - start}
        note(f"the model of {names}: the package's pre-derived C ({source.count(chr(10))} lines), compiling it")
    else:
        source, info, timings = derive_source(effects)
    t_derive, t_codegen = timings["derive"], timings["codegen"]
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "model.c").write_text(source, encoding="utf-8")
    compile_model(compiler, directory / "model.c", directory / "model.so", directory.parent,
                  tuple(info.get("shared_objects", ())))
    t_compile = time.perf_counter() - start - t_derive - t_codegen
    note(f"compiled with {Path(compiler).name} {COMPILE_FLAGS[0]}: {t_compile:.1f} s")
    info.update({"sha256": {name: _sha256(directory / name) for name in BUILT_FILES}, "sympy_version": _sympy_version(),
                 "prebuilt": prebuilt is not None,
                 "timings_s": {**timings, "compile": t_compile, "total": time.perf_counter() - start}})
    (directory / "model.json").write_text(json.dumps(info, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return info


def entry_path(effects: list[Effect]) -> Path:
    return cache_root() / model_key(effects)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def entry_is_sound(directory: Path) -> bool:
    """True if `directory` holds a complete entry: model.json readable, and model.c and model.so present with
    the SHA-256 it recorded (content, not timestamps: a truncated or replaced library is not trusted)."""
    try:
        info = json.loads((directory / "model.json").read_text(encoding="utf-8"))
        recorded = info["sha256"]
        return all(_sha256(directory / name) == recorded[name] for name in BUILT_FILES)
    except (OSError, ValueError, KeyError, TypeError):
        return False


# What a cache folder that cannot be written raises: read-only, no permission, no space or quota, a file in the path.
CACHE_WRITE_ERRNOS = {errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOSPC, errno.EDQUOT, errno.ENOTDIR, errno.EEXIST}


@contextmanager
def writing_cache(root: Path) -> Iterator[None]:
    """Writing into the model cache `root`: an error that says it cannot be written (a read-only checkout, a full
    disk, a path through a file) becomes one line, with the folder, why, and where else the cache can go."""
    try:
        yield
    except OSError as exc:
        if exc.errno not in CACHE_WRITE_ERRNOS:
            raise
        why = "no space left on its disk" if exc.errno == errno.ENOSPC else exc.strerror or type(exc).__name__
        raise UsageError(f"cannot write the model cache {root} ({why}): set {CACHE_ENV} to a folder with room that "
                         "you can write (the cache is results/model of a checkout, else "
                         "$XDG_CACHE_HOME/parksteer/model, XDG_CACHE_HOME "
                         f"{os.environ.get('XDG_CACHE_HOME') or 'unset: ~/.cache'})") from None


def ensure_entry(effects: list[Effect], final: Path | None = None) -> Path:
    """The cache entry of `effects` (at `final`, if the caller has its path), built if missing or unsound (built
    aside, then renamed into place; a killed build's scratch directory removed; one build at a time per entry). A
    cache that cannot be written is one line (:func:`writing_cache`), with nothing half-written left in it."""
    final = entry_path(effects) if final is None else final
    if entry_is_sound(final):
        return final
    with writing_cache(final.parent):
        return _build_entry_into(effects, final)


def ensure_tangent_library(directory: Path, info: dict) -> Path:
    """The library of the cache entry `directory` (its description `info`) with the model's tangent compiled in,
    which only the forward sensitivities call (:func:`.compiler.tangent_library`), compiled on first use; a cache
    that cannot be written is one line (:func:`writing_cache`)."""
    with writing_cache(directory.parent):
        return tangent_library(find_compiler(), directory, tuple(info.get("shared_objects", ())))


def _build_entry_into(effects: list[Effect], final: Path) -> Path:
    final.parent.mkdir(parents=True, exist_ok=True)
    with build_lock(final):
        if entry_is_sound(final):  # built by the process this one waited for
            return final
        clean_stale_scratch(final.parent)
        scratch = scratch_directory(final.parent, final.name)
        try:
            build_entry(effects, scratch, final.name)
            if final.exists() and not entry_is_sound(final):  # damaged or incomplete: replaced by the new build
                broken = scratch_directory(final.parent, final.name)
                os.rename(final, broken / "old")
                shutil.rmtree(broken, ignore_errors=True)
            try:
                os.rename(scratch, final)
            except OSError:
                if not entry_is_sound(final):  # someone else's complete entry wins
                    raise
        finally:
            if scratch.exists():
                shutil.rmtree(scratch, ignore_errors=True)
    return final


def _build_in_child(effect_sets: list[list[Effect]]) -> None:
    # terminate() ends the build through SystemExit (its scratch removed), whatever SIGTERM handler it inherited
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    for effects in effect_sets:
        ensure_entry(effects)


def start_builds(effect_sets: list[list[Effect]], jobs: int = 1) -> list:
    """Start building the missing cache entries of `effect_sets` in the background: on up to `jobs` processes forked
    from this one (sympy, code generation and `cc` run in each in line), the largest sets first, dealt in turn.
    Return the processes (:func:`finish_builds` waits for them). Nothing starts where the platform cannot fork or
    `jobs` is 1: each entry is then built when first loaded.

    Whoever needs an entry meanwhile loads it as usual (:func:`ensure_entry`): the entry's build lock makes it wait
    for the process building it, or build it itself if it gets there first (the builder then finds it built), so
    no entry is built twice and a failed build is met again, with its one-line error, where the entry is loaded."""
    import multiprocessing

    if int(jobs) <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        return []
    missing = sorted((effects for effects in effect_sets if not entry_is_sound(entry_path(effects))),
                     key=lambda effects: -len(effects))
    shares = [missing[i :: int(jobs)] for i in range(min(int(jobs), len(missing)))]
    context = multiprocessing.get_context("fork")
    processes = [context.Process(target=_build_in_child, args=(share,), daemon=True) for share in shares]
    for process in processes:
        process.start()
    return processes


def finish_builds(processes: list) -> None:
    """Wait for the background builds :func:`start_builds` started (each has finished or failed by the time its
    entry was loaded; a failed one is reported there)."""
    for process in processes:
        process.join()


def ensure(effects: list[Effect], note_cached: bool = False) -> dict:
    """Build (or find) the compiled model of `effects` and return its manifest.

    The one derive path: ``parksteer derive`` and the pipeline's derive rule both call it. The
    manifest names the effects, the cache key and entry directory, the generalised coordinates,
    the number of run-time parameters, and the derivation's timings (of the build that made the
    entry, possibly earlier) with ``built_now`` saying whether this call built it. A build reports its stages on
    stderr (:mod:`parksteer.progress`); a cache hit only with `note_cached`.
    """
    existed = entry_is_sound(entry_path(effects))
    directory = ensure_entry(effects)
    if not existed or note_cached:
        note(f"model of {','.join(e.name for e in effects) or 'none'}: "
             f"{'found in' if existed else 'built into'} the cache, {directory}")
    info = json.loads((directory / "model.json").read_text(encoding="utf-8"))
    return {
        "effects": [e.name for e in effects],
        "key": directory.name,
        "directory": str(directory),
        "coordinates": info["coordinates"],
        "n_parameters": len(info["parameters"]),
        "timings_s": info["timings_s"],
        "built_now": not existed,
        # compiled from the package's pre-derived C rather than derived (the build that made the entry)
        "prebuilt": bool(info.get("prebuilt")),
    }
