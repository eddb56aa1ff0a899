"""How a model's generated C becomes its shared library: the compiler, its flags, and the shared objects it links.

The runtime (:mod:`.runtime`: the mass-matrix solves, the outputs, the stiff integrator and its sensitivities) is the
same text for every model, and the boost table's law the same for every model with a boost table; each is compiled
once per cache and compiler, into ``runtime/<key>.o`` beside the cache's entries, and linked with each model's own
file (:data:`.runtime.SHARED_OBJECTS`). An object is compiled in the building entry's scratch directory, under a
lock, and renamed into place whole, so a killed build leaves no half of one and builders side by side compile it
once. C that no model links (the assisted replay's torsion-bar inversion, ``model/numeric/torsion_bar.c``) is
compiled alike into a library of its own, ``runtime/<name>-<key>.so`` (:func:`standalone_library`), and a model's
tangent, which only the forward sensitivities call, into a second library of the model's entry on first use
(:func:`tangent_library`).
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import os
import platform
import shutil
import subprocess
from contextlib import suppress
from functools import lru_cache
from pathlib import Path

from ...errors import UsageError
from ...progress import note
from .runtime import SHARED_OBJECTS, WITH_TANGENT, check_portable
from .scratch import scratch_directory

# How the C is compiled; part of the model key. -O1 for a model's own C and the runtime: their straight-line
# functions run about as fast as at -O2 and compile in less time, and every first use of a model waits for them;
# the runtime's loops a replay spends most of its time in are compiled at -O2 all the same (PS_HOT, runtime.c). -O2
# for the boost table's law, which compiles faster there, and the torsion-bar inversion, a loop a few lines long.
# -ffp-contract=off: no fused multiply-add, which GCC otherwise forms wherever the target has one (aarch64, or x86
# with -march=native), so every product is rounded on its own and the bits do not depend on it; without
# -ffast-math nothing is reordered at any level, so the level changes no bit.
FP_FLAGS = ("-ffp-contract=off",)
OPTIMISE_FLAGS = ("-O1", *FP_FLAGS)
COMPILE_FLAGS = (*OPTIMISE_FLAGS, "-shared", "-fPIC")
SHARED_LEVELS = {"runtime": "-O1", "boost_table": "-O2"}  # of each of runtime.SHARED_OBJECTS
STANDALONE_COMPILE_FLAGS = ("-O2", *FP_FLAGS, "-shared", "-fPIC")
RUNTIME_FOLDER = "runtime"


def find_compiler() -> str:
    for name in filter(None, (os.environ.get("CC"), "cc", "gcc", "clang")):
        found = shutil.which(name)
        if found:
            return found
    raise UsageError("no C compiler found (tried $CC, cc, gcc, clang): install one, e.g. apt-get install gcc")


@lru_cache(maxsize=None)
def _compiler_identity(compiler: str) -> str:
    """The compiler's real path, its version line and the machine: what the runtime object's bytes depend on."""
    done = subprocess.run([compiler, "--version"], capture_output=True, text=True)
    version = (done.stdout.strip().splitlines() or [""])[0]
    return f"{os.path.realpath(compiler)}\n{version}\n{platform.machine()}\n"


def _built_key(compiler: str, flags: tuple[str, ...], source: str) -> str:
    """Hash of what a file compiled on its own is made of: the compiler, the flags and the C `source`."""
    digest = hashlib.sha256(_compiler_identity(compiler).encode())
    digest.update(" ".join(flags).encode() + b"\0" + source.encode())
    return digest.hexdigest()[:20]


def shared_key(compiler: str, name: str) -> str:
    """Hash of the shared object `name`'s source (:data:`.runtime.SHARED_OBJECTS`), the flags and the compiler."""
    return _built_key(compiler, shared_flags(name), SHARED_OBJECTS[name][1]())


def shared_flags(name: str) -> tuple[str, ...]:
    """The optimisation flags of the shared object `name` (:data:`.runtime.SHARED_OBJECTS`): its level
    (:data:`SHARED_LEVELS`) and :data:`FP_FLAGS`."""
    return (SHARED_LEVELS[name], *FP_FLAGS)


