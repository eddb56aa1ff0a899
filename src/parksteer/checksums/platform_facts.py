"""The facts of a platform that can move a last bit of a figure: recorded beside the sums at refresh
(figures/PLATFORM.json) and compared with the running platform at verification.

Gathering takes a few milliseconds: package versions come from their installed metadata (nothing is imported but
numpy, which the comparison needs anyway), the BLAS core from the OpenBLAS library numpy has already loaded, and the
compiler from one ``cc --version``.
"""

from __future__ import annotations

import json
import os
import platform
import shutil
import subprocess
from importlib import metadata
from pathlib import Path

PLATFORM_NAME = "PLATFORM.json"
PACKAGES = ("numpy", "scipy", "sympy", "matplotlib")


def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


def _blas() -> tuple[str, str]:
    """numpy's BLAS (name and version) and the core type its OpenBLAS chose on this CPU ('unknown' if not OpenBLAS)."""
    import ctypes

    import numpy as np

    try:
        blas = np.__config__.CONFIG["Build Dependencies"]["blas"]
        name = f"{blas.get('name', 'unknown')} {blas.get('version', '')}".strip()
    except (AttributeError, KeyError, TypeError):
        name = "unknown"
    core = "unknown"
    try:
        maps = Path("/proc/self/maps").read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError:  # not Linux: the BLAS name alone
        maps = []
    libraries = sorted({line.split()[-1] for line in maps if "openblas" in line.split()[-1].lower()})
    for library in libraries:
        try:
            handle = ctypes.CDLL(library)
        except OSError:
            continue
        for symbol in ("openblas_get_corename", "scipy_openblas_get_corename64_", "scipy_openblas_get_corename",
                       "openblas_get_corename64_"):
            function = getattr(handle, symbol, None)
            if function is not None:
                function.restype = ctypes.c_char_p
                core = function().decode(errors="replace")
                break
        if core != "unknown":
            break
    return name, core


def _first_cpu() -> dict[str, str] | None:
    """The fields of the first processor in /proc/cpuinfo, or None where there is none (not Linux)."""
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    first = text.split("\n\n", 1)[0]
    return {k.strip(): v.strip() for k, _, v in (line.partition(":") for line in first.splitlines())}


def _flags(fields: dict[str, str]) -> frozenset[str]:
    return frozenset((fields.get("flags") or fields.get("Features") or "").split())


def cpu_flags() -> frozenset[str]:
    """The CPU's feature flags as /proc/cpuinfo names them (x86's "flags", aarch64's "Features"); empty where it
    cannot be read."""
    return _flags(_first_cpu() or {})


# OpenBLAS's kernels of AVX-512 code (OPENBLAS_CORETYPE values): on a CPU without avx512f, such as an AMD EPYC of the
# Zen 3 generation, they die of SIGILL.
AVX512_KERNELS = frozenset({"SkylakeX", "Cooperlake"})


def kernel_runs_here(core: str) -> bool:
    """Whether OpenBLAS's kernel `core` (an OPENBLAS_CORETYPE value) can run on this CPU."""
    return core not in AVX512_KERNELS or "avx512f" in cpu_flags()


def _cpu() -> tuple[str, str]:
    """The CPU's model name and whether it has FMA (glibc's libm picks FMA variants of exp, log, sin, pow by it)."""
    fields = _first_cpu()
    if fields is None:
        return platform.processor() or "unknown", "unknown"
    name = fields.get("model name") or fields.get("CPU part") or platform.processor() or "unknown"
    flags = _flags(fields)
    fma = "yes" if ("fma" in flags or "asimd" in flags) else "no"  # aarch64's Advanced SIMD always fuses
    return name, fma


def _compiler() -> str:
    """First line of `$CC --version` (the compiler the generated model is built with) and its target, or why there
    is none."""
    cc = os.environ.get("CC", "cc").split()[0]
    if shutil.which(cc) is None:
        return f"{cc}: not found"
    try:
        out = subprocess.run([cc, "--version"], capture_output=True, text=True, timeout=10).stdout
    except (OSError, subprocess.SubprocessError) as exc:
        return f"{cc}: {type(exc).__name__}"
    if not out.strip():
        return f"{cc}: no version"
    try:
        target = subprocess.run([cc, "-dumpmachine"], capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        target = ""
    return out.splitlines()[0].strip() + (f", target {target}" if target else "")


def gather() -> dict[str, str]:
    """The running platform's facts, each a string."""
    libc, libc_version = platform.libc_ver()
    if not libc and platform.system() == "Darwin":
        libc, libc_version = "libSystem macOS", platform.mac_ver()[0]
    blas, blas_core = _blas()
    cpu, cpu_fma = _cpu()
    facts = {
        "machine": platform.machine(),
        "cpu": cpu,
        "cpu_fma": cpu_fma,
        "os": f"{platform.system()} {platform.release()}",
        "libc": f"{libc or 'unknown'} {libc_version}".strip(),
        "python": platform.python_version(),
        "blas": blas,
        "blas_core": blas_core,
        "compiler": _compiler(),
    }
    facts.update({package: _version(package) for package in PACKAGES})
    return facts


def write(path: Path, facts: dict[str, str]) -> None:
    from ..tables import atomic_path

    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(facts, indent=2, sort_keys=True) + "\n", encoding="utf-8")


def read(path: Path) -> dict[str, str] | None:
    """The recorded facts, or None if there is no readable record."""
    path = Path(path)
    try:
        recorded = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):  # no record, or not one verification can read: said as "no record"
        return None
    return {str(k): str(v) for k, v in recorded.items()} if isinstance(recorded, dict) else None


def differences(recorded: dict[str, str] | None, running: dict[str, str]) -> list[str]:
    """'fact recorded -> running' for each fact that differs (the OS kernel release only if the OS differs)."""
    if recorded is None:
        return ["no record of the platform the sums were made on (figures/PLATFORM.json)"]
    lines = []
    for key in sorted(set(recorded) | set(running)):
        old, new = recorded.get(key, "not recorded"), running.get(key, "not known")
        if key == "os" and old.split()[:1] == new.split()[:1]:
            continue  # another kernel release of the same OS does not change arithmetic
        if old != new:
            lines.append(f"{key} {old} -> {new}")
    return lines
