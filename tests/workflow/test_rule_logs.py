"""Rule logs and progress: each rule's log says what the job computed, how long it took and its key numbers; the
model's derivation reports its stages on stderr, and `parksteer derive --quiet` silences them."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from parksteer.cli import main
from parksteer.errors import UsageError
from parksteer.progress import note, set_quiet
from parksteer.rules import rule_log


class _Wildcards(dict):
    """Snakemake's wildcards: named values with items()."""


def _job(tmp_path: Path, outputs: list[str], **wildcards) -> SimpleNamespace:
    return SimpleNamespace(rule="figX", wildcards=_Wildcards(wildcards), log=[str(tmp_path / "job.log")],
                           input=[str(tmp_path / "a.toml"), str(tmp_path / "b.py")],
                           output=[str(tmp_path / o) for o in outputs])


def test_rule_log_records_start_progress_outputs_numbers_and_time(tmp_path, monkeypatch):
    """The log holds, in order: the job (rule and wildcards) and its input count; the progress the code printed;
    the job's time; each output with its size on disk, a missing output named as not written; and the numbers of a
    JSON output with the values that were written."""
    monkeypatch.setattr(sys, "stderr", sys.stderr)  # rule_log redirects stderr for the rest of a rule's process
    job = _job(tmp_path, ["out.json", "out.csv", "never.svg"], figure="fig12")
    with rule_log(job):
        note("computing the curve")
        (tmp_path / "out.json").write_text(json.dumps({"peak_torque_Nm": 31.25, "label": "x",
                                                       "per_case": {"unladen": 2.5e-3}}), encoding="utf-8")
        (tmp_path / "out.csv").write_text("a,b\n" + "1,2\n" * 600, encoding="utf-8")
    lines = (tmp_path / "job.log").read_text(encoding="utf-8").splitlines()
    assert lines[0] == "figX figure=fig12: started, 2 input files"
    assert lines[1] == "computing the curve"
    assert re.fullmatch(r"figX figure=fig12: finished after \d+\.\d\d s", lines[2])
    csv_kib = (tmp_path / "out.csv").stat().st_size / 1024
    assert f"  {tmp_path / 'out.csv'}: {csv_kib:.1f} KiB" in lines
    assert f"  {tmp_path / 'never.svg'}: not written" in lines
    assert "    peak_torque_Nm = 31.25" in lines and "    per_case.unladen = 0.0025" in lines
    assert not any("label" in line for line in lines)  # only numbers are key numbers


def test_rule_log_ends_a_usage_error_with_one_line(tmp_path, monkeypatch):
    """A user error ends the job with exit status 1 and one error line naming the rule, no traceback; the job is
    logged as failed, not finished."""
    monkeypatch.setattr(sys, "stderr", sys.stderr)
    job = _job(tmp_path, ["out.json"])
    with pytest.raises(SystemExit) as ended:
        with rule_log(job):
            raise UsageError("data/x.toml: key tyre.radius_m: must be positive")
    assert ended.value.code == 1
    text = (tmp_path / "job.log").read_text(encoding="utf-8")
    assert "figX: error: data/x.toml: key tyre.radius_m: must be positive\n" in text
    assert re.search(r"^figX: failed after \d+\.\d\d s$", text, re.MULTILINE)
    assert "finished" not in text and "Traceback" not in text


def test_a_failing_job_names_its_cause_on_the_terminal(tmp_path, monkeypatch, capsys):
    """Snakemake reports a failed job by its log file's path only: the cause (a user error, or the exception that
    ended the job, such as a module that is not installed) is also one line on the terminal's stderr, naming the
    job; the traceback stays in the log."""
    terminal = sys.stderr
    monkeypatch.setattr(sys, "stderr", terminal)
    job = _job(tmp_path, ["out.json"], batch="peers_00")
    with pytest.raises(ModuleNotFoundError):
        with rule_log(job):
            raise ModuleNotFoundError("No module named 'pysindy'")
    assert capsys.readouterr().err.strip().splitlines() == [f"parksteer: figX batch=peers_00: ModuleNotFoundError: No module named 'pysindy' "
                        f"(traceback in {tmp_path / 'job.log'})"]
    monkeypatch.setattr(sys, "stderr", terminal)
    with pytest.raises(SystemExit):
        with rule_log(_job(tmp_path, ["out.json"])):
            raise UsageError("data/x.toml: key tyre.radius_m: must be positive")
    assert capsys.readouterr().err.strip() == "parksteer: figX: error: data/x.toml: key tyre.radius_m: must be positive"


def test_every_rule_script_logs_through_rule_log(repo_root):
    """Each rule script under workflow/scripts runs its work inside rule_log, so no rule's log stays empty."""
    scripts = sorted((repo_root / "workflow" / "scripts").glob("*.py"))
    assert scripts
    bare = [p.name for p in scripts if "with rule_log(snakemake)" not in p.read_text(encoding="utf-8")]
    assert bare == []


@pytest.mark.slow  # builds a model of its own: started early, so that the workers end together
def test_derive_reports_each_stage_and_quiet_silences_it(tmp_path, monkeypatch, capsys):
    """A cold `parksteer derive` names each stage on stderr (derivation with its coordinates, generated C, the
    runtime's one compile on an empty cache, the compilation) with the numbers the cache entry records; a second call finds it in the cache; --quiet prints
    nothing on stderr and still answers on stdout. The smallest effect set (rack friction alone) keeps it short."""
    monkeypatch.setenv("PARKSTEER_MODEL_CACHE", str(tmp_path / "cache"))
    effects = "--effects=-carcass_compliance,-hooke_joint,-lifting,-tyre_friction"
    try:
        assert main(["derive", effects, "--out", str(tmp_path / "m.json")]) == 0
        err = capsys.readouterr().err
        manifest = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
        source = (Path(manifest["directory"]) / "model.c").read_text(encoding="utf-8")
        stages = [line.split(":")[0] for line in err.splitlines()]
        assert stages[:3] == ["deriving the model of rack_friction (sympy Kane's method) ...", "derived",
                              "generated C"], err
        # an empty cache compiles the models' runtime once, before the model's own C
        assert stages[3].startswith("compiling the models' runtime, once for this cache and compiler"), err
        assert stages[4].startswith("compiled with ") and stages[5:] == ["model of rack_friction"], err
        assert f"derived: {len(manifest['coordinates'])} coordinates ({', '.join(manifest['coordinates'])}), " \
               f"{manifest['n_parameters']} parameters" in err
        assert f"generated C: {source.count(chr(10))} lines" in err
        assert "built into the cache" in err
        assert main(["derive", effects]) == 0
        assert "found in the cache" in capsys.readouterr().err
        assert main(["derive", effects, "--quiet"]) == 0
        out, err = capsys.readouterr()
        assert err == "" and out.startswith("cached rack_friction")
    finally:
        set_quiet(False)
