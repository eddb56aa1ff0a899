"""Design sweeps: declaration and expansion, design variables, figures of merit, physics of a tiny grid,
the point job's no-derivation guarantee and the SLURM profile's dry run."""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from parksteer.errors import UsageError
from parksteer.geometry import lock_steer_angle, steer_axis
from parksteer.model.numeric.simulate import with_overrides
from parksteer.sweep import SweepError, load_sweep
from parksteer.sweep.aggregate import threshold_crossings
from parksteer.sweep.design import point_overrides
from parksteer.sweep.merit import figures_of_merit
from parksteer.sweep.run import simulate_point

EXAMPLE = "config/sweeps/design.yaml"


def _write(tmp_path: Path, text: str, name: str = "s.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


GRID = """
name: grid
base_case: unladen
axes:
  tyre.tyre_pressure: {start: 120000, stop: 300000, num: 3}
  design.front_axle_load: [5576, 7000]
  steering.rack_friction_force: [500, 730]
"""


# ---------------------------------------------------------------------------- declaration


def test_grid_is_the_full_factorial_with_stable_ids(tmp_path, params):
    """A 3 x 2 x 2 grid gives 12 points, first axis slowest; the ids hash what each point simulates, so they
    are identical when the file is read again and when the axes are declared in another order, and extending
    an axis adds points without changing the ids of the existing ones."""
    sweep = load_sweep(_write(tmp_path, GRID), params)
    assert len(sweep.points) == 12
    assert [p.values["tyre.tyre_pressure"] for p in sweep.points[:4]] == [120000.0] * 4
    assert [p.values["steering.rack_friction_force"] for p in sweep.points[:2]] == [500.0, 730.0]
    assert sweep.points[5].values == {"tyre.tyre_pressure": 210000.0, "design.front_axle_load": 5576.0,
                                      "steering.rack_friction_force": 730.0}
    ids = sweep.point_ids
    assert len(set(ids)) == 12 and all(len(i) == 10 and int(i, 16) >= 0 for i in ids)
    assert load_sweep(_write(tmp_path, GRID, "again.yaml"), params).point_ids == ids
    reordered = GRID.replace("  tyre.tyre_pressure: {start: 120000, stop: 300000, num: 3}\n", "") + \
        "  tyre.tyre_pressure: [120000, 210000, 300000]\n"
    assert set(load_sweep(_write(tmp_path, reordered, "r.yaml"), params).point_ids) == set(ids)
    extended = GRID.replace("[500, 730]", "[500, 600, 730]")
    assert set(ids) < set(load_sweep(_write(tmp_path, extended, "e.yaml"), params).point_ids)


def test_full_switch_and_declared_points(tmp_path, params):
    """The shipped example has 48 points and a 240-point full version; a declared list runs exactly its points."""
    example = load_sweep(EXAMPLE, params)
    assert len(example.points) == 48
    assert len(load_sweep(EXAMPLE, params, full=True).points) == 240
    listed = load_sweep(_write(tmp_path, """
name: listed
base_case: unladen
points:
  - {tyre.tyre_pressure: 150000}
  - {tyre.tyre_pressure: 250000, design.extra_offset: 0.02}
"""), params)
    assert [p.values for p in listed.points] == [{"tyre.tyre_pressure": 150000.0},
                                                {"tyre.tyre_pressure": 250000.0, "design.extra_offset": 0.02}]


@pytest.mark.parametrize("body, key", [
    ("axes: {tyre.tyre_presure: [2.0e+5]}", "tyre.tyre_presure"),
    ("axes: {tyre.tyre_pressure: [2.0e+5, -1]}", "axes.tyre.tyre_pressure[1]"),
    ("axes: {tyre.tyre_pressure: []}", "axes.tyre.tyre_pressure"),
    ("axes: {tyre.tyre_pressure: {start: 1.0e+5, stop: 2.0e+5, num: 0}}", "axes.tyre.tyre_pressure.num"),
    ("axes: {design.front_axle_load: [6000], case.load_left: [3000]}", "case.load_left"),
    ("axes: {design.steering_ratio: [500]}", "axes.design.steering_ratio[0]"),
    ("axes: {design.front_axle_load: [1500], vehicle.unsprung_mass: [200]}", "design.front_axle_load"),
    ("effects: '-rack_friction'\naxes: {rack_lash.lash: [0.0002]}", "rack_lash"),
    ("axes: {tyre.tyre_pressure: [2.0e+5]}\ncolour: blue", "colour"),
    ("axes: {tyre.tyre_pressure: [2.0e+5]}\nbraked: handbrake", "braked"),
    ("axes: {tyre.tyre_pressure: [2.0e+5]}\nsurface: air_bearing\nbraked: braked_wheels", "braked"),
    ("axes: {tyre.tyre_pressure: [2.0e+5]}\neffects: '-tyre_friction'\nbraked: rig_theory", "braked"),
    ("axes: {tyre.tyre_pressure: [2.0e+5]}\nmap: {x: tyre.tyre_pressure, y: case.chassis_mass, quantity: "
     "peak_torque_Nm}", "map.y"),
])
def test_invalid_declarations_fail_with_one_line_naming_file_and_key(tmp_path, params, body, key):
    """Unknown parameter, out-of-bounds value, empty axis, bad grid, conflicting keys, an effect not in the model,
    an unknown field, a braked comparison that cannot be made, a map over a key that is not swept: each is one
    line naming the file and the key."""
    path = _write(tmp_path, f"name: bad\nbase_case: unladen\n{body}\n")
    with pytest.raises(SweepError) as info:
        load_sweep(path, params)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path)) and key in message


BAR = "name: bar\nbase_case: unladen\naxes: {tyre.tyre_pressure: [1.2, 2.0]}\n"  # pressures in bar, not Pa


