"""What importing the command line and the diagnosis costs: no heavy package is imported before it is used.

scipy.signal (with scipy.stats, which it imports) is more than a second of every process that imports it, sympy
seconds; a diagnosis needs neither (its decimation and running filters are written out in parksteer.portable), nor
scipy.interpolate (a second, with scipy.linalg, sparse and optimize: the rack smoothing's B-splines are written out
in parksteer.measure.bspline), nor scipy.special (half a second, with numpy.f2py and the array-API layer: the t
quantile and the chi-square survival of its intervals and signature are parksteer.portable.distributions'). The
command line's help needs no numpy at all, nor the package metadata (read for
``--version`` alone). These tests import in a fresh interpreter and read sys.modules.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
NEVER_AT_IMPORT = ("scipy", "sympy", "matplotlib")
NEVER_FOR_HELP = NEVER_AT_IMPORT + ("numpy", "importlib.metadata")
NEVER_IN_A_DIAGNOSIS = ("scipy.signal", "scipy.stats", "scipy.interpolate", "scipy.sparse", "scipy.linalg",
                        "scipy.optimize", "scipy.special", "sympy", "matplotlib")


def _loaded_after(code: str) -> list[str]:
    probe = code + "\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))\n"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _heavy(modules: list[str], packages: tuple[str, ...]) -> list[str]:
    return sorted({m for m in modules for p in packages if m == p or m.startswith(p + ".")})


def test_importing_the_command_line_and_the_diagnosis_imports_no_scipy_sympy_or_matplotlib():
    """The modules a `parksteer diagnose` process imports before it reads a record pull in none of the heavy
    packages: each is imported where it is first used."""
    modules = _loaded_after("import parksteer.cli, parksteer.commands.measure, parksteer.diagnose.select")
    assert _heavy(modules, NEVER_AT_IMPORT) == []


def test_help_of_diagnose_imports_no_numpy():
    """`parksteer diagnose --help` prints its options without importing numpy, scipy, sympy or matplotlib, or the
    package metadata: every subcommand's module imports its numerical layers where its command runs."""
    modules = _loaded_after("import contextlib, io\nfrom parksteer.cli import main\n"
                            "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
                            "    main(['diagnose', '--help'])")
    assert "parksteer.commands.measure" in modules  # the probe did build the diagnose parser
    assert _heavy(modules, NEVER_FOR_HELP) == []


def _resampled(source: Path, target: Path, factor: int) -> None:
    """`source` (a measurement CSV) linearly interpolated onto a grid `factor` times finer, header kept."""
    lines = source.read_text().splitlines()
    header = [line for line in lines if line.startswith("#")]
    names = lines[len(header)].split(",")
    data = np.loadtxt(lines[len(header) + 1:], delimiter=",")
    time_s = np.linspace(data[0, 0], data[-1, 0], (len(data) - 1) * factor + 1)
    columns = [time_s] + [np.interp(time_s, data[:, 0], data[:, j]) for j in range(1, data.shape[1])]
    body = "\n".join(",".join(repr(float(v)) for v in row) for row in np.column_stack(columns))
    target.write_text("\n".join(header + [",".join(names), body]) + "\n")


@pytest.mark.slow
def test_a_diagnosis_of_a_decimated_record_never_imports_scipy_signal_stats_or_sympy(tmp_path):
    """The README's example record at five times its rate (so decimated to the method's rate on import), diagnosed
    from start to verdict (its rack smoothed, with the replay ensemble's racks), imports neither scipy.signal nor
    scipy.stats nor scipy.interpolate (nor the scipy.linalg, sparse and optimize it brings) nor scipy.special
    (its intervals' t quantile and its signature's p-values included) nor sympy nor matplotlib."""
    from parksteer.measure.importers import load_record

    record = tmp_path / "example_250Hz.csv"
    _resampled(ROOT / "data" / "measurements" / "example_unladen.csv", record, 5)
    assert "decimated" in load_record(record).metadata  # the path that used scipy.signal is taken
    modules = _loaded_after("import contextlib, io\nfrom parksteer.cli import main\n"
                            "with contextlib.redirect_stdout(io.StringIO()):\n"
                            f"    main(['diagnose', {str(record)!r}, '--json', '--quiet', '--jobs', '1'])")
    assert "parksteer.diagnose.select" in modules
    assert _heavy(modules, NEVER_IN_A_DIAGNOSIS) == []


@pytest.mark.slow
def test_a_diagnosis_written_as_json_alone_imports_no_page_renderer():
    """The README's example diagnosed with `--json` alone (no report, no page) imports neither the pages' renderer
    (parksteer.reporting.pages) nor the standard library's html (with its table of entities): they are imported
    where a report or a page is written."""
    record = ROOT / "data" / "measurements" / "example_unladen.csv"
    modules = _loaded_after("import contextlib, io\nfrom parksteer.cli import main\n"
                            "with contextlib.redirect_stdout(io.StringIO()):\n"
                            f"    main(['diagnose', {str(record)!r}, '--json', '--quiet', '--jobs', '1'])")
    assert "parksteer.reporting.report" in modules  # the JSON was made
    assert _heavy(modules, ("parksteer.reporting.pages", "html")) == []


def test_planning_the_workflow_and_loading_the_example_effect_imports_no_sympy_or_scipy():
    """What Snakemake computes from the package while it reads the workflow (parksteer.plan.diagnosis: the candidate
    models, the example user effect among them, and the benchmarks' cases) imports neither sympy nor scipy, and
    neither does a replaying process that loads the example effect (src/parksteer/examples/column_imbalance.py takes
    sympy lazily, as the package's own effects do): the example is a candidate in every benchmark job."""
    example = "src/parksteer/examples/column_imbalance.py"
    modules = _loaded_after(
        "import yaml\nfrom parksteer import plan\n"
        "config = yaml.safe_load(open('config/config.yaml', encoding='utf-8'))\n"
        "sections = {k: config[k] for k in ('car', 'benchmark', 'outclass', 'variations', 'signature')}\n"
        f"planned = plan.diagnosis(sections, config['parameters'], {example!r})\n"
        "assert 'with_column_imbalance' in planned['candidates'], planned['candidates']\n"
        "from parksteer.model.symbolic.components import load_effect_module\n"
        f"assert load_effect_module({example!r}).quantities")
    assert _heavy(modules, ("sympy", "scipy")) == []