def shared_object(compiler: str, name: str, root: Path, scratch: Path) -> Path:
    """The shared object `name` (:data:`.runtime.SHARED_OBJECTS`) compiled by `compiler` for the cache `root`:
    root/runtime/<key>.o, compiled in `scratch` and renamed into place if it is not there yet. Builders that need it
    at once (a first diagnosis builds its models side by side) wait for the one compiling it, under a lock the
    kernel releases when its holder ends."""
    what, source_of = SHARED_OBJECTS[name]
    final = root / RUNTIME_FOLDER / f"{shared_key(compiler, name)}.o"
    if final.is_file():
        return final
    final.parent.mkdir(parents=True, exist_ok=True)
    with open(final.with_suffix(".lock"), "a", encoding="utf-8") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if final.is_file():
            return final
        note(f"compiling {what}, once for this cache and compiler ({final})")
        source, built = scratch / f"{name}.c", scratch / f"{name}.o"
        source.write_text(source_of(), encoding="utf-8")
        compile_object(compiler, source, built, what, shared_flags(name))
        os.replace(built, final)
        source.unlink()
    return final


def library_key(compiler: str, source: str) -> str:
    """Hash of a standalone library's C `source`, the flags and the compiler (:func:`standalone_library`)."""
    return _built_key(compiler, STANDALONE_COMPILE_FLAGS, source)


def standalone_library(compiler: str, name: str, source: str, what: str, root: Path) -> Path:
    """The C `source` (`what` it is) compiled on its own by `compiler` into a shared library for the cache `root`:
    root/runtime/<name>-<key>.so (:func:`library_key`), built once (:func:`_library_once`)."""
    check_portable(source)
    stem = f"{name}-{library_key(compiler, source)}"

    def build(scratch: Path) -> Path:
        c_path, built = scratch / f"{name}.c", scratch / f"{name}.so"
        c_path.write_text(source, encoding="utf-8")
        run_compiler([compiler, *STANDALONE_COMPILE_FLAGS, "-o", str(built), str(c_path), "-lm"], what)
        return built

    return _library_once(root / RUNTIME_FOLDER / f"{stem}.so", what, root, stem, build)


def tangent_library(compiler: str, entry: Path, shared: tuple[str, ...] = ()) -> Path:
    """The library of the model in the cache entry `entry` with its tangent compiled in (its model.c compiled with
    :data:`.runtime.WITH_TANGENT` defined, linked as :func:`compile_model` links the model's own library), which
    the forward sensitivities call: entry/model_tangent.so, built once (:func:`_library_once`). The model's C is
    read from the entry, whose digests the caller has checked."""

    def build(scratch: Path) -> Path:
        c_path, built = scratch / "model.c", scratch / "model_tangent.so"
        shutil.copyfile(entry / "model.c", c_path)
        compile_model(compiler, c_path, built, entry.parent, shared, (f"-D{WITH_TANGENT}",))
        return built

    return _library_once(entry / "model_tangent.so", "the model's tangent (its forward sensitivities)", entry.parent,
                         f"{entry.name}-tangent", build)


def _library_once(final: Path, what: str, root: Path, stem: str, build) -> Path:
    """The library `final` (`what` it is), with the SHA-256 of its bytes beside it (.sha256): as it is, or built
    by `build` (given a new scratch folder of the cache `root`, named from `stem` as the cache's builds name theirs,
    so that ``scratch.clean_stale_scratch`` removes a killed build's; it returns the library it built there) if it is
    not there yet or its bytes are not the ones recorded (a damaged or truncated file). The build runs under a lock
    the kernel releases when its holder ends (builders side by side build it once), and its library is renamed into
    place whole, its digest first: a killed build leaves no half of it, nor a library without its digest."""
    digest = final.with_suffix(".sha256")
    if _library_is_sound(final, digest):
        return final
    final.parent.mkdir(parents=True, exist_ok=True)
    with open(final.with_suffix(".lock"), "a", encoding="utf-8") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if _library_is_sound(final, digest):
            return final
        note(f"compiling {what}, once for this cache and compiler ({final})")
        scratch = scratch_directory(root, stem)
        try:
            built = build(scratch)
            (scratch / "sha256").write_text(hashlib.sha256(built.read_bytes()).hexdigest(), encoding="utf-8")
            os.replace(scratch / "sha256", digest)
            os.replace(built, final)
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
    return final