@pytest.mark.parametrize("body, key", [
    ("axes: {}", "axes"),
    ("axes: {tyre.pressure_bar: [2.0]}", "tyre.pressure_bar"),
    ("effects: '+no_such_effect'\naxes: {tyre.tyre_pressure: [2.0e+5]}", "no_such_effect"),
    ("axes: {tyre.tyre_pressure: [1.2, 2.0]}", "axes.tyre.tyre_pressure[0]"),
    ("axes: {tyre.tyre_pressure: [2.0e+5]}\nfull_axes: {design.front_axle_load: [1500], vehicle.unsprung_mass: [200]}",
     "full_axes point 0"),
])
def test_declarations_the_dag_build_refuses(tmp_path, params, body, key):
    """What `--config sweep=...` may name and the DAG build must refuse, each in one line naming the file and the
    key: empty axes, an unknown axis, an unknown effect, a pressure given in bar (1.2 Pa is below the registry's
    1e4 Pa), and a point of the unselected full sweep whose derived quantities are unphysical (a front axle
    load below the unsprung weight leaves a negative chassis mass)."""
    path = _write(tmp_path, f"name: bad\nbase_case: unladen\n{body}\n")
    with pytest.raises(SweepError) as info:
        load_sweep(path, params)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path)) and key in message


def test_a_missing_declaration_is_one_line(tmp_path, params):
    """A sweep file that does not exist is refused in one line naming it."""
    missing = tmp_path / "nowhere.yaml"
    with pytest.raises(SweepError, match="nowhere.yaml: cannot read") as info:
        load_sweep(missing, params)
    assert "\n" not in str(info.value)


