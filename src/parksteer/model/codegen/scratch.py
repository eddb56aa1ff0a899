"""A build's scratch folders and locks in the model cache: each build runs in a scratch folder named for its
builder (``.<name>.<host>.<pid>.<random>``) and is renamed into place whole, under a lock the kernel releases when its
holder ends; what a killed build leaves is found by its name and removed (:func:`clean_stale_scratch`). Stores and
compiles nothing, so its source is not part of a model's key (``cache.KEYLESS_SOURCES``)."""

from __future__ import annotations

import fcntl
import os
import shutil
import socket
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

from ...progress import note

# A scratch directory whose builder is gone is removed by the next build; one from another host (a shared cache on a
# cluster) only once it is older than any build could take.
STALE_SCRATCH_S = 6 * 3600.0


def scratch_host() -> str:
    """This machine's name as a build's scratch directory carries it (:func:`clean_stale_scratch` reads it back)."""
    return socket.gethostname().replace(".", "-")


def scratch_directory(parent: Path, name: str) -> Path:
    """A new scratch directory in `parent` for building `name`: ``.<name>.<host>.<pid>.<random>``, the name by which
    :func:`clean_stale_scratch` finds a killed build's."""
    return Path(tempfile.mkdtemp(prefix=f".{name}.{scratch_host()}.{os.getpid()}.", dir=parent))


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _unheld(lock: Path) -> bool:
    """Whether no process holds the build lock `lock` now."""
    try:
        fd = os.open(lock, os.O_RDWR)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False
    finally:
        os.close(fd)


def clean_stale_scratch(root: Path) -> list[Path]:
    """Remove scratch directories and build locks of builds that were killed (their process is gone); return what
    was removed."""
    removed = []
    host = scratch_host()  # as the scratch name writes it
    if not root.is_dir():
        return removed
    for path in root.iterdir():
        parts = path.name.split(".")
        if path.name.startswith(".") and path.name.endswith(".lock") and _unheld(path):
            with suppress(FileNotFoundError):
                path.unlink()  # the build lock of a killed build
            removed.append(path)
            continue
        if not (path.name.startswith(".") and len(parts) >= 5 and path.is_dir()):
            continue
        _, _key, owner_host, pid, *_ = parts
        try:
            age = time.time() - path.stat().st_mtime
        except OSError:
            continue
        if not pid.isdigit():
            continue
        stale = (owner_host == host and not _alive(int(pid))) or age > STALE_SCRATCH_S
        if stale:
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
    return removed


@contextmanager
def build_lock(final: Path) -> Iterator[None]:
    """Hold the build of one cache entry: processes that need the same model at the same time build it once, the
    others wait here and then find it built. The lock file goes when its holder is done (a waiter that wakes on a
    removed file takes the lock again on the new one)."""
    path = final.parent / f".{final.name}.lock"
    while True:
        fd = os.open(path, os.O_CREAT | os.O_RDWR, 0o644)
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                note(f"another process is building the model {final.name}: waiting for it")
                fcntl.flock(fd, fcntl.LOCK_EX)
            try:
                current = os.stat(path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                current = False
            if current:
                try:
                    yield
                finally:
                    with suppress(FileNotFoundError):
                        os.unlink(path)
                return
        finally:
            os.close(fd)
