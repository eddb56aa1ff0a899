"""The sweep's table, key numbers and torque maps: reproducible files whose numbers carry the physics."""

from __future__ import annotations

import json

import numpy as np
import pytest

from parksteer.model.codegen.cache import ensure_entry
from parksteer.model.symbolic.components import resolve_effects

from parksteer.figures.sweep import make_sweep_figure
from parksteer.sweep import SweepError, load_sweep
from parksteer.sweep.run import run_point
from parksteer.tables import read_csv

SMALL = """
name: small
base_case: unladen
axes:
  tyre.tyre_pressure: [122500, 245000]
  design.front_axle_load: [5576, 8500]
  design.extra_offset: [0.0, 0.0685]
braked: rig_theory
map: {x: tyre.tyre_pressure, y: design.front_axle_load, hold: {design.extra_offset: 0.0}, quantity: peak_torque_Nm}
assistance:
  rim_force: {value: 150, unit: N, source: "test: UN ECE R79 M1 intact steering"}
  rim_radius: {value: 0.19, unit: m, source: "test: typical rim"}
"""


@pytest.fixture(scope="module")
def small_sweep(params, tmp_path_factory):
    """Eight points of the multibody model, run through the point job's own code path."""
    root = tmp_path_factory.mktemp("sweep")
    declaration = root / "small.yaml"
    declaration.write_text(SMALL, encoding="utf-8")
    sweep = load_sweep(declaration, params)
    for effects in sweep.model_sets.values():  # what derive_model / sweep_model provide in the pipeline
        ensure_entry(resolve_effects(effects))
    points = []
    for point_id in sweep.point_ids:
        points.append(root / f"{point_id}.json")
        run_point(sweep.point_spec(point_id), params.path, points[-1])
    return root, declaration, points


def test_outputs_are_reproducible_and_complete(params, small_sweep):
    """Made twice, the SVG and CSV are byte-identical; the table has one row per point with the figures of
    merit, the mechanism shares and the assistance flag of each design. The shares summing to one is bookkeeping
    (the inertia share is the residual, so the contributions add up to the torque by construction): it checks
    that no mechanism's column is lost on the way to the table. The shares' physics (equation (2) in pressure and
    load, rack friction over the ratio) is tested in tests/test_sweep.py."""
    root, declaration, points = small_sweep
    for tag in ("a", "b"):
        make_sweep_figure(declaration, params, points, root / f"{tag}.svg", root / f"{tag}.csv", root / f"{tag}.json")
    assert (root / "a.svg").read_bytes() == (root / "b.svg").read_bytes()
    assert (root / "a.csv").read_bytes() == (root / "b.csv").read_bytes()
    columns, header = read_csv(root / "a.csv")
    assert len(columns["point"]) == 8
    shares = sum(columns[c] for c in columns if c.startswith("share_"))
    np.testing.assert_allclose(shares, 1.0, atol=1e-5, err_msg="bookkeeping: a mechanism's share column is missing")
    np.testing.assert_array_equal(columns["needs_assistance"], (columns["peak_torque_Nm"] > 28.5).astype(float))
    assert "28.5 N m" in header["assistance threshold"]


def test_summary_answers_the_design_questions(params, small_sweep):
    """At the test car the map finds the Table B1 point; doubling the pressure lowers the plateau; the spacer
    changes the free-rolling plateau only through lifting (under 10 %) but raises the braked one (rig-theory
    estimate) by far more; heavier and softer designs are the ones above the assistance threshold."""
    root, declaration, points = small_sweep
    summary = make_sweep_figure(declaration, params, points, root / "s.svg", root / "s.csv", root / "s.json")
    assert json.loads((root / "s.json").read_text())["n_points"] == 8
    design = summary["design_point"]
    assert design["on_design"] and design["values"]["design.front_axle_load"] == 5576.0
    pressure = summary["sensitivity"]["tyre.tyre_pressure"]
    assert pressure["ratio_plateau_torque_Nm"] < 0.8
    offset = summary["sensitivity"]["design.extra_offset"]
    assert 0.0 < offset["ratio_plateau_torque_Nm"] - 1.0 < 0.10
    assert offset["ratio_plateau_torque_braked_Nm"] - 1.0 > 2.0 * (offset["ratio_plateau_torque_Nm"] - 1.0)
    above = json.loads((root / "s.json").read_text())["assistance"]["points_above"]  # in the file only
    assert len(above) == summary["assistance"]["n_above"]
    assert above and all(p["values"]["design.front_axle_load"] == 8500.0 for p in above)
    assert all(p["values"]["tyre.tyre_pressure"] == 122500.0 for p in above)


def test_point_files_must_match_the_declaration(params, small_sweep):
    """Gathering fewer point files than the sweep declares is refused with one line, not a partial map."""
    root, declaration, points = small_sweep
    with pytest.raises(SweepError, match="do not match"):
        make_sweep_figure(declaration, params, points[:-1], root / "x.svg", root / "x.csv", root / "x.json")
    assert not (root / "x.svg").exists()


def test_map_points_and_test_car_lie_inside_the_axes(params, small_sweep, monkeypatch, tmp_path):
    """The torque map's grid points sit on its edges and the test car (1.225 bar, the lowest pressure) on one of
    them: every sweep point and the test-car star lie strictly inside the axes limits, so none is cut in half."""
    import parksteer.figures.sweep as sweep_figures

    root, declaration, points = small_sweep
    figures = []
    monkeypatch.setattr(sweep_figures, "save_svg", lambda fig, path: figures.append(fig))
    make_sweep_figure(declaration, params, points, tmp_path / "m.svg", tmp_path / "m.csv", tmp_path / "m.json")
    (fig,) = figures
    maps = [ax for ax in fig.axes if ax.collections and any(c.get_label() == "sweep points" for c in ax.collections)]
    assert maps
    for ax in maps:
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        shown = [c.get_offsets() for c in ax.collections if c.get_label() == "sweep points"]
        shown += [np.column_stack(line.get_data()) for line in ax.lines if line.get_label() == "test car"]
        xy = np.vstack(shown)
        assert np.all((xy[:, 0] > x0) & (xy[:, 0] < x1) & (xy[:, 1] > y0) & (xy[:, 1] < y1))
        assert any(line.get_label() == "test car" for line in ax.lines)