def test_sweep_expand_refuses_a_pressure_in_bar_with_exit_status_2(tmp_path):
    """`parksteer sweep expand` checks every value against the registry's bounds: exit status 2, one line on
    stderr naming the file and the axis, nothing on stdout."""
    path = _write(tmp_path, BAR)
    done = subprocess.run([str(Path(sys.executable).with_name("parksteer")), "sweep", "expand", str(path)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [f"parksteer sweep: error: {path}: axes.tyre.tyre_pressure[0]: 1.2 Pa is out "
                                        "of bounds [10000, 1e+06]"]


def test_the_dag_build_refuses_a_bad_sweep_in_one_line(repo_root, tmp_path):
    """`snakemake --config sweep=bad.yaml` stops while the DAG is built: exit status 2, exactly one error line
    naming the file and the axis, no traceback, no job started (nothing under results/ or logs/ of the
    working directory). load_sweep's refusals above are the ones this line reports."""
    path = _write(tmp_path, BAR)
    work = tmp_path / "work"
    work.mkdir()
    for name in ("config", "src", "workflow"):
        (work / name).symlink_to(repo_root / name)
    done = subprocess.run([str(Path(sys.executable).with_name("snakemake")), "--cores", "1", "--directory",
                           str(work), "--snakefile", str(repo_root / "workflow" / "Snakefile"), "sweep_design",
                           "--config", f"sweep={path}"], capture_output=True, text=True, timeout=300)
    out = done.stdout + done.stderr
    assert done.returncode == 2, out[-2000:]
    errors = [line for line in out.splitlines() if "error" in line.lower()]
    assert errors == [f"parksteer: error: {path}: axes.tyre.tyre_pressure[0]: 1.2 Pa is out of bounds [10000, 1e+06]"]
    assert "Traceback" not in out and "SweepError" not in out
    assert not (work / "results").exists() and not (work / "logs").exists()


# ---------------------------------------------------------------------------- batches


def _listed(tmp_path, pressures, name):
    lines = "".join(f"  - {{tyre.tyre_pressure: {p}}}\n" for p in pressures)
    return _write(tmp_path, f"name: listed\nbase_case: unladen\npoints:\n{lines}", name)


def test_batches_partition_the_points_and_a_new_point_reruns_only_its_batch(tmp_path, params):
    """Every point is in exactly one batch; adding a point (here one whose id is not a boundary) changes exactly
    one batch (the one it joins: new id, old members plus it) and leaves every other batch, id and members, as it
    was; removing one changes one old batch. At batch size 1 every point is its own batch; over 2,000 points
    batches average about the asked size and none exceeds the cap."""
    pressures = list(range(100000, 500000, 2000))  # 200 points
    sweep = load_sweep(_listed(tmp_path, pressures, "a.yaml"), params)
    batches = sweep.batches(8)
    members = [p for points in batches.values() for p in points]
    assert sorted(members) == sorted(sweep.point_ids)
    grown = load_sweep(_listed(tmp_path, pressures + [123457], "b.yaml"), params).batches(8)
    new_id = (set(load_sweep(_listed(tmp_path, pressures + [123457], "b.yaml"), params).point_ids)
              - set(sweep.point_ids)).pop()
    assert int(new_id, 16) % 8  # not a boundary: it joins a batch rather than splitting one
    changed_old, changed_new = set(batches) - set(grown), set(grown) - set(batches)
    assert len(changed_old) == 1 and len(changed_new) == 1
    assert set(grown[changed_new.pop()]) == set(batches[changed_old.pop()]) | {new_id}
    from parksteer.sweep.expansion import point_id

    boundary = next(q for q in range(123001, 124000, 2)
                    if int(point_id("unladen", None, "ground", {"tyre.tyre_pressure": float(q)}), 16) % 8 == 0)
    split = load_sweep(_listed(tmp_path, pressures + [boundary], "s.yaml"), params).batches(8)
    old_batch, new_batches = set(batches) - set(split), set(split) - set(batches)
    assert len(old_batch) == 1 and len(new_batches) == 2  # a boundary point splits the one batch it falls in
    assert set().union(*(split[b] for b in new_batches)) - set(batches[old_batch.pop()]) == {
        point_id("unladen", None, "ground", {"tyre.tyre_pressure": float(boundary)})}
    shrunk = load_sweep(_listed(tmp_path, pressures[1:], "c.yaml"), params).batches(8)
    assert len(set(batches) - set(shrunk)) == 1 and len(set(shrunk) - set(batches)) <= 1
    assert all(len(points) == 1 for points in sweep.batches(1).values()) and len(sweep.batches(1)) == 200
    ids = [hashlib.sha256(str(k).encode()).hexdigest()[:10] for k in range(2000)]  # uniform, as point ids are
    from parksteer.sweep.expansion import batch_points

    sizes = [len(points) for points in batch_points(ids, 25).values()]
    assert sum(sizes) == 2000 and max(sizes) <= 75 and 15 <= 2000 / len(sizes) <= 40


def test_a_large_sweep_is_cut_into_a_bounded_number_of_batches_and_a_small_one_as_before(monkeypatch):
    """The scheduler's cost grows with the number of batch jobs, so beyond MAX_BATCHES x the batch size points the
    batch size doubles until the points fit in about MAX_BATCHES batches; a sweep up to that size is cut exactly as
    at the plain batch size (same batches, same ids: its results stay valid), and the grown size is a power-of-two
    multiple of the asked one (its natural boundaries a subset of the plain size's)."""
    from parksteer.sweep import expansion
    from parksteer.sweep.expansion import batch_points, effective_batch_size

    ids = [hashlib.sha256(str(k).encode()).hexdigest()[:10] for k in range(2000)]  # uniform, as point ids are
    plain = batch_points(ids, 25)  # 2,000 points <= 4,096 x 25: the plain size
    assert effective_batch_size(2000, 25) == 25 and effective_batch_size(4096 * 50, 50) == 50
    assert effective_batch_size(4096 * 50 + 1, 50) == 100 and effective_batch_size(10**6, 50) == 400
    monkeypatch.setattr(expansion, "MAX_BATCHES", 80)  # 2,000 points = 80 x 25: still the plain size
    assert batch_points(ids, 25) == plain
    monkeypatch.setattr(expansion, "MAX_BATCHES", 20)  # 2,000 > 20 x 25 x 2: cut at 100 points a batch
    grown = batch_points(ids, 25)
    monkeypatch.setattr(expansion, "MAX_BATCHES", 10**6)
    assert grown == batch_points(ids, 100)
    assert sorted(p for points in grown.values() for p in points) == sorted(ids)
    assert 10 <= len(grown) <= 1.25 * 20 and len(plain) > 60  # about n / size: fewer only where a batch is capped


def test_a_batch_writes_the_records_its_points_give_alone(tmp_path, params):
    """The batch job's records are, point for point, the records of the single-point job (same simulation, same
    rounding): batching changes where the work runs, not its result."""
    from parksteer.sweep.run import run_batch, run_point

    sweep = load_sweep(_listed(tmp_path, [150000, 250000], "two.yaml"), params)
    (batch_id, points), = sweep.batches(100).items()
    out = run_batch(sweep.batch_spec(batch_id, 100), params.path, tmp_path / "batch.json")
    saved = json.loads((tmp_path / "batch.json").read_text(encoding="utf-8"))
    assert saved["points"] == list(points) == sorted(points) and len(saved["records"]) == 2
    for record in saved["records"]:
        run_point(sweep.point_spec(record["point"]), params.path, tmp_path / "point.json")
        assert json.loads((tmp_path / "point.json").read_text(encoding="utf-8")) == record
    assert [r["point"] for r in out["records"]] == saved["points"]


def test_point_ids_in_bulk_are_point_id_of_each_point():
    """The bulk hashing (pieces kept per key and value) gives each point the id point_id gives it alone, signed
    zeros, mixed key sets and keys out of order included."""
    from parksteer.sweep.expansion import point_id, point_ids

    values = [{"tyre.tyre_pressure": 122500.0, "design.front_axle_load": 5576.0},
              {"design.front_axle_load": 5576.0, "tyre.tyre_pressure": 122500.0},
              {"design.castor_angle": 0.0}, {"design.castor_angle": -0.0}, {"design.castor_angle": 0.1},
              {"design.castor_angle": -0.0, "tyre.tyre_pressure": 1.0e5}, {"design.castor_angle": 0.1}]
    for effects, surface in ((None, "ground"), ("default,+my/effect.py", "air_bearing")):
        assert point_ids("unladen", effects, surface, values) == [point_id("unladen", effects, surface, v)
                                                                  for v in values]
    assert point_id("unladen", None, "ground", {"design.castor_angle": 0.0}) != \
        point_id("unladen", None, "ground", {"design.castor_angle": -0.0})


@pytest.mark.parametrize("declaration", ["grid", "listed"])
def test_a_batch_job_reads_from_the_batch_index_the_spec_the_sweep_gives(tmp_path, params, declaration):
    """Each batch's spec read from the batch index (what the batch job runs) equals Sweep.batch_spec; a job that
    finds no index writes it; an index that no longer matches its batch is refused, not run."""
    from parksteer.sweep.batch_index import batch_index_path, batch_spec_from_index, write_batch_index

    path = _write(tmp_path, GRID) if declaration == "grid" else _listed(tmp_path, range(100000, 300000, 7000), "l.yaml")
    sweep = load_sweep(path, params)
    index_dir = tmp_path / "index"
    assert not batch_index_path(index_dir, path, False, 4).exists()
    for batch in sweep.batches(4):  # the first call writes the index
        assert batch_spec_from_index(path, params.path, False, 4, batch, sweep.shared_spec, index_dir) == \
            sweep.batch_spec(batch, 4)
    index = write_batch_index(sweep, 4, index_dir)
    assert index == batch_index_path(index_dir, path, False, 4) and len(index.read_text().splitlines()) == \
        len(sweep.batches(4))
    first, second = sorted(sweep.batches(4))[:2]
    lines = index.read_text().splitlines()
    index.write_text("\n".join([f"{first} {lines[1].split(' ', 1)[1]}", *lines[1:]]) + "\n")
    with pytest.raises(SweepError, match="does not match the declaration"):
        batch_spec_from_index(path, params.path, False, 4, first, sweep.shared_spec, index_dir)
    with pytest.raises(SweepError, match="no batch"):
        batch_spec_from_index(path, params.path, False, 4, "0123456789", sweep.shared_spec, index_dir)


def test_the_streamed_gathering_writes_what_all_records_in_memory_give(tmp_path, params):
    """gather_points, reading batch files in any order with the sweep unexpanded (each record's index found from
    its values, checked against its id), writes the table sweep_table and write_csv give from every record in
    memory, and the summary (points above the threshold streamed from a scratch file) that summarise gives from
    every record, byte for byte; a missing point is named, a record of another sweep or one gathered twice
    refused."""
    from parksteer.sweep.aggregate import summarise
    from parksteer.sweep.gathering import gather_points
    from parksteer.sweep.records import read_points, sweep_table
    from parksteer.tables import write_csv, write_json

    text = GRID + ("map: {x: tyre.tyre_pressure, y: design.front_axle_load, panels: steering.rack_friction_force,\n"
                   "      quantity: peak_torque_Nm}\n"
                   "assistance:\n  rim_force: {value: 150, unit: N, source: test}\n"
                   "  rim_radius: {value: 0.2, unit: m, source: test}\n")
    path = _write(tmp_path, text)
    sweep = load_sweep(path, params)
    streamed = load_sweep(path, params, expand=False)
    assert not streamed.points and streamed.n_points == len(sweep.points) == 12
    files = []
    for k, (batch, members) in enumerate(sorted(sweep.batches(3).items())):
        records = []
        for m in members:
            point = sweep.point(m)
            merits = {"peak_torque_Nm": 20.0 + point.index, "plateau_torque_Nm": 18.0, "lock_torque_Nm": 19.0,
                      "reversal_drop_Nm": 9.0, "sliding_start_rack_m": 0.02, "share_contrib_lifting_Nm": 0.1}
            if point.index % 5 == 3:  # a share that some points have: its column joins where it first shows
                merits["share_contrib_rack_friction_Nm"] = 0.3
            records.append({"point": m, "effects": ["lifting"], "values": point.values, "merits": merits,
                            "braked": {"method": "none", "factor": math.nan, "ground_offset_m": math.nan,
                                       "plateau_torque_Nm": math.nan, "peak_torque_Nm": math.nan,
                                       "lock_torque_Nm": math.nan}})
        files.append(tmp_path / f"b{k}.json")
        files[-1].write_text(json.dumps({"batch": batch, "records": records}), encoding="utf-8")
    files.reverse()
    header = {"sweep": "streamed"}
    with gather_points(files, streamed, params, tmp_path / "streamed.csv", lambda totals: header, 30.0) as kept:
        write_json(tmp_path / "streamed.json", summarise(streamed, params, kept.records, kept.totals, kept.map_slice))
    everything = read_points(files, sweep)
    write_csv(tmp_path / "memory.csv", sweep_table(sweep, everything, 30.0), header)
    write_json(tmp_path / "memory.json", summarise(sweep, params, everything))
    assert (tmp_path / "streamed.csv").read_bytes() == (tmp_path / "memory.csv").read_bytes()
    assert (tmp_path / "streamed.json").read_bytes() == (tmp_path / "memory.json").read_bytes()
    summary = json.loads((tmp_path / "memory.json").read_text())
    assert summary["assistance"]["n_above"] == len(summary["assistance"]["points_above"]) == 1  # 20 + 11 > 30
    assert kept.totals.n_points == 12 and kept.totals.peak_range_Nm == (20.0, 31.0)
    assert len(kept.records) < 12  # only the lines through the design point are kept whole
    with pytest.raises(SweepError, match=f"first difference: {min(sweep.batches(3)[json.loads(files[0].read_text())['batch']])}"):
        with gather_points(files[1:], streamed, params, tmp_path / "short.csv", lambda totals: header, 30.0):
            pass
    with pytest.raises(SweepError, match="gathered from another file"):
        with gather_points(files + files[:1], streamed, params, tmp_path / "twice.csv", lambda totals: header, 30.0):
            pass
    other = load_sweep(_write(tmp_path, text.replace("base_case: unladen", "base_case: part_laden"), "o.yaml"), params,
                       expand=False)  # the same values simulate another case: other ids
    with pytest.raises(SweepError, match="point files do not match"):
        with gather_points(files, other, params, tmp_path / "other.csv", lambda totals: header, 30.0):
            pass


def test_an_unexpanded_grid_is_checked_and_indexed_as_the_expansion(tmp_path, params):
    """Loaded without its expansion, a grid decodes each point's values and id from its index and finds each
    index from the values, as the expansion lists them; a point whose design values are unphysical is refused
    with the same line, naming the same (first) point."""
    path = _write(tmp_path, GRID)
    sweep, lazy = load_sweep(path, params), load_sweep(path, params, expand=False)
    for point in sweep.points:
        assert lazy.values_at(point.index) == point.values and lazy.id_at(point.index) == point.id
        assert lazy.locate(point.id, point.values) == point.index
    assert lazy.locate(sweep.points[1].id, sweep.points[0].values) == -1
    with pytest.raises(SweepError, match="expanded"):
        lazy.point_ids
    # 1,500 N on the front axle is below the unsprung weight once the unsprung mass is 200 kg (1,962 N): the
    # first such point is pressure 0, load 1, mass 1: point 3 (the check itself tries a point per load and mass,
    # that one its second), and the same in the unselected full sweep of one pressure
    axes = "  tyre.tyre_pressure: [150000, 200000]\n  design.front_axle_load: [5576, 1500]\n" \
           "  vehicle.unsprung_mass: [50, 200]\n"
    for text, where in ((f"name: bad\nbase_case: unladen\naxes:\n{axes}", ": point 3:"),
                        (f"name: bad\nbase_case: unladen\naxes: {{tyre.tyre_pressure: [2.0e+5]}}\n"
                         f"full_axes:\n{axes.replace('150000, ', '')}", ": full_axes point 3:")):
        bad = _write(tmp_path, text, "bad.yaml")
        with pytest.raises(SweepError) as expanded:
            load_sweep(bad, params)
        with pytest.raises(SweepError) as unexpanded:
            load_sweep(bad, params, expand=False)
        assert str(unexpanded.value) == str(expanded.value) and where in str(expanded.value)


# ---------------------------------------------------------------------------- design variables


@pytest.mark.parametrize("case", ["offset_12_7mm", "offset_44_5mm", "offset_68_5mm"])
def test_offset_and_load_statics_reproduce_table_b1(params, case):
    """Moving the wheels out by a spacer with the chassis's mass and lateral mass centre kept re-splits the
    loads by statics exactly as the paper's Table B1 lists them for its three spacers (within 0.5 N, the
    table's rounding plus the 0.1 N the notes found for the statics)."""
    table = params.case(case)
    total = params.case("unladen")["load_left"] + params.case("unladen")["load_right"]
    overrides = point_overrides(params, "unladen", {"design.extra_offset": table["extra_offset"],
                                                    "design.front_axle_load": total})
    assert overrides["case.wheel_centre_y"] == pytest.approx(table["wheel_centre_y"], abs=1e-9)
    assert overrides["case.load_left"] == pytest.approx(table["load_left"], abs=0.5)
    assert overrides["case.load_right"] == pytest.approx(table["load_right"], abs=0.5)
    assert overrides["case.chassis_mass"] == pytest.approx(table["chassis_mass"], abs=0.01)


def test_ratio_keeps_road_wheel_lock_and_castor_keeps_axis_through_wheel_centre(params):
    """A quicker rack leaves the road-wheel lock angle unchanged (the rack travel is the car's), and a new
    castor angle comes with the trail that keeps the steer axis through the wheel centre in side view."""
    overrides = point_overrides(params, "unladen", {"design.steering_ratio": 15.0, "design.castor_angle": 0.1})
    sections = {}
    for key, value in overrides.items():
        section, _, name = key.partition(".")
        sections.setdefault(section, {})[name] = value
    changed = params
    for section, values in sections.items():
        changed = with_overrides(changed, section, **values)
    assert changed["steering.handwheel_to_rack_ratio"] / changed["steering.roadwheel_to_rack_ratio"] == \
        pytest.approx(15.0)
    assert lock_steer_angle(changed) == pytest.approx(lock_steer_angle(params), rel=1e-12)
    axis = steer_axis(changed, "unladen", "left")
    along = (axis.wheel_centre[2] - axis.top[2]) / axis.direction[2]
    assert (axis.top + along * axis.direction)[0] == pytest.approx(axis.wheel_centre[0], abs=1e-12)


# ---------------------------------------------------------------------------- figures of merit

RACK_SHARE = 4.0  # N m
TYRE_LIMIT = 11.0  # N m, reached after the carcass wind-up
WIND_UP_M = 0.02
COLUMN_PER_RACK = 186.47
STEER_PER_RACK = 8.3682


def synthetic_cycle(ripple_Nm=0.0, ripple_phase=0.0, tread_slides=True, dt=0.001):
    """A right-going stroke to lock and the start of the return, built from the paper's mechanisms.

    Rack speed ramps to 15 mm/s in 0.02 s, cruises, stops at lock at t = 4.5 s and returns. The rack friction
    share is +-RACK_SHARE (reversing with the rack speed); the tyre share rises linearly over WIND_UP_M of rack
    (the tread stuck, the carcass twisting) to TYRE_LIMIT and stays there while the tread slides; after the
    reversal the carcass unwinds at the same rate. A ripple of period pi in column angle stands for the Hooke
    joint. So the plateau is RACK_SHARE + TYRE_LIMIT, the drop at reversal 2 RACK_SHARE.
    """
    t = np.arange(0.0, 5.5 + dt / 2, dt)
    v0, ramp = 0.015, 0.02
    speed = np.where(t < 4.5, v0 * np.clip(np.minimum(t, 4.5 - t) / ramp, 0, 1),
                     -v0 * np.clip((t - 4.5) / ramp, 0, 1))
    rack = np.concatenate([[0.0], np.cumsum((speed[1:] + speed[:-1]) / 2 * dt)])
    lock = rack.max()
    steer = STEER_PER_RACK * rack
    column = COLUMN_PER_RACK * rack
    rack_part = RACK_SHARE * np.tanh(speed / 1e-4)
    going = t <= 4.5
    tyre_part = np.where(going, TYRE_LIMIT * np.minimum(rack / WIND_UP_M, 1.0),
                         TYRE_LIMIT * (1.0 - 2.0 * np.minimum((lock - rack) / WIND_UP_M, 1.0)))
    ripple = ripple_Nm * np.sin(2.0 * column + ripple_phase)
    twist_stuck = -steer  # the tread does not turn: ring angle steer + twist stays zero
    twist = np.where(going & (rack > WIND_UP_M) & tread_slides, -STEER_PER_RACK * WIND_UP_M, twist_stuck)
    twist = np.where(going, twist, twist[going][-1])
    return {
        "time_s": t, "rack_m": rack, "handwheel_torque_Nm": rack_part + tyre_part + ripple,
        "column_angle_rad": column, "steer_left_rad": steer, "steer_right_rad": steer,
        "twist_left_rad": twist, "twist_right_rad": twist,
        "contrib_rack_friction_Nm": rack_part, "contrib_tyre_friction_Nm": tyre_part, "contrib_ripple_Nm": ripple,
    }


@pytest.mark.parametrize("phase", [0.0, 1.0, 2.5])
def test_plateau_and_shares_of_a_synthetic_cycle_average_out_the_ripple(phase):
    """Plateau = rack share + sliding tyre moment; the shares are their fractions and the Hooke-type ripple's
    share vanishes, whatever its phase, because the window holds whole ripple periods; sliding is found where
    the carcass stops twisting (at the wind-up travel)."""
    merits = figures_of_merit(synthetic_cycle(ripple_Nm=1.5, ripple_phase=phase))
    plateau = RACK_SHARE + TYRE_LIMIT
    assert merits["plateau_torque_Nm"] == pytest.approx(plateau, abs=0.02)
    assert merits["share_contrib_rack_friction_Nm"] == pytest.approx(RACK_SHARE / plateau, abs=0.002)
    assert merits["share_contrib_tyre_friction_Nm"] == pytest.approx(TYRE_LIMIT / plateau, abs=0.002)
    assert abs(merits["share_contrib_ripple_Nm"]) < 0.002
    assert merits["sliding_start_rack_m"] == pytest.approx(WIND_UP_M, abs=0.0002)
    assert merits["peak_torque_Nm"] == pytest.approx(plateau + 1.5, abs=0.01)


def test_lock_torque_and_reversal_drop_of_a_synthetic_cycle():
    """Arriving at lock the torque is rack share + tyre limit; on reversal it drops by twice the rack share
    (the friction reverses) plus the carcass unwinding over the rack's travel to half its return speed
    (0.04 mm here, so at most 2 * 11 N m * 0.04 / 20 = 0.05 N m)."""
    merits = figures_of_merit(synthetic_cycle())
    assert merits["lock_torque_Nm"] == pytest.approx(RACK_SHARE + TYRE_LIMIT, abs=1e-6)
    assert merits["reversal_drop_Nm"] == pytest.approx(2 * RACK_SHARE, abs=0.05)
    assert merits["reversal_rack_travel_m"] < 1e-4


def test_no_plateau_when_the_tread_never_slides():
    """If the carcass twists all the way to lock (the tread never slides) there is no plateau to quote."""
    merits = figures_of_merit(synthetic_cycle(tread_slides=False))
    assert math.isnan(merits["plateau_torque_Nm"]) and merits["sliding_fraction"] == 0.0


def test_threshold_crossing_is_interpolated_along_the_map_axis(tmp_path, params):
    """With the peak torque linear in front load (10 N m + 3 N m per kN), the load at which it reaches the
    28.5 N m threshold is (28.5 - 10) / 3 kN, at every pressure."""
    sweep = load_sweep(_write(tmp_path, """
name: lin
base_case: unladen
axes:
  tyre.tyre_pressure: [150000, 250000]
  design.front_axle_load: [5000, 6000, 7000]
map: {x: tyre.tyre_pressure, y: design.front_axle_load, quantity: peak_torque_Nm}
"""), params)
    records = [{"point": p.id, "values": p.values,
                "merits": {"peak_torque_Nm": 10.0 + 3.0e-3 * p.values["design.front_axle_load"]}}
               for p in sweep.points]
    design = {k: {"nearest": v} for k, v in sweep.points[0].values.items()}
    crossings = threshold_crossings(sweep, records, design, "peak_torque_Nm", 28.5)
    assert [c["x"] for c in crossings] == [150000.0, 250000.0]
    for c in crossings:
        assert c["crossing_y"] == pytest.approx((28.5 - 10.0) / 3.0e-3, rel=1e-12)


# ---------------------------------------------------------------------------- physics of a tiny grid


@pytest.fixture(scope="module")
def default_model():
    """The paper's model derived (a sweep point never derives; rule derive does it before the points run)."""
    from parksteer.model.numeric.compiled import load_model
    from parksteer.model.symbolic.components import resolve_effects

    return load_model(resolve_effects(None))


@pytest.fixture(scope="module")
def tiny_grid(params, default_model):
    """Four points of the multibody model: two pressures x two front axle loads, the rest the test car."""
    out = {}
    for pressure in (122500.0, 245000.0):
        for load in (5576.0, 8000.0):
            spec = {"sweep": "tiny", "point": "x", "case": "unladen", "effects": None,
                    "surface": "ground", "values": {"tyre.tyre_pressure": pressure, "design.front_axle_load": load}}
            out[pressure, load] = simulate_point(spec, params)["merits"]
    return out


def _tyre_share(merits):
    return merits["plateau_torque_Nm"] * merits["share_contrib_tyre_friction_Nm"]


def test_plateau_falls_with_pressure_as_equation_2(tiny_grid):
    """Doubling the pressure lowers the plateau, and its tyre share by (1/2)^n with n = 0.78 (equation (2)),
    within 1 %: the sliding tread carries the moment limit at its instantaneous load, and lifting moves the
    loads by well under 1 % between the two runs' windows; the rack share does not depend on pressure."""
    for load in (5576.0, 8000.0):
        low, high = tiny_grid[122500.0, load], tiny_grid[245000.0, load]
        assert high["plateau_torque_Nm"] < low["plateau_torque_Nm"]
        assert _tyre_share(high) / _tyre_share(low) == pytest.approx(0.5**0.78, rel=0.01)
        rack = [m["plateau_torque_Nm"] * m["share_contrib_rack_friction_Nm"] for m in (low, high)]
        assert rack[1] == pytest.approx(rack[0], rel=0.01)


def test_plateau_tyre_share_rises_with_load_as_w_to_the_1_5(tiny_grid):
    """The tyre share of the plateau grows as W^1.5 with the front axle load (equations (1), (2)), within 1 %
    for the reason above; the total grows more slowly because the rack friction share (F / 186.47 rad/m,
    about 3.9 N m) does not depend on load."""
    for pressure in (122500.0, 245000.0):
        light, heavy = tiny_grid[pressure, 5576.0], tiny_grid[pressure, 8000.0]
        assert _tyre_share(heavy) / _tyre_share(light) == pytest.approx((8000.0 / 5576.0) ** 1.5, rel=0.01)
        total_ratio = heavy["plateau_torque_Nm"] / light["plateau_torque_Nm"]
        assert 1.0 < total_ratio < (8000.0 / 5576.0) ** 1.5
        rack = [m["plateau_torque_Nm"] * m["share_contrib_rack_friction_Nm"] for m in (light, heavy)]
        assert rack == pytest.approx([730.0 / 186.47] * 2, rel=0.01)


def test_plateau_scales_inversely_with_steering_ratio(params, default_model):
    """Through lossless gearing the handwheel carries the road-side resistance divided by the overall ratio:
    plateau x G is the same for G = 16 and 30 within 2 % (the Hooke-joint ripple is averaged over whole
    periods, the column damping adds only c * rate, under 0.1 N m at these rates)."""
    products = []
    for ratio in (16.0, 30.0):
        spec = {"sweep": "tiny", "point": "x", "case": "unladen", "effects": None,
                "surface": "ground", "values": {"design.steering_ratio": ratio}}
        products.append(simulate_point(spec, params)["merits"]["plateau_torque_Nm"] * ratio)
    assert products[0] == pytest.approx(products[1], rel=0.02)


def test_braked_wheels_effect_agrees_with_rig_theory_and_matters_only_with_offset(params):
    """Held wheels drag the patch about the axis's ground point: with the 68.5 mm spacer (62.7 mm at the ground,
    about 0.75 patch radii) the simulated braked_wheels effect raises the tyre's plateau share by the same factor
    as the rig theory applied after the fact (within 1 %: the effect's series for the patch integral and its
    lateral-only offset), and the plateau by over 20 % (the drag part without equation (2)'s pressure correction,
    as Fig. 4); with the standard wheels (5.8 mm) by under 1 %."""
    from parksteer.model.numeric.compiled import load_model
    from parksteer.model.symbolic.components import resolve_effects

    braked_effects = sorted(["braked_wheels", "carcass_compliance", "hooke_joint", "lifting", "rack_friction",
                             "tyre_friction"])
    load_model(resolve_effects(braked_effects))  # a sweep point never derives: derived here, as rule derive would
    plateaus = {}
    for offset in (0.0, 0.0685):
        spec = {"sweep": "tiny", "point": "x", "case": "unladen", "effects": None, "surface": "ground",
                "values": {"design.extra_offset": offset}, "braked": "braked_wheels", "braked_effects": braked_effects}
        record = simulate_point(spec, params)
        braked = record["braked"]
        assert braked["factor"] == pytest.approx(braked["rig_theory_factor"], rel=0.01)
        plateaus[offset] = record["merits"]["plateau_torque_Nm"], braked["plateau_torque_Nm"]
    free, held = plateaus[0.0]
    assert held / free == pytest.approx(1.0, abs=0.01)
    free, held = plateaus[0.0685]
    assert held / free > 1.2


def test_point_job_never_derives(params, tmp_path, monkeypatch):
    """A point whose model is not in the cache fails with one line and writes nothing, instead of deriving."""
    from parksteer.sweep.run import run_point

    monkeypatch.setenv("PARKSTEER_MODEL_CACHE", str(tmp_path / "empty_cache"))
    spec = {"sweep": "t", "point": "0000000000", "case": "unladen", "effects": None,
            "surface": "ground", "values": {"tyre.tyre_pressure": 200000.0}}
    out = tmp_path / "point.json"
    with pytest.raises(UsageError, match="never derives") as info:
        run_point(spec, params.path, out)
    assert "\n" not in str(info.value) and not out.exists()
    assert not (tmp_path / "empty_cache").exists()


# ---------------------------------------------------------------------------- cluster profile


def _design_batches(repo_root, params) -> dict[str, tuple[str, ...]]:
    """The batches of the example sweep at the configured batch size, as the pipeline forms them."""
    import yaml

    config = yaml.safe_load((repo_root / "config" / "config.yaml").read_text(encoding="utf-8"))
    return load_sweep(repo_root / EXAMPLE, params).batches(config["sweep_batch_size"])


def test_slurm_profile_dry_run_lists_the_batch_jobs_and_their_resources(repo_root, tmp_path, params):
    """A dry run with workflow/profiles/slurm plans the example sweep's 48 points as its batch jobs bundled into
    group jobs of at most 8 batches, each batch asking for the profile's partition, account, memory and runtime.

    What this shows and what it does not: Snakemake needs the plugin installed to accept `executor: slurm`,
    but a dry run never hands jobs to it (the plugin's maintainers say so, snakemake-executor-plugin-slurm
    issue 312): no sbatch, sinfo or sacct is called, which the fake sbatch on PATH below verifies. So the
    partition and account placeholders and the submission itself are only exercised on a real cluster.
    """
    pytest.importorskip("snakemake_executor_plugin_slurm", reason="the SLURM executor plugin is a test-only extra")
    batches = _design_batches(repo_root, params)
    assert sum(len(points) for points in batches.values()) == 48
    fake_bin = tmp_path / "bin"
    fake_bin.mkdir()
    called = tmp_path / "sbatch_called"
    for tool in ("sbatch", "sinfo", "sacct", "squeue"):
        script = fake_bin / tool
        script.write_text(f"#!/bin/sh\necho {tool} >> {called}\nexit 1\n", encoding="utf-8")
        script.chmod(0o755)
    env = dict(os.environ, PATH=f"{fake_bin}{os.pathsep}{os.environ['PATH']}")
    snakemake = Path(sys.executable).with_name("snakemake")
    done = subprocess.run(
        [str(snakemake), "--snakefile", str(repo_root / "workflow" / "Snakefile"), "--directory",
         str(repo_root), "--profile", "workflow/profiles/slurm", "--dry-run", "--forceall", "sweep_design"],
        capture_output=True, text=True, env=env, timeout=120,
    )
    out = done.stdout + done.stderr
    assert done.returncode == 0, out[-2000:]
    # Snakemake names the profiles it reads: this one, and the workflow's default (workflow/profiles/default).
    assert re.search(r"Using profiles? workflow/profiles/slurm", out), out[-2000:]
    stats = {line.split()[0]: int(line.split()[1]) for line in out.splitlines()
             if len(line.split()) == 2 and line.split()[1].isdigit()}
    assert stats["sweep_batch"] == len(batches) and stats["sweep_design"] == 1
    assert out.count("Group job sweep_batches") == math.ceil(len(batches) / 8)
    assert set(re.findall(r"logs/sweep_batch/design/([0-9a-f]{10})\.log", out)) == set(batches)
    # each job's block starts at its "rule <name>:" line; the resources of the sweep_batch blocks
    blocks = re.split(r"^ *(?:local)?rule (\w+):$", out, flags=re.MULTILINE)[1:]
    batch_resources = [line for name, block in zip(blocks[::2], blocks[1::2]) if name == "sweep_batch"
                       for line in block.splitlines() if "resources:" in line]
    assert len(batch_resources) == len(batches)
    assert all("slurm_partition=your_partition" in r and "slurm_account=your_account" in r and "mem_mb=1000" in r
               and "runtime=10" in r for r in batch_resources)
    assert not called.exists()


def test_slurm_submission_with_stand_in_tools_requests_bounded_group_jobs(repo_root, tmp_path, params):
    """Submitting for real, against stand-ins for sbatch, sacct and friends that only record their arguments,
    the example sweep goes to SLURM as group jobs of at most 8 batches, each asking for at most 4 cores and
    4 GB (the batches run 4 at a time) and 10 minutes per layer of 4 batches, on the profile's partition and
    account.

    This exercises the plugin's own submission code, which a dry run does not; the stand-in sbatch runs
    nothing, so no point is computed and Snakemake is stopped once every group is submitted.
    """
    pytest.importorskip("snakemake_executor_plugin_slurm", reason="the SLURM executor plugin is a test-only extra")
    batches = _design_batches(repo_root, params)
    groups = math.ceil(len(batches) / 8)
    work = tmp_path / "work"
    (work / "workflow").mkdir(parents=True)
    for name in ("config", "src", "paper"):
        (work / name).symlink_to(repo_root / name)
    for child in (repo_root / "workflow").iterdir():
        (work / "workflow" / child.name).symlink_to(child)
    # The model manifests the batch jobs wait for (the pipeline's full model and the sweep's braked-wheel model),
    # present and newer than their inputs, so that the first submissions are the batches. Nothing runs a point
    # here, so their content does not matter.
    for manifest in ("results/model/full.json", "results/model/with_braked_wheels.json"):
        (work / manifest).parent.mkdir(parents=True, exist_ok=True)
        (work / manifest).write_text("{}\n", encoding="utf-8")
    fake_bin, calls = tmp_path / "bin", tmp_path / "calls"
    fake_bin.mkdir()
    (fake_bin / "sbatch").write_text(f'#!/bin/sh\necho "$@" >> {calls}.sbatch\necho 4242\n', encoding="utf-8")
    for tool in ("sinfo", "sacct", "squeue", "scancel", "sacctmgr", "sshare"):
        (fake_bin / tool).write_text(f'#!/bin/sh\necho "$@" >> {calls}.{tool}\nexit 0\n', encoding="utf-8")
    for tool in fake_bin.iterdir():
        tool.chmod(0o755)
    env = dict(os.environ, PATH=f"{fake_bin}{os.pathsep}{os.environ['PATH']}")
    snakemake = Path(sys.executable).with_name("snakemake")
    # Snakemake's log goes to a file: read through a pipe only at the end, it would fill the pipe and stall.
    log_path = tmp_path / "snakemake.log"
    with log_path.open("w", encoding="utf-8") as log:
        process = subprocess.Popen(
            [str(snakemake), "sweep_design", "--snakefile", str(work / "workflow" / "Snakefile"),
             "--directory", str(work), "--profile", str(repo_root / "workflow" / "profiles" / "slurm")],
            stdout=log, stderr=subprocess.STDOUT, env=env, text=True,
            start_new_session=True,  # its own process group, so every child dies with it below
        )
    submissions: list[str] = []
    try:
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline and process.poll() is None:
            sbatch_log = Path(f"{calls}.sbatch")
            submissions = sbatch_log.read_text().splitlines() if sbatch_log.exists() else []
            if len(submissions) >= groups:
                break
            time.sleep(0.5)
    finally:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:  # it ended by itself; its log says how
            pass
        process.wait(timeout=30)
    output = log_path.read_text(encoding="utf-8")
    assert len(submissions) == groups, output[-3000:]
    # no derive job among them (by the rule's job and comment names: the checkout's path may hold the word)
    assert "'derive:" not in " ".join(submissions) and "rule_derive" not in " ".join(submissions)
    for line in submissions:
        members = line.count("sweep_batch:")
        assert 1 <= members <= 8
        assert "-p your_partition" in line and "-A your_account" in line
        assert f"--cpus-per-task={min(members, 4)}" in line and f"--mem {1000 * min(members, 4)}" in line
        assert line.split(" -t ")[1].split()[0] == str(10 * math.ceil(members / 4))
    assert sum(line.count("sweep_batch:") for line in submissions) == len(batches)
