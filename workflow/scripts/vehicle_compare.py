# Thin rule script: `parksteer compare --vehicle` (parksteer.commands.measure) with its JSON kept as the output.
import contextlib
import sys
from pathlib import Path

import parksteer.commands.measure  # noqa: F401 (the command this rule runs; its imports are the rule's inputs)
from parksteer.cli import main
from parksteer.rules import rule_log


def measurement_files(items):
    """The rule's measurement inputs, a folder (the synthetic set) listed as its files."""
    items = [items] if isinstance(items, str) else list(items)
    out = []
    for item in items:
        path = Path(item)
        out += sorted(str(p) for p in path.iterdir() if p.suffix == ".csv") if path.is_dir() else [item]
    return out


with rule_log(snakemake), open(snakemake.output.json, "w", encoding="utf-8") as out, \
        contextlib.redirect_stdout(out):
    status = main(["compare", *measurement_files(snakemake.input.files), "--parameters", snakemake.input.parameters,
                   "--vehicle", snakemake.input.vehicle, *snakemake.params.options,
                   "--json", "--plot", snakemake.output.svg])
sys.exit(status)
