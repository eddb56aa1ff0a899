"""Every record enters through the readers' table (parksteer.measure.readers.READERS), a raw CAN log given with its
bus included: the import layer asks the table for a reader and nothing else."""

from __future__ import annotations

import ast
from pathlib import Path

from parksteer.measure import importers
from parksteer.measure.readers import READERS, reader_for
from parksteer.measure.readers.bus_log import BusLogReader
from parksteer.measure.readers.bus_files import BusMap, load_bus
from parksteer.measure.readers.can_log import CanLogReader

SAMPLES = Path(__file__).resolve().parents[2] / "data" / "samples"


def test_a_bus_log_given_with_its_bus_is_read_by_the_tables_bus_reader():
    """The fact checked: with a channel map that carries a bus, the table gives its bus-log reader, whatever the
    file's bytes (a candump log, or bytes no other reader would give to a CAN decoder); without a bus, the same
    log sniffs as a CAN log and an MDF file is not given to the bus reader."""
    raw = (SAMPLES / "polo_kerb.log").read_bytes()
    bus = BusMap([], load_bus("vw_mqb"))
    assert "bus_log" in READERS and isinstance(reader_for(raw, bus), BusLogReader)
    assert isinstance(reader_for(b"MDF     4.10", bus), BusLogReader)
    assert isinstance(reader_for(raw), CanLogReader)
    assert not isinstance(reader_for(b"MDF     4.10"), BusLogReader)


def test_the_import_layer_reads_records_only_through_the_table():
    """The fact checked: importers.py calls no reader (a ``read_*`` function or a ``*Reader`` of the readers)
    directly: the only reading call it makes is ``reader_for(...).read(...)`` (a format added to the table is read without touching the import layer)."""
    tree = ast.parse(Path(importers.__file__).read_text(encoding="utf-8"))
    from_readers = {alias.asname or alias.name for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
                    and (node.module or "").startswith("readers") for alias in node.names}
    called = {node.func.id for node in ast.walk(tree) if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)}
    reading = {name for name in from_readers & called if name.startswith("read") or name.endswith("Reader")}
    assert reading == {"reader_for"}


def test_the_readers_refuse_a_record_through_one_helper():
    """The fact checked: no reader and no module of the import layer (importers.py and the channel map, units and
    plausibility checks it runs) writes a refusal's ``{where}: `` prefix by hand
    (``UsageError(f"{where}: ...")``): each goes through ``readers.base.refusal``, which gives the one-line form
    ``FILE: problem``."""
    from parksteer.errors import UsageError
    from parksteer.measure.readers.base import refusal

    layer = [Path(importers.__file__).with_name(f"{name}.py")
             for name in ("importers", "channel_map", "units", "plausibility")]
    modules = [*layer, *sorted(Path(importers.__file__).with_name("readers").glob("*.py"))]
    by_hand = [f"{path.name}:{number}" for path in modules
               for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
               if 'UsageError(f"{where}: ' in line and path.name != "base.py"]
    assert by_hand == []
    error = refusal(Path("car.csv"), "row 3: not a number")
    assert isinstance(error, UsageError) and str(error) == "car.csv: row 3: not a number"