def _library_is_sound(library: Path, digest: Path) -> bool:
    """Whether `library` is there with the SHA-256 its `digest` file records."""
    try:
        return hashlib.sha256(library.read_bytes()).hexdigest() == digest.read_text(encoding="utf-8").strip()
    except OSError:
        return False


def compile_model(compiler: str, c_path: Path, so_path: Path, root: Path, shared: tuple[str, ...] = (),
                  defines: tuple[str, ...] = ()) -> None:
    """Compile the generated `c_path` (with the macro `defines`, e.g. ``-DPS_WITH_TANGENT``) and link it with the
    runtime and the `shared` objects it names into `so_path` (the cache `root` holds the shared objects; `c_path`'s
    folder is the build's scratch). The model's own object compiles while this builder finds the shared objects or
    compiles a missing one (:func:`shared_object`), so that on an empty cache the runtime's compile runs beside the
    models' rather than after the first of them."""
    model_object = c_path.with_suffix(".o")
    compiling = start_compiler(object_command(compiler, c_path, model_object, defines))
    names = ("runtime", *shared)
    try:
        objects = [shared_object(compiler, name, root, c_path.parent) for name in names]
    except BaseException:
        compiling.kill()
        compiling.communicate()
        raise
    finish_compiler(compiling, "the generated model")
    for attempt in (1, 2):
        try:
            run_compiler([compiler, "-shared", "-o", str(so_path), str(model_object), *map(str, objects), "-lm"],
                         "the model's library")
            break
        except UsageError:
            if attempt == 2:
                raise
            # a damaged shared object: each compiled again once and linked again
            for path in objects:
                with suppress(FileNotFoundError):
                    path.unlink()
            objects = [shared_object(compiler, name, root, c_path.parent) for name in names]
    model_object.unlink()


def object_command(compiler: str, source: Path, built: Path, defines: tuple[str, ...] = (),
                   flags: tuple[str, ...] = OPTIMISE_FLAGS) -> list[str]:
    """The command that compiles the C file `source` (with the macro `defines`, at the optimisation `flags`) into the
    position-independent object `built`."""
    return [compiler, *flags, *defines, "-fPIC", "-c", "-o", str(built), str(source)]


def compile_object(compiler: str, source: Path, built: Path, what: str, flags: tuple[str, ...]) -> None:
    """Compile the C file `source` of a shared object (`what` it is, for an error) at the optimisation `flags` into
    the position-independent object `built`."""
    run_compiler(object_command(compiler, source, built, flags=flags), what)


def run_compiler(cmd: list[str], what: str) -> None:
    """Run the compiler command `cmd` on `what`; a failure is one line (its first), a full disk an OSError."""
    finish_compiler(start_compiler(cmd), what)


def start_compiler(cmd: list[str]) -> subprocess.Popen:
    """The compiler command `cmd`, started (:func:`finish_compiler` waits for it)."""
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def finish_compiler(process: subprocess.Popen, what: str) -> None:
    """Wait for the compiler `process` (on `what`); a failure is one line (its first), a full disk an OSError."""
    _, stderr = process.communicate()
    if process.returncode != 0:
        if "No space left on device" in stderr:  # the library could not be written: the cache's disk is full
            raise OSError(errno.ENOSPC, "No space left on device")
        first = (stderr.strip().splitlines() or ["unknown error"])[0]
        raise UsageError(f"C compiler failed on {what}: {first}")
