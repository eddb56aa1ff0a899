"""How a model's generated C becomes its shared library: the compiler, its flags, and the shared objects it links.

The runtime (:mod:`.runtime`: the mass-matrix solves, the outputs, the stiff integrator and its sensitivities) is the
same text for every model, and the boost table's law the same for every model with a boost table; each is compiled
once per cache and compiler, into ``runtime/<key>.o`` beside the cache's entries, and linked with each model's own
file (:data:`.runtime.SHARED_OBJECTS`). An object is compiled in the building entry's scratch directory, under a
lock, and renamed into place whole, so a killed build leaves no half of one and builders side by side compile it
once. C that no model links (the assisted replay's torsion-bar inversion, ``model/numeric/torsion_bar.c``) is
compiled alike into a library of its own, ``runtime/<name>-<key>.so`` (:func:`standalone_library`).
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import os
import platform
import shutil
import socket
import subprocess
import tempfile
from contextlib import suppress
from functools import lru_cache
from pathlib import Path

from ...errors import UsageError
from ...progress import note
from .runtime import SHARED_OBJECTS, check_portable

# How the C is compiled; part of the model key. -O1: integrates these models about as fast as -O2 and compiles in
# less time. -ffp-contract=off: no fused multiply-add, which GCC otherwise forms wherever the target has one
# (aarch64, or x86 with -march=native), so every product is rounded on its own and the bits do not depend on it.
OPTIMISE_FLAGS = ("-O1", "-ffp-contract=off")
COMPILE_FLAGS = (*OPTIMISE_FLAGS, "-shared", "-fPIC")
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
    return _built_key(compiler, OPTIMISE_FLAGS, SHARED_OBJECTS[name][1]())


def scratch_host() -> str:
    """This machine's name as a build's scratch directory carries it (``cache.clean_stale_scratch`` reads it back)."""
    return socket.gethostname().replace(".", "-")


def scratch_directory(parent: Path, name: str) -> Path:
    """A new scratch directory in `parent` for building `name`: ``.<name>.<host>.<pid>.<random>``, the name by which
    ``cache.clean_stale_scratch`` finds a killed build's."""
    return Path(tempfile.mkdtemp(prefix=f".{name}.{scratch_host()}.{os.getpid()}.", dir=parent))


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
        compile_object(compiler, source, built, what)
        os.replace(built, final)
        source.unlink()
    return final


def library_key(compiler: str, source: str) -> str:
    """Hash of a standalone library's C `source`, the flags and the compiler (:func:`standalone_library`)."""
    return _built_key(compiler, COMPILE_FLAGS, source)


def standalone_library(compiler: str, name: str, source: str, what: str, root: Path) -> Path:
    """The C `source` (`what` it is) compiled on its own by `compiler` into a shared library for the cache `root`:
    root/runtime/<name>-<key>.so (:func:`library_key`), with the SHA-256 of its bytes beside it (.sha256), compiled
    if it is not there yet or its bytes are not the ones recorded (a damaged or truncated file). It is compiled in a
    scratch folder of `root` named as the cache's builds name theirs (``cache.clean_stale_scratch`` removes a
    killed build's), under a lock the kernel releases when its holder ends (builders side by side compile it once),
    and renamed into place whole, its digest first: a killed build leaves no half of it, nor a library without its
    digest."""
    check_portable(source)
    stem = f"{name}-{library_key(compiler, source)}"
    final = root / RUNTIME_FOLDER / f"{stem}.so"
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
            c_path, built = scratch / f"{name}.c", scratch / f"{name}.so"
            c_path.write_text(source, encoding="utf-8")
            run_compiler([compiler, *COMPILE_FLAGS, "-o", str(built), str(c_path), "-lm"], what)
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


def compile_model(compiler: str, c_path: Path, so_path: Path, root: Path, shared: tuple[str, ...] = ()) -> None:
    """Compile the generated `c_path` and link it with the runtime and the `shared` objects it names into `so_path`
    (the cache `root` holds the shared objects; `c_path`'s folder is the build's scratch). The model's own object is
    compiled first, so that builders side by side compile their models while one of them compiles a missing shared
    object."""
    model_object = c_path.with_suffix(".o")
    compile_object(compiler, c_path, model_object, "the generated model")
    names = ("runtime", *shared)
    for attempt in (1, 2):
        objects = [shared_object(compiler, name, root, c_path.parent) for name in names]
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
    model_object.unlink()


def compile_object(compiler: str, source: Path, built: Path, what: str) -> None:
    """Compile the C file `source` (`what` it is, for an error) into the position-independent object `built`."""
    run_compiler([compiler, *OPTIMISE_FLAGS, "-fPIC", "-c", "-o", str(built), str(source)], what)


def run_compiler(cmd: list[str], what: str) -> None:
    """Run the compiler command `cmd` on `what`; a failure is one line (its first), a full disk an OSError."""
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        if "No space left on device" in done.stderr:  # the library could not be written: the cache's disk is full
            raise OSError(errno.ENOSPC, "No space left on device")
        first = (done.stderr.strip().splitlines() or ["unknown error"])[0]
        raise UsageError(f"C compiler failed on {what}: {first}")
