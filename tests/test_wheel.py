"""The package works installed from its wheel, away from the repository.

Builds the wheel from a copy of the sources, installs it without dependencies into a fresh virtual environment
outside the repository (its dependencies come from this environment through a .pth file; a plain directory in a
.pth file does not run that directory's own .pth files, so this environment's editable parksteer stays off), and
runs `effects`, `simulate` and `compare` from an empty directory. Any file the package still read from the
checkout (data, schemas, the example effect, the model cache) would fail here.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.slow


def run(cmd: list[str], cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess:
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, f"{' '.join(map(str, cmd))} failed ({done.returncode}):\n{done.stdout[-2000:]}\n{done.stderr[-4000:]}"
    return done


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """A fresh virtual environment (outside the repository) with the wheel installed; its bin/ and an env."""
    base = tmp_path_factory.mktemp("wheel")
    assert not base.resolve().is_relative_to(REPO_ROOT)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}

    # Build from a copy, so the build leaves nothing (build/, *.egg-info) in the checkout.
    source = base / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(REPO_ROOT / name, source / name)
    shutil.copytree(REPO_ROOT / "src", source / "src",
                    ignore=shutil.ignore_patterns("__pycache__", "*.egg-info", "*.so"))
    dist = base / "dist"
    run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index", "-w", str(dist),
         str(source)], cwd=base, env=env)
    (wheel,) = dist.glob("parksteer-*.whl")

    venv = base / "venv"
    run([sys.executable, "-m", "venv", "--without-pip", str(venv)], cwd=base, env=env)
    python = venv / "bin" / "python"
    site = Path(run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                    cwd=base, env=env).stdout.strip())
    parents = dict.fromkeys(sysconfig.get_paths()[key] for key in ("purelib", "platlib"))
    (site / "dependencies_from_parent.pth").write_text("".join(f"{p}\n" for p in parents))
    # --ignore-installed: never touch the parent environment's (editable) parksteer that pip can see.
    run([str(python), "-m", "pip", "install", "--no-deps", "--no-index", "--ignore-installed", "--no-compile",
         str(wheel)], cwd=base, env=env)

    env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env["PARKSTEER_MODEL_CACHE"] = str(base / "model-cache")
    work = base / "work"
    work.mkdir()
    return venv, env, work


def test_the_wheel_is_what_runs(installed):
    """The imported parksteer is the wheel's copy in the new environment, and it takes no checkout for its home."""
    venv, env, work = installed
    env = {k: v for k, v in env.items() if k != "PARKSTEER_MODEL_CACHE"}
    probe = ("import parksteer, parksteer.resources as r; from parksteer.model.codegen import cache; "
             "print(parksteer.__file__); print(r.data_file('parameters.toml')); print(cache.cache_root())")
    file, data, cache_root = run([str(venv / "bin" / "python"), "-c", probe], cwd=work, env=env).stdout.split("\n")[:3]
    assert Path(file).resolve().is_relative_to(venv.resolve()), file
    assert Path(data).resolve().is_relative_to(venv.resolve()) and Path(data).is_file(), data
    # An installed wheel caches models in the user's cache, never beside its source or in a repository.
    assert not Path(cache_root).resolve().is_relative_to(venv.resolve()), cache_root
    assert not Path(cache_root).resolve().is_relative_to(REPO_ROOT), cache_root


def test_effects_simulate_and_compare_run_from_the_wheel(installed):
    venv, env, work = installed
    parksteer = str(venv / "bin" / "parksteer")
    listing = run([parksteer, "effects"], cwd=work, env=env).stdout
    assert "tyre_friction" in listing and "column_friction" in listing

    run([parksteer, "simulate", "--case", "unladen", "--out", "x.csv"], cwd=work, env=env)
    header = (work / "x.csv").read_text().splitlines()
    assert len([line for line in header if not line.startswith("#")]) > 100
    assert list(Path(env["PARKSTEER_MODEL_CACHE"]).iterdir()), "the model was not cached where it was told"

    measured = work / "example_unladen.csv"
    shutil.copy2(REPO_ROOT / "data" / "measurements" / "example_unladen.csv", measured)
    report = run([parksteer, "compare", str(measured)], cwd=work, env=env)
    assert "RMS" in report.stdout or "rms" in report.stdout.lower(), report.stdout[-2000:]


def test_an_assisted_replays_inversion_compiles_from_the_wheel(installed):
    """The assisted replay's torsion-bar inversion is C shipped beside the package's Python
    (model/numeric/torsion_bar.c, package data): installed from the wheel, the first inversion compiles it into the
    model cache and solves T + A(T) = y (here a valve of gain 4e5 Pa per N m on 8 cm^2 at G_hr 150: T well below y)."""
    venv, env, work = installed
    probe = ("import numpy as np; from parksteer.model.numeric.assisted import BoostLaw; "
             "law = BoostLaw('hydraulic_assist', 'rack', 4e5, 0.3, 0.05, 7e6, 1e5, 150.0, area=8e-4); "
             "print(law.torsion_bar(np.array([5.0]))[0])")
    torque = float(run([str(venv / "bin" / "python"), "-c", probe], cwd=work, env=env).stdout)
    assert 0.3 < torque < 5.0
    assert list((Path(env["PARKSTEER_MODEL_CACHE"]) / "runtime").glob("torsion_bar-*.so"))
