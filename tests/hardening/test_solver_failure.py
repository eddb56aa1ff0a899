"""An integration the solver gives up on is one line naming the case, the values set and the time it failed at,
exit status 2, and no output written. The failures are real: the integrator is allowed only a few steps per
output, so it stops over its work budget (the generated integrator with its code 1, LSODA with 'Excess work done'),
as it does on a stiff set of values."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy.integrate import odeint as real_odeint

from parksteer.cli import main
from parksteer.model.numeric import prescribed, simulate
from parksteer.model.numeric.tolerances import solver_failure

from .corpus import _write, record_text


@pytest.fixture(scope="module", autouse=True)
def _paper_model_built():
    """The paper's model compiled before these tests, so that their one-line checks of stderr see the failure only
    and not a cold cache's derivation notes (whichever tests ran before)."""
    from parksteer.model.codegen.cache import ensure
    from parksteer.model.symbolic.components import resolve_effects

    ensure(resolve_effects(None))


@pytest.mark.filterwarnings("ignore::scipy.integrate.ODEintWarning")  # odeint called directly warns
def test_solver_failure_reports_the_last_time_reached():
    """odeint's own report of a starved stiff problem (Van der Pol, mu = 1000) becomes one line with the time
    the integrator reached, which lies inside the requested span."""
    def rhs(y, t):
        return [y[1], 1000.0 * (1 - y[0] ** 2) * y[1] - y[0]]

    t = np.linspace(0.0, 3000.0, 11)
    _, info = real_odeint(rhs, [2.0, 0.0], t, mxstep=50, full_output=True)
    assert "Excess work done" in info["message"]
    error = solver_failure("integration", info, t)
    assert "\n" not in str(error)
    assert 0.0 < error.t_failed_s < 3000.0
    assert re.search(r"failed at t = [0-9.e+-]+ s: more than [0-9,]+ integration steps per simulated second .*"
                     r"too stiff to integrate$", str(error))


def test_simulate_names_case_values_and_time(tmp_path, capsys, monkeypatch):
    """A saw-tooth run that the generated integrator abandons (three steps allowed per output): exit 2, one line
    naming case, effects, --set values and time."""
    monkeypatch.setattr(simulate, "max_steps", lambda t_out: 3)
    out = tmp_path / "out.csv"
    status = main(["simulate", "--case", "unladen", "--set", "tyre.tyre_pressure=180000", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    assert "case unladen (ground)" in err[0] and "tyre.tyre_pressure=180000" in err[0], err[0]
    assert re.search(r"integration failed at t = [0-9.e+-]+ s: more than [0-9,]+ integration steps", err[0]), err[0]
    assert not out.exists()


def test_rack_drive_failure_names_the_file(tmp_path, capsys, monkeypatch):
    """The same for a prescribed rack (three steps allowed per output): the line names the --rack-from file as
    well."""
    monkeypatch.setattr(prescribed, "max_steps", lambda t_out: 3)
    record = _write(tmp_path, "rec.csv", record_text())
    out = tmp_path / "out.csv"
    status = main(["simulate", "--rack-from", str(record), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    assert f"--rack-from {record}" in err[0] and "the parameter file's values" in err[0], err[0]
    assert "prescribed-rack integration failed at t = " in err[0], err[0]
    assert not out.exists()


def test_an_absurdly_stiff_tyre_is_refused_before_integrating(tmp_path, capsys):
    """The registry's bounds refuse a radial tyre stiffness of 1e16 N/m up front, naming the key and the range of
    real tyres, exit 2, nothing written."""
    out = tmp_path / "out.csv"
    status = main(["simulate", "--case", "unladen", "--set", "tyre.radial_stiffness=1e16", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    assert "tyre.radial_stiffness: value 1e+16 N/m is non-physical" in err[0] and "integrat" not in err[0], err[0]
    assert not out.exists()


def test_an_absurdly_stiff_tyre_fails_in_one_line_within_the_work_budget(tmp_path, capsys, monkeypatch):
    """No starving here: a radial tyre stiffness of 1e16 N/m (a car tyre has about 2e5; the registry's bounds,
    lifted here, refuse it) makes the bounce mode so
    stiff that an integration could run for minutes (LSODA did at 1e14, which the generated integrator follows in
    about 9 s); the work budget (tolerances.STEP_BUDGET_PER_S) stops it with one line naming the value, exit 2,
    nothing written. It stops early in the run, long before the 18 s cycle ends, because the budget is per
    simulated second."""
    import dataclasses
    import math
    from types import MappingProxyType

    from parksteer import parameters

    unbounded = dataclasses.replace(parameters.quantity("tyre.radial_stiffness"), upper=math.inf)
    monkeypatch.setattr(parameters, "FILE_AND_CASE_KEYS",
                        MappingProxyType({**parameters.FILE_AND_CASE_KEYS, "tyre.radial_stiffness": unbounded}))
    out = tmp_path / "out.csv"
    status = main(["simulate", "--case", "unladen", "--set", "tyre.radial_stiffness=1e16", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    assert "tyre.radial_stiffness=1e+16" in err[0] and "too stiff to integrate" in err[0], err[0]
    t_failed = float(re.search(r"failed at t = ([0-9.e+-]+) s", err[0]).group(1))
    assert 0.0 <= t_failed < 2.0
    assert not out.exists()


def test_the_work_budget_leaves_the_papers_runs_and_a_stiffer_tyre_alone():
    """The budget is far above what the model needs: the paper's cycle and a tyre fifty times stiffer than Appendix
    B's run through (their step counts are quoted in parksteer.model.numeric.tolerances)."""
    for overrides in ({}, {"tyre.radial_stiffness": 8e6}):
        columns = simulate.simulate("unladen", overrides=overrides).columns
        assert np.all(np.isfinite(columns["handwheel_torque_Nm"]))
